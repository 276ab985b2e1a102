"""How far below its present error an unbiased fit of the inverse structure could go on the
everyday drifting-wind flights, and how low one ratio (AirspeedFit's structure) could go.

Run: ``python benchmarks/bench_drift_bound.py [--flights 100] [--out DIR]``.

The flights and the yardstick are `bench_airspeedfit.py`'s (the 15-minute everyday flight in a
wind drifting from 9 m/s from 270° to 12 m/s from 310°, 0.5 m/s turbulence, 5 Hz GPS; max
|ΔV error| over 7 flown speeds, kt; the same seeds). Per flight, with the true drift taken out
of the GPS velocity (the oracle's flight), the residual at the true k and the true mean wind is
the noise the fit met, sample by sample (the gusts' copy in q_ci and the GPS noise). Its
autocovariance, averaged over the flights and tapered (Hann, `MAX_LAG_S`), is the noise
spectrum Σ of the rows below:

- ``identify``: `pitotcal.estimation.identify` (inverse, the wind model by its test), its
  error against the truth and whether its 2σ covers it (the benchmark's row, in process);
- ``IV, true wind track``: identify's estimating equations (the coefficient rows on the
  instruments, `estimation.identification.iv`), linearised at the truth and solved on the true
  residual: the error the estimator makes when the wind track is known;
- the same, *expected* from Σ: the IV sandwich (Z'S)⁻¹ Z'ΣZ (S'Z)⁻¹, turned into the median of
  max |ΔV error| by Gaussian draws;
- ``bound``: (Z'Σ⁻¹Z)⁻¹, the Cramér-Rao bound of an unbiased fit whose regressors are the
  flight's design (q_ci smoothed over the instruments' window: the speeds and headings flown,
  not the gusts' copy of themselves in q_ci), expected the same way. The ratio of the two
  expected medians is the IV's efficiency;
- ``bound counting the gusts' copy``: (S'Σ⁻¹S)⁻¹ with the raw sensitivities S, which counts
  the gusts' copy of themselves in q_ci as information; the actual error of the Σ⁻¹-weighted
  least squares that would reach it (biased by that copy) says why it cannot be reached;
- ``one ratio, best possible``: the ratio whose ΔV is closest to the truth over the grid
  (minimax): a one-ratio fit's error from its structure alone, before any noise.
"""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.linalg import matmul_toeplitz, solve_toeplitz
from scipy.optimize import minimize_scalar

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from bench_airspeedfit import dv_ratio, truth_of, without_true_drift  # noqa: E402
from bench_peers_speed import machine  # noqa: E402

MAX_LAG_S = 300.0       # the noise autocovariance's taper length
DRAWS = 2000            # Gaussian draws per flight for an expected median


def flight_terms(seed):
    """Per flight: the true residual, sensitivities S and instruments Z at the truth, the ΔV
    gradient on the grid, identify's error and coverage, the one-ratio floor."""
    from pitotcal.core.measurement import flight_channels, flight_air
    from pitotcal.core.models import get_model
    from pitotcal.estimation import identify
    from pitotcal.estimation.identification.iv import IV_WINDOW_S, instruments, smooth_in_time
    from pitotcal.estimation.identification.residual import residual, sensitivities
    from pitotcal.maneuvers.fly.everyday import everyday_flight
    from pitotcal.studies.engine.common import truth_delta_v_kt, vi_grid_kt

    flight, truth = everyday_flight(seed, drifting=True)
    case = truth_of(flight, truth)
    model = get_model(truth.model)
    k = np.array([truth.parameters[p] for p in model.params])
    grid = vi_grid_kt(case["qci_pa"])
    dv_true = np.asarray(truth_delta_v_kt(truth, grid), dtype=float)
    dv, band = identify(flight, truth.model).delta_v_kt(grid)
    oracle = without_true_drift(flight, case)
    ch = flight_channels(oracle, air_data=truth.air_data)
    air = flight_air(oracle, truth.air_data)
    theta = np.array([*k, *case["mean"]])
    s = sensitivities(model, theta, ch.qci, ch.vn, ch.ve, air, ch.vd2)
    z = instruments(model, theta, smooth_in_time(ch.qci, oracle.time_s, IV_WINDOW_S), s)
    return {"r": residual(model, theta, ch.qci, ch.vn, ch.ve, air, ch.vd2), "s": s, "z": z,
            "grad": _dv_gradient(model, k, grid, truth.air_data),
            "dt_s": float(np.median(np.diff(oracle.time_s))),
            "identify": float(np.max(np.abs(dv - dv_true))),
            "covered": bool(np.all(np.abs(dv - dv_true) <= band)),
            "ratio_floor": ratio_floor(grid, dv_true)}


def _dv_gradient(model, k, grid, air_data):
    from pitotcal.core.models import delta_v_kt

    cols = []
    for i, h in enumerate(model.scales):
        up, dn = k.copy(), k.copy()
        up[i] += h
        dn[i] -= h
        cols.append((delta_v_kt(model, up, grid, air_data)
                     - delta_v_kt(model, dn, grid, air_data)) / (2 * h))
    return np.column_stack(cols)


def ratio_floor(grid_kt, dv_true):
    """The smallest max |ΔV error| (kt) any one ratio reaches against `dv_true` on `grid_kt`."""
    worst = lambda r: float(np.max(np.abs(dv_ratio(r, 0.0, grid_kt)[0] - dv_true)))  # noqa: E731
    best = minimize_scalar(worst, bounds=(1.0, 2.5), method="bounded",
                           options={"xatol": 1e-9})
    return float(best.fun)


