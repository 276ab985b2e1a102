// The AirspeedFit runs of bench_peers_speed.py and bench_airspeedfit.py: ArduPilot/WebTools'
// AirspeedFit numeric core (AirspeedFit/airspeedfit_core.js) under node, on a pitotcal flight CSV.
//
// Run: node benchmarks/peer_airspeedfit.js CORE.js FLIGHT.csv [constant|drifting [Q]]
// As the tool's page does: u = sqrt(dp) * EAS2TAS (here EAS2TAS = sqrt(rho_SSL / rho) from the
// CSV's air density), a constant-wind fit per sensor as the seed (`calibrate`), then the
// reported time-varying-wind fit (`calibrate_combined`). Prints one JSON line.
// Without a mode (bench_peers_speed.py): every row, the core's default options.
// With a mode (bench_airspeedfit.py), as the page runs it: the page's automatic window
// (`auto_window` over the record) and samples with dp > 0 only; `constant` reports the
// constant-wind fit `calibrate` (the page's per-sensor cross-check), `drifting` the
// time-varying-wind fit with the page's default wind process noise, q = 10^-1.5 (m/s)/sqrt(s)
// (its slider's start), or Q, and the wind track.
'use strict'
const fs = require('fs')

const core = require(require('path').resolve(process.argv[2]))
const mode = process.argv[4]
const PAGE_Q_WIND = Math.pow(10, -1.5)
const lines = fs.readFileSync(process.argv[3], 'utf8').split('\n')
let head = 0
while (lines[head].startsWith('#')) head++
const names = lines[head].trim().split(',')
const col = (name) => names.indexOf(name)
const it = col('time_s'), iq = col('qc_pa'), ivn = col('gps_vn_mps'), ive = col('gps_ve_mps')
const ivd = col('gps_vd_mps'), irho = col('rho_kgm3')
let t = [], vn = [], ve = [], vd = [], u = [], dp = []
for (let i = head + 1; i < lines.length; i++) {
    const line = lines[i]
    if (line.length === 0 || line[0] === '#') continue
    const f = line.split(',')
    dp.push(parseFloat(f[iq]))
    t.push(parseFloat(f[it])); vn.push(parseFloat(f[ivn])); ve.push(parseFloat(f[ive]))
    vd.push(ivd >= 0 ? parseFloat(f[ivd]) : 0)
    const eas2tas = Math.sqrt(core.SSL_AIR_DENSITY / parseFloat(f[irho]))
    u.push(Math.sqrt(Math.max(dp[dp.length - 1], 0)) * eas2tas)
}
let window = null
if (mode) {
    window = core.auto_window(t, dp, t[0], t[t.length - 1])
    const keep = t.map((ti, i) => ti >= window.start && ti <= window.end && dp[i] > 0)
    const pick = (a) => a.filter((_, i) => keep[i])
    t = pick(t); vn = pick(vn); ve = pick(ve); vd = pick(vd); u = pick(u)
}
const seed = core.calibrate(vn, ve, vd, u)
if (mode === 'constant') {
    console.log(JSON.stringify({
        mode, ratio: seed.ratio, ratio_stderr: seed.ratio_stderr, wind_ne_mean: seed.wind_ne,
        n: u.length, window: [window.start, window.end], course_spread_deg: seed.course_spread_deg,
        warnings: seed.warnings,
    }))
    process.exit(0)
}
let q
if (mode === 'drifting') q = process.argv[5] ? parseFloat(process.argv[5]) : PAGE_Q_WIND
const fit = core.calibrate_combined(t, vn, ve, vd, [u], [seed],
                                    q === undefined ? undefined : { q_wind: q })
let wn = 0, we = 0
for (const w of fit.wind_ne) { wn += w[0]; we += w[1] }
wn /= fit.wind_ne.length; we /= fit.wind_ne.length
const out = {
    ratio: fit.per_sensor[0].ratio, ratio_stderr: fit.per_sensor[0].ratio_stderr,
    ratio_constant_wind: seed.ratio, wind_ne_constant: seed.wind_ne, wind_ne_mean: [wn, we],
    wind_drift_mps: fit.wind_drift, iterations: fit.iterations, n: u.length,
    n_smoothed: fit.n_samples, warnings: seed.warnings,
}
if (mode === 'drifting') {
    Object.assign(out, {
        mode, q_wind: q, window: [window.start, window.end],
        wind_track: { time_s: fit.t, wind_n_mps: fit.wind_ne.map((w) => w[0]),
                      wind_e_mps: fit.wind_ne.map((w) => w[1]) },
    })
}
console.log(JSON.stringify(out))
