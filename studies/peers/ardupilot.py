"""ArduPilot's in-flight airspeed calibration (ARSPD_AUTOCAL), re-implemented as a peer baseline.

Written from `libraries/AP_Airspeed/Airspeed_Calibration.cpp` (algorithm by P. Riseborough):
a 3-state EKF on [wind N, wind E, z = 1/sqrt(ARSPD_RATIO)] updated once a second. Choices the
source leaves open are marked "guess".
"""

import numpy as np

from pitotcal.core.checks import positive
from pitotcal.core.units import RHO0_KGM3

from .baselines import BaselineTrack, causal_samples, check_flight

__all__ = ["ardupilot_autocal"]


def ardupilot_autocal(flight, *, initial_ratio=None, rate_hz=1.0, q_wind=0.01, q_scale=5e-7,
                      r_tas=1.0, p0=(100.0, 100.0, 1e-6), max_wind_mps=None):
    """ArduPilot-style ARSPD_AUTOCAL: 3-state EKF [wind N, wind E, z = 1/sqrt(ratio)].

    Parameters
    ----------
    flight : Flight
    initial_ratio : float, optional
        Starting ARSPD_RATIO. Default: the ratio of a perfect sensor, 2/ρ0 (k1 = 0).
        (ArduPilot's parameter default is 1.9936, i.e. k1 = 0.18.)
    rate_hz : float
        Update rate; ArduPilot calls the update once a second.
    q_wind, q_scale : float
        Process noise added to the wind variances, (m/s)^2, and to the z variance, per update
        (ArduPilot: 0.01 and 5e-7; older releases 1e-6).
    r_tas : float
        TAS measurement variance, (m/s)^2 (ArduPilot: 1.0).
    p0 : tuple of 3 float
        Initial variances (ArduPilot: 100, 100, 1e-6).
    max_wind_mps : float, optional
        Clamp on the wind states (ArduPilot uses the aircraft's maximum airspeed).

    Returns
    -------
    BaselineTrack

    Notes
    -----
    Each update: P += diag(q_wind, q_wind, q_scale); predicted measurement
    TAS_pred = z · |v_gps − w| (vertical GPS velocity included, no vertical wind); measured
    TAS_mea = sqrt(q_ci) · EAS2TAS, the airspeed of ratio 1, with EAS2TAS = sqrt(ρ0/ρ); scalar
    EKF update with H = [−z (v_n − w_n)/|·|, −z (v_e − w_e)/|·|, |·|] (horizontal norm, as in the
    source), symmetrised P, diagonals ≥ 0, z clamped to [0.5, 1]. Then ratio = 1/z².
    Guesses: the pressure is the latest sample at each tick (the autopilot's driver low-pass
    filters it first); EAS2TAS comes from the flight's density instead of the AHRS.
    """
    check_flight(flight, "ardupilot_autocal")
    for what, value in (("rate_hz", rate_hz), ("q_wind", q_wind), ("q_scale", q_scale),
                        ("r_tas", r_tas)):
        positive(what, value)
    ratio0 = 2.0 / RHO0_KGM3 if initial_ratio is None else positive("initial_ratio",
                                                                     initial_ratio)
    t, qci, vn, ve, vd, rho = causal_samples(flight, rate_hz)
    if max_wind_mps is None:
        max_wind_mps = 2.0 * float(np.max(np.hypot(vn, ve)))
    eas2tas = np.sqrt(RHO0_KGM3 / rho)
    tas_mea = np.sqrt(qci) * eas2tas

    x = np.array([0.0, 0.0, 1.0 / np.sqrt(ratio0)])
    P = np.diag(np.asarray(p0, dtype=float))
    Q = np.diag([q_wind, q_wind, q_scale])
    m = t.size
    states = np.empty((m, 3))
    covs = np.empty((m, 3, 3))
    for i in range(m):
        P = P + Q
        x, P = _update(x, P, vn[i], ve[i], vd[i], tas_mea[i], r_tas, max_wind_mps)
        states[i] = x
        covs[i] = P
    z = states[:, 2]
    return BaselineTrack(
        name="ardupilot", time_s=t, wind_n_mps=states[:, 0], wind_e_mps=states[:, 1],
        wind_var_n=covs[:, 0, 0], wind_var_e=covs[:, 1, 1],
        k1=1.0 - 2.0 * z ** 2 / RHO0_KGM3,
        k1_std=4.0 * z / RHO0_KGM3 * np.sqrt(covs[:, 2, 2]),
        state=states, covariance=covs)


def _update(x, P, vn, ve, vd, tas_mea, r_tas, max_wind_mps):
    """One scalar EKF update on the measured TAS; no update when the aircraft is (nearly) at
    rest relative to the wind estimate (the Jacobian would be undefined)."""
    dn, de = vn - x[0], ve - x[1]
    h2 = dn * dn + de * de
    if h2 <= 1e-6:
        return x, P
    norm3 = np.sqrt(h2 + vd * vd)
    nh = np.sqrt(h2)
    H = np.array([-x[2] * dn / nh, -x[2] * de / nh, nh])
    PH = P @ H
    S = H @ PH + r_tas
    K = PH / S
    x = x + K * (tas_mea - x[2] * norm3)
    P = P - np.outer(K, H @ P)
    P = 0.5 * (P + P.T)
    P[np.diag_indices(3)] = np.maximum(np.diag(P), 0.0)
    x[0] = np.clip(x[0], -max_wind_mps, max_wind_mps)
    x[1] = np.clip(x[1], -max_wind_mps, max_wind_mps)
    x[2] = np.clip(x[2], 0.5, 1.0)
    return x, P
