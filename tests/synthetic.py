"""A small seeded generator of calibration flights with known truth, for the tests.

The full simulator lives in `maneuvers.simulate`; this one is deliberately simple so the
estimation tests do not depend on it: the aircraft turns at a constant rate while q sweeps
uniformly from q_lo to q_hi; the air mass moves with the mean wind plus first-order
Gauss-Markov (Dryden-like) turbulence; GPS may be slower (sample-and-hold) and noisy.
"""

import dataclasses

import numpy as np

from pitotcal.core.flight import Flight
from pitotcal.core.models import get_model, qci_from_qc_pa
from pitotcal.core.units import RHO0_KGM3, kt_to_mps


def wind_vector(speed_mps, from_deg):
    """(north, east) air-mass velocity of a wind of this speed blowing FROM `from_deg`."""
    a = np.radians(from_deg)
    return -speed_mps * np.cos(a), -speed_mps * np.sin(a)


def synthetic_flight(seed=0, n=16000, rate_hz=50.0, model="inverse", k=(0.02, -15.0),
                     wind_speed_mps=5.0, wind_from_deg=270.0, cas_kt=(70.0, 100.0),
                     turns=3.0, turbulence_mps=0.0, turbulence_length_m=300.0,
                     gps_rate_hz=None, gps_noise_mps=0.0, qc_noise_pa=0.3,
                     quantization_pa=0.0, rho_kgm3=1.196, vertical=False,
                     wind_drift_mps2=(0.0, 0.0)):
    """Return (Flight, truth); truth = {"model", "parameters": {...}, "k": tuple}.

    `turns` is the number of full heading revolutions (0: straight and level, unobservable).
    `wind_drift_mps2` (north, east): the mean wind drifts linearly, the given wind at the
    record's middle. Truth wind is the time-average of the wind actually flown through
    (turbulence and drift included).
    """
    rng = np.random.default_rng(seed)
    dt = 1.0 / rate_hz
    t = np.arange(n) * dt
    frac = t / t[-1]
    qlo, qhi = (0.5 * RHO0_KGM3 * kt_to_mps(v) ** 2 for v in cas_kt)
    qc = qlo + (qhi - qlo) * frac                       # uniform in q (paper section IV)
    tas = np.sqrt(2.0 * qc / rho_kgm3)
    psi = 2.0 * np.pi * turns * frac + rng.uniform(0, 2 * np.pi)

    wn0, we0 = wind_vector(wind_speed_mps, wind_from_deg)
    turb = np.zeros((n, 2))
    if turbulence_mps > 0:
        tau = turbulence_length_m / np.mean(tas)
        a = np.exp(-dt / tau)
        e = rng.standard_normal((n, 2)) * turbulence_mps * np.sqrt(1 - a * a)
        turb[0] = rng.standard_normal(2) * turbulence_mps
        for i in range(1, n):
            turb[i] = a * turb[i - 1] + e[i]
    wn = wn0 + turb[:, 0] + wind_drift_mps2[0] * (t - 0.5 * t[-1])
    we = we0 + turb[:, 1] + wind_drift_mps2[1] * (t - 0.5 * t[-1])
    vn = tas * np.cos(psi) + wn
    ve = tas * np.sin(psi) + we
    vd = 0.5 * np.sin(2 * np.pi * t / 30.0) if vertical else None
    if vertical:
        # climb rate adds to the true airspeed magnitude: keep q_c consistent with it
        tas_h = np.sqrt(np.maximum(tas ** 2 - vd ** 2, 1.0))
        vn = tas_h * np.cos(psi) + wn
        ve = tas_h * np.sin(psi) + we

    gps_n, gps_e = vn.copy(), ve.copy()
    if gps_noise_mps > 0:
        held = _hold_index(t, gps_rate_hz)
        noise = rng.standard_normal((n, 2)) * gps_noise_mps
        gps_n += noise[held, 0]
        gps_e += noise[held, 1]
    if gps_rate_hz:
        held = _hold_index(t, gps_rate_hz)
        gps_n, gps_e = gps_n[held], gps_e[held]

    m = get_model(model)
    qci = qci_from_qc_pa(m, k, qc) + rng.standard_normal(n) * qc_noise_pa
    if quantization_pa > 0:
        qci = np.round(qci / quantization_pa) * quantization_pa

    flight = Flight(time_s=t, qci_pa=qci, gps_vn_mps=gps_n, gps_ve_mps=gps_e,
                    rho_kgm3=np.full(n, rho_kgm3), gps_vd_mps=vd, source=f"synthetic(seed={seed})")
    mean_n, mean_e = wn.mean(), we.mean()
    truth = {
        "model": model,
        "k": tuple(k),
        "parameters": {
            **dict(zip(m.params, k)),
            "wind_speed_mps": float(np.hypot(mean_n, mean_e)),
            "wind_from_deg": float(np.degrees(np.arctan2(-mean_e, -mean_n)) % 360.0),
        },
        "wind_n_mps": float(mean_n),
        "wind_e_mps": float(mean_e),
    }
    return flight, truth


