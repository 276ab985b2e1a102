"""Two airspeed sensors sharing the wind model: seeded flights with known truth, for the joint
fit's tests and the study of docs/measured.md ("Two airspeed sensors: the shared wind model").

Cases:

- ``windows``: two calibration windows 600 s apart (`synthetic.two_window_sensor_flights`,
  300 s each at 10 Hz, 0.5 m/s turbulence), 5 m/s from 270° and 8 m/s from 300°;
- ``drifting``: 900 s at 10 Hz (`synthetic.two_sensor_flights`, 8 turns, 0.5 m/s
  turbulence), the wind drifting linearly from 5 m/s from 260° to 7.5 m/s from 300° (2.5 m/s
  in speed, 40° in direction, 4.9 m/s of the vector);
- ``turbulence``: the simulator (`maneuvers.fly.simulator.simulate`: the speed loop puts the
  gust into q_ci) on the 15-minute loiter of `driftflights` in its mean wind, 1 m/s
  turbulence, 10 Hz; the second sensor's q_ci from the true q_c (`Truth.history`);
- ``sim_drifting``: the same loiter in `driftflights`' drifting wind (9 m/s from 270° to 11 m/s
  from 310°), 0.5 m/s turbulence.

Sensor a: k = (0.02, -15) (the simulator's own true k in ``turbulence``), sensor b: (-0.03, 10).

    PYTHONPATH=tests python -m two_sensor_wind --case windows --runs 30 [--impl MODULE]

prints the mean and rms z of k1, k2 of both sensors and their 2σ coverage; ``--impl`` names a
module with an `identify_sensors` (default `pitotcal.estimation.identification.multi_sensor`).
"""

import argparse
import importlib

import numpy as np

K_B = (-0.03, 10.0)
DRIFT_FROM = (5.0, 260.0)
DRIFT_TO = (7.5, 300.0)
DRIFT_S = 900.0


def windows_flights(seed):
    from synthetic import two_window_sensor_flights

    return two_window_sensor_flights(seed=seed, n=3000, rate_hz=10.0, turbulence_mps=0.5)


def drifting_flights(seed):
    from synthetic import two_sensor_flights, wind_vector

    w0, w1 = (np.array(wind_vector(*w)) for w in (DRIFT_FROM, DRIFT_TO))
    mid = 0.5 * (w0 + w1)
    return two_sensor_flights(seed=seed, n=9000, rate_hz=10.0, turbulence_mps=0.5,
                              wind_speed_mps=float(np.hypot(*mid)),
                              wind_from_deg=float(np.degrees(np.arctan2(-mid[1], -mid[0]))),
                              wind_drift_mps2=tuple((w1 - w0) / DRIFT_S), turns=8.0)


def turbulence_flights(seed, turbulence_mps=1.0, drifting=False):
    import dataclasses

    from driftflights import drift_mps2, loiter_plan

    from pitotcal.core.models import get_model, qci_from_qc_pa
    from pitotcal.maneuvers.fly.simulator import simulate

    flight, truth = simulate(loiter_plan(), seed=seed, turbulence_mps=turbulence_mps,
                             rate_hz=10.0, gps_noise_mps=0.1, keep_history=True,
                             wind_drift_mps2=drift_mps2() if drifting else (0.0, 0.0))
    qc = np.asarray(truth.history["qc_pa"])
    rng = np.random.default_rng(seed + 7919)
    qci = qci_from_qc_pa(get_model(truth.model), K_B, qc) + rng.standard_normal(qc.size) * 0.5
    fb = dataclasses.replace(flight, qci_pa=qci, source=f"{flight.source} sensor b")
    return flight, fb, {"k_a": tuple(truth.k), "k_b": K_B, "wind_n_mps": truth.wind_n_mps,
                        "wind_e_mps": truth.wind_e_mps}


def sim_drifting_flights(seed):
    return turbulence_flights(seed, turbulence_mps=0.5, drifting=True)


CASES = {"windows": windows_flights, "drifting": drifting_flights,
         "turbulence": turbulence_flights, "sim_drifting": sim_drifting_flights}


def scored(case, seed, impl="pitotcal.estimation.identification.multi_sensor"):
    """{z: [k1_a, k2_a, k1_b, k2_b], kind, iv} of one flight (z = error / reported sigma)."""
    fa, fb, truth = CASES[case](seed)
    identify_sensors = importlib.import_module(impl).identify_sensors
    air = "compressible" if case in ("turbulence", "sim_drifting") else "incompressible"
    results = identify_sensors([fa, fb], air=air)
    z, sd = [], []
    for res, k in zip(results, (truth["k_a"], truth["k_b"])):
        sd += [float(np.sqrt(res.internal_covariance[i, i])) for i in range(2)]
        z += [(res.internal_params[i] - k[i]) / sd[-2 + i] for i in range(2)]
    return {"z": z, "sd": sd, "kind": results[0].wind_model["kind"],
            "iv": not any("instrumental-variable refinement did not converge" in w
                          for w in results[0].warnings)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=sorted(CASES), default="windows")
    parser.add_argument("--runs", type=int, default=30)
    parser.add_argument("--impl", default="pitotcal.estimation.identification.multi_sensor")
    args = parser.parse_args(argv)
    rows = [scored(args.case, seed, args.impl) for seed in range(args.runs)]
    z = np.array([r["z"] for r in rows])
    sd = np.array([r["sd"] for r in rows])
    kinds = {k: sum(r["kind"] == k for r in rows) for k in sorted({r["kind"] for r in rows})}
    print(f"{args.case}, {args.runs} flights, {args.impl}: wind models {kinds}, IV converged "
          f"on {sum(r['iv'] for r in rows)}")
    for j, name in enumerate(("k1 a", "k2 a", "k1 b", "k2 b")):
        print(f"  {name}: mean z {np.mean(z[:, j]):+.2f}, rms z {np.sqrt(np.mean(z[:, j] ** 2)):.2f}, "
              f"2sigma covers {np.mean(np.abs(z[:, j]) < 2.0):.2f}, rms error "
              f"{np.sqrt(np.mean((z[:, j] * sd[:, j]) ** 2)):.4g}, median sigma "
              f"{np.median(sd[:, j]):.4g} (internal units)")
    return rows


if __name__ == "__main__":
    main()
