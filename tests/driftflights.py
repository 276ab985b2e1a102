"""Simulated 15-minute flights in a drifting wind, with their truth, for the wind-model tests
and the study of docs/measured.md ("Drifting wind").

An everyday loiter: ground circles of 600 m radius (an orbit every 80-100 s) for 900 s, the
airspeed swept 70-100 KCAS and back three times, in 0.5 m/s Dryden turbulence with 0.1 m/s
GPS velocity noise, the wind drifting linearly from 9 m/s from 270° to 11 m/s from 310°
(2 m/s in speed and 40° in direction: a 7.1 m/s change of the vector).

    PYTHONPATH=tests python -m driftflights --runs 100 [--constant] [--wind constant]

prints the median max|ΔV error|, the 2σ coverage and how often the drift was chosen.
"""

import argparse
import functools

import numpy as np

from pitotcal.core.units import wind_polar, wind_vector_mps

from plans import circle_plan

DURATION_S = 900.0
WIND_START = (9.0, 270.0)       # m/s, deg from
WIND_END = (11.0, 310.0)


def drift_mps2():
    """The linear drift of the air-mass velocity (north, east), m/s²."""
    w0, w1 = (np.array(wind_vector_mps(*w)) for w in (WIND_START, WIND_END))
    return tuple(float(x) for x in (w1 - w0) / DURATION_S)


@functools.lru_cache(maxsize=1)
def loiter_plan():
    """The 15-minute plan, planned in the record's mean wind."""
    w0, w1 = (np.array(wind_vector_mps(*w)) for w in (WIND_START, WIND_END))
    speed, from_deg = wind_polar(*(0.5 * (w0 + w1)))
    return circle_plan(duration_s=DURATION_S, radius_m=600.0, wind_speed_mps=float(speed),
                       wind_from_deg=float(from_deg), sweeps=3)


def loiter_flight(seed, drifting=True, turbulence_mps=0.5):
    """(Flight, Truth) of the loiter, the wind drifting (or constant at its mean)."""
    from pitotcal.maneuvers import simulate

    return simulate(loiter_plan(), seed=seed, turbulence_mps=turbulence_mps,
                    wind_drift_mps2=drift_mps2() if drifting else (0.0, 0.0),
                    gps_noise_mps=0.1)


def true_wind_mps(truth, time_s):
    """The true wind (north, east) at `time_s` without the gusts: mean + drift (t - t_mid)."""
    t_mid = 0.5 * DURATION_S
    drift = truth.options["wind_drift_mps2"] if isinstance(truth.options, dict) else \
        truth.options.wind_drift_mps2
    t = np.asarray(time_s, dtype=float) - t_mid
    return truth.wind_n_mps + drift[0] * t, truth.wind_e_mps + drift[1] * t


def scored(seed, drifting=True, wind="auto"):
    """{dv_err_max_kt, dv_2sigma_max_kt, covered, kind, statistic, warned} of one flight."""
    from pitotcal.estimation import identify
    from pitotcal.studies.engine.common import score

    flight, truth = loiter_flight(seed, drifting)
    result = identify(flight, wind=wind)
    row = score(result, truth, flight)
    return {"dv_err_max_kt": row["dv_err_max_kt"], "dv_2sigma_max_kt": row["dv_2sigma_max_kt"],
            "covered": row["dv_inside_2sigma"] == 1.0, "kind": result.wind_model["kind"],
            "statistic": (result.wind_model["test"] or {}).get("statistic"),
            "warned": any("the wind drifted" in w for w in result.warnings),
            "k1_z": row["k1_z"], "k2_z": row["k2_z"]}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--constant", action="store_true", help="fly the mean wind, no drift")
    parser.add_argument("--wind", default="auto")
    args = parser.parse_args(argv)
    rows = [scored(seed, not args.constant, args.wind) for seed in range(args.runs)]
    err = np.array([r["dv_err_max_kt"] for r in rows])
    band = np.array([r["dv_2sigma_max_kt"] for r in rows])
    z = np.array([[r["k1_z"], r["k2_z"]] for r in rows])
    print(f"{args.runs} flights, {'constant' if args.constant else 'drifting'} wind, "
          f"wind={args.wind}: median max|dV error| {np.median(err):.3f} kt, 90th percentile "
          f"{np.percentile(err, 90):.3f} kt; median max 2sigma {np.median(band):.3f} kt; "
          f"2sigma covers the truth on {sum(r['covered'] for r in rows)}/{len(rows)}; "
          f"drift chosen on {sum(r['kind'] == 'drifting' for r in rows)}/{len(rows)}, "
          f"warned on {sum(r['warned'] for r in rows)}/{len(rows)}; rms z k1 "
          f"{np.sqrt(np.mean(z[:, 0] ** 2)):.2f}, k2 {np.sqrt(np.mean(z[:, 1] ** 2)):.2f}")
    return rows


if __name__ == "__main__":
    main()