def with_ground_rolls(flight, still_s=10.0, roll_s=10.0):
    """`flight` between a take-off and a landing on the ground, for the log readers' cuts.

    Before the flight the aircraft stands still for `still_s`, then accelerates uniformly along
    its first ground track to its first ground velocity in `roll_s`; after the flight it
    decelerates the same way along its last track and stands still again. On the ground q_ci
    is the flight's first (last) q_ci scaled with the squared speed, with 0.3 Pa noise around
    zero when standing. Returns (Flight, roll_start_s, roll_end_s): when the take-off roll
    starts and the landing roll ends.
    """
    dt = float(np.median(np.diff(flight.time_s)))
    n_still, n_roll = round(still_s / dt), round(roll_s / dt)
    rng = np.random.default_rng(0)

    def ground(i, reverse):
        speed = np.r_[np.zeros(n_still), np.arange(1, n_roll + 1) / n_roll]   # 0..1
        if reverse:
            speed = speed[::-1]
        q = flight.qci_pa[i] * speed ** 2 + rng.standard_normal(speed.size) * 0.3 * (speed == 0)
        return (q, flight.gps_vn_mps[i] * speed, flight.gps_ve_mps[i] * speed)

    before, after = ground(0, False), ground(-1, True)
    n_before, n_after = before[0].size, after[0].size
    t = flight.time_s[0] + dt * np.arange(-n_before, flight.n + n_after)
    join = [np.r_[b, x, a] for b, x, a in zip(before, (flight.qci_pa, flight.gps_vn_mps,
                                                        flight.gps_ve_mps), after)]
    vd = (np.r_[np.zeros(n_before), flight.gps_vd_mps, np.zeros(n_after)]
          if flight.gps_vd_mps is not None else None)
    rho = np.full(t.size, flight.rho_kgm3[0])
    out = Flight(time_s=t - t[0], qci_pa=join[0], gps_vn_mps=join[1], gps_ve_mps=join[2],
                 rho_kgm3=rho, gps_vd_mps=vd, source=flight.source)
    return out, still_s, out.time_s[-1] - still_s


def _hold_index(t, rate_hz):
    """Index of the latest sample at or before each GPS update time (sample-and-hold)."""
    if not rate_hz:
        return np.arange(t.size)
    period = 1.0 / rate_hz
    tick = np.floor((t - t[0]) / period + 1e-9) * period + t[0]
    return np.searchsorted(t, tick - 1e-9)


def reference_static_flight():
    """A simulated compressible flight (90-150 KCAS at 8,000 ft, calm, seed 2) with a reference
    static pressure 40 Pa below the static port's."""
    import dataclasses

    from plans import circle_plan

    from pitotcal.maneuvers.fly.simulator import simulate

    plan = circle_plan(duration_s=180.0, cas_kt=(90.0, 150.0), radius_m=1500.0,
                       altitude_m=2438.4, wind_speed_mps=5.0)
    flight, _ = simulate(plan, seed=2, turbulence_mps=0.0, rate_hz=10.0,
                         air_data="compressible")
    return dataclasses.replace(flight, ps_ref_pa=flight.ps_pa - 40.0)


def two_sensor_flights(seed=0, k_a=(0.02, -15.0), k_b=(-0.03, 10.0), model="inverse",
                       qc_noise_pa=0.3, **kw):
    """Two airspeed sensors on one simulated flight (`synthetic_flight`'s, keywords passed on):
    the same true q_c, GPS and wind, each sensor its own pressure error and independent noise.

    Returns (flight_a, flight_b, truth): truth as `synthetic_flight`'s, with "k_a" and "k_b".
    """
    clean, truth = synthetic_flight(seed=seed, model="constant", k=(0.0,), qc_noise_pa=0.0, **kw)
    rng = np.random.default_rng(seed + 7919)
    m = get_model(model)
    flights = []
    for name, k in (("a", k_a), ("b", k_b)):
        qci = qci_from_qc_pa(m, k, clean.qci_pa) + rng.standard_normal(clean.n) * qc_noise_pa
        flights.append(dataclasses.replace(clean, qci_pa=qci,
                                           source=f"synthetic(seed={seed}, sensor {name})"))
    return flights[0], flights[1], {**truth, "k_a": tuple(k_a), "k_b": tuple(k_b)}


def two_window_sensor_flights(seed=0, winds=((5.0, 270.0), (8.0, 300.0)), gap_s=600.0, **kw):
    """Two airspeed sensors over two calibration windows `gap_s` apart (`Flight.segment` 0 and
    1), each window a `two_sensor_flights` flight with its own constant wind (speed m/s, from
    deg) and the same calibrations.

    Returns (flight_a, flight_b, truth): truth with "k_a", "k_b", "windows" [(wind_n, wind_e)
    per window, the average flown through] and the record's mean "wind_n_mps", "wind_e_mps".
    """
    parts = [two_sensor_flights(seed=seed + 1000 * i, wind_speed_mps=speed, wind_from_deg=frm,
                                **kw) for i, (speed, frm) in enumerate(winds)]
    start = parts[0][0].time_s[-1] + gap_s
    out = []
    for j in range(2):
        one, two = parts[0][j], parts[1][j]
        fields = {name: np.concatenate([getattr(one, name), getattr(two, name)])
                  for name in ("qci_pa", "gps_vn_mps", "gps_ve_mps", "rho_kgm3")}
        out.append(Flight(time_s=np.concatenate([one.time_s, two.time_s + start]), **fields,
                          segment=np.repeat([0, 1], [one.n, two.n]),
                          source=f"synthetic(seed={seed}, two windows, sensor {'ab'[j]})"))
    windows = [(t["wind_n_mps"], t["wind_e_mps"]) for _, _, t in parts]
    n = [p[0].n for p in parts]
    mean = np.average(np.array(windows), axis=0, weights=n)
    return out[0], out[1], {"k_a": parts[0][2]["k_a"], "k_b": parts[0][2]["k_b"],
                            "windows": windows, "wind_n_mps": float(mean[0]),
                            "wind_e_mps": float(mean[1])}
