// The AirspeedFit run of bench_peers_speed.py: ArduPilot/WebTools' AirspeedFit numeric core
// (AirspeedFit/airspeedfit_core.js) under node, on a pitotcal flight CSV.
//
// Run: node benchmarks/peer_airspeedfit.js CORE.js FLIGHT.csv
// As the tool's page does: u = sqrt(dp) * EAS2TAS (here EAS2TAS = sqrt(rho_SSL / rho) from the
// CSV's air density), a constant-wind fit per sensor as the seed (`calibrate`), then the
// reported time-varying-wind fit (`calibrate_combined`, default options). Prints one JSON line.
'use strict'
const fs = require('fs')

const core = require(require('path').resolve(process.argv[2]))
const lines = fs.readFileSync(process.argv[3], 'utf8').split('\n')
let head = 0
while (lines[head].startsWith('#')) head++
const names = lines[head].trim().split(',')
const col = (name) => names.indexOf(name)
const it = col('time_s'), iq = col('qc_pa'), ivn = col('gps_vn_mps'), ive = col('gps_ve_mps')
const ivd = col('gps_vd_mps'), irho = col('rho_kgm3')
const t = [], vn = [], ve = [], vd = [], u = []
for (let i = head + 1; i < lines.length; i++) {
    const line = lines[i]
    if (line.length === 0 || line[0] === '#') continue
    const f = line.split(',')
    const dp = Math.max(parseFloat(f[iq]), 0)
    t.push(parseFloat(f[it])); vn.push(parseFloat(f[ivn])); ve.push(parseFloat(f[ive]))
    vd.push(ivd >= 0 ? parseFloat(f[ivd]) : 0)
    u.push(Math.sqrt(dp) * Math.sqrt(core.SSL_AIR_DENSITY / parseFloat(f[irho])))
}
const seed = core.calibrate(vn, ve, vd, u)
const fit = core.calibrate_combined(t, vn, ve, vd, [u], [seed])
let wn = 0, we = 0
for (const w of fit.wind_ne) { wn += w[0]; we += w[1] }
wn /= fit.wind_ne.length; we /= fit.wind_ne.length
console.log(JSON.stringify({
    ratio: fit.per_sensor[0].ratio, ratio_stderr: fit.per_sensor[0].ratio_stderr,
    ratio_constant_wind: seed.ratio, wind_ne_constant: seed.wind_ne, wind_ne_mean: [wn, we],
    wind_drift_mps: fit.wind_drift, iterations: fit.iterations, n: u.length,
    n_smoothed: fit.n_samples, warnings: seed.warnings,
}))