def noise_autocovariance(residuals, max_lag):
    """The residuals' autocovariance at lags 0..max_lag, averaged over flights, Hann-tapered."""
    acov = np.zeros(max_lag + 1)
    for r in residuals:
        x = r - r.mean()
        f = np.fft.rfft(x, 2 * x.size)
        acov += np.fft.irfft(f * np.conj(f))[:max_lag + 1] / x.size
    lag = np.arange(max_lag + 1)
    return acov / len(residuals) * 0.5 * (1.0 + np.cos(np.pi * lag / max_lag))


def covariances(d, acov):
    """{name: (coefficient covariance or None, actual linearised coefficient error or None)}."""
    s, z, r = d["s"], d["z"], d["r"]
    z = z.copy()
    z[:, -2:] = s[:, -2:]                     # the wind rows keep the score (as identify)
    col = np.zeros(r.size)
    col[:min(acov.size, r.size)] = acov[:r.size]
    inv = solve_toeplitz(col, np.column_stack([s, z, r]))
    n = s.shape[1]
    inv_s, inv_z, inv_r = inv[:, :n], inv[:, n:2 * n], inv[:, -1]
    b = np.linalg.inv(z.T @ s)
    nk = d["grad"].shape[1]
    return {"iv": (b @ (z.T @ matmul_toeplitz(col, z)) @ b.T, -b @ (z.T @ r)),
            "bound": (np.linalg.inv(z.T @ inv_z), None),
            "gls": (np.linalg.inv(s.T @ inv_s), -np.linalg.solve(s.T @ inv_s, s.T @ inv_r)),
            "nk": nk}


def expected_median(items, rng):
    """Median over flights and draws of max |ΔV error| with coefficient errors ~ N(0, C)."""
    worst = []
    for cov, grad in items:
        e = rng.multivariate_normal(np.zeros(grad.shape[1]), cov, size=DRAWS)
        worst.append(np.max(np.abs(e @ grad.T), axis=1))
    return float(np.median(np.concatenate(worst)))


def summarize(flights):
    """The table's rows: (name, median, 90th percentile or None, note)."""
    max_lag = int(round(MAX_LAG_S / flights[0]["dt_s"]))
    acov = noise_autocovariance([d["r"] for d in flights], max_lag)
    rng = np.random.default_rng(0)
    cov_iv, cov_bound, cov_gls, err_iv, err_gls = [], [], [], [], []
    for d in flights:
        c = covariances(d, acov)
        nk, grad = c["nk"], d["grad"]
        cov_iv.append((c["iv"][0][:nk, :nk], grad))
        cov_bound.append((c["bound"][0][:nk, :nk], grad))
        cov_gls.append((c["gls"][0][:nk, :nk], grad))
        err_iv.append(float(np.max(np.abs(grad @ c["iv"][1][:nk]))))
        err_gls.append(float(np.max(np.abs(grad @ c["gls"][1][:nk]))))
    iv_exp, bound_exp = expected_median(cov_iv, rng), expected_median(cov_bound, rng)
    gls_exp = expected_median(cov_gls, rng)
    pct = lambda x: (float(np.median(x)), float(np.percentile(x, 90)))  # noqa: E731
    covered = sum(d["covered"] for d in flights)
    return [("identify (inverse, wind model by its test)", *pct([d["identify"] for d in flights]),
             f"2σ covers {covered}/{len(flights)}"),
            ("IV, true wind track (linearised, actual)", *pct(err_iv), ""),
            ("IV, expected from the noise spectrum", iv_exp, None, ""),
            ("bound: design regressors, same spectrum", bound_exp, None,
             f"IV efficiency {bound_exp / iv_exp:.2f} (draws: ±0.01)"),
            ("bound counting the gusts' copy in q_ci (GLS on the measured q_ci)", gls_exp,
             None, "not reachable: see the next row"),
            ("GLS on the measured q_ci (actual)", *pct(err_gls), "biased by the gusts in q_ci"),
            ("one ratio, best possible (no noise)", *pct([d["ratio_floor"] for d in flights]),
             "structure alone")]


def table(rows, n, where):
    lines = [f"Machine: {where}", "",
             f"| {n} drifting-wind everyday flights | max \\|ΔV error\\| kt, median | "
             "90th pct | note |", "|---|---:|---:|---|"]
    for name, med, p90, note in rows:
        lines.append(f"| {name} | {med:.3f} | {'' if p90 is None else f'{p90:.3f}'} | {note} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flights", type=int, default=100, help="flights, seeds 0.. (100)")
    parser.add_argument("--out", default="drift-bound", help="folder for drift_bound.md/.json")
    args = parser.parse_args(argv)
    if args.flights < 2:
        parser.error("--flights must be at least 2 (the noise spectrum is an ensemble mean)")
    before, start = machine(), time.perf_counter()
    flights = []
    for seed in range(args.flights):
        flights.append(flight_terms(seed))
        print(f"flight {seed + 1}/{args.flights}", file=sys.stderr, flush=True)
    rows = summarize(flights)
    text = table(rows, args.flights, f"{before}; {time.perf_counter() - start:.0f} s in all")
    print(text)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "drift_bound.md").write_text(text + "\n", encoding="utf-8")
    (out / "drift_bound.json").write_text(json.dumps(
        {"rows": [dict(zip(("name", "median", "p90", "note"), r)) for r in rows],
         "flights": args.flights, "max_lag_s": MAX_LAG_S}, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
