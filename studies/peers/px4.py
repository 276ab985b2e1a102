"""PX4's airspeed-selector wind estimator, re-implemented as a peer baseline.

Written from `src/lib/wind_estimator/WindEstimator.cpp` with the CAS-scale check of
`src/modules/airspeed_selector/AirspeedValidator.cpp`: an EKF on [wind N, wind E, TAS scale k]
fused at up to 10 Hz, and a validation of the scale over 12 course bins. Choices the sources
leave open are marked "guess".

Measurement model: TAS_raw = k · |v_gps − w| with TAS_raw = sqrt(2 q_ci / ρ) (scale 1), so
k² = q_ci/q_c = 1 − k1 and the CAS scale is s = 1/k. Initialisation (first sample above 3 m/s
ground speed): w = v_gps − TAS_raw · (cos χ, sin χ), k = 1/s0, and the wind covariance from the
Jacobian of that expression with respect to the GPS velocity, heading, sideslip and TAS. P
diagonals are capped at 25 (wind) and 0.1 (scale) (here by scaling the row and column, which
keeps P positive semi-definite; clipping only the diagonal, as the source does, made this
float64 copy re-initialise in a loop); a non-positive innovation variance re-initialises the
filter. This follows the 2023 release; the 2018-2021 one added the wind process noise to the N-E
covariance as well and initialised the wind covariance from the GPS variance only, which pins the
wind in one direction.

Scale validation (AirspeedValidator): the course over ground falls in one of 12 bins holding the
latest ground speed and raw TAS; once all 12 are filled, the new scale replaces the validated one
if it brings Σ TAS·s closer to Σ ground speed. Guess: the validated scale is the CAS scale
s = 1/k of the filter state (releases differ in whether the state or its inverse multiplies the
measurement).
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core.checks import positive
from pitotcal.core.errors import PitotcalError

from .baselines import BaselineTrack, causal_samples, check_flight

__all__ = ["N_COURSE_BINS", "px4_wind_estimator"]

N_COURSE_BINS = 12          # PX4 validates the scale over 12 course segments of 30 degrees
_VARIANCE_CAPS = np.array([25.0, 25.0, 0.1])      # PX4's limits on the P diagonal
_MIN_GROUND_SPEED_MPS = 3.0                       # PX4 does not initialise on the ground


@dataclass(frozen=True)
class _Tuning:
    """The filter's settings in its own terms (variances)."""

    r_tas: float            # TAS measurement variance, (m/s)^2
    q_wind: float           # wind process noise, (m/s)^2 per s
    q_scale: float          # scale process noise, 1 per s
    gate_sd: float
    gps_vel_var: float
    angle_var: float        # heading + sideslip variance at initialisation, rad^2
    scale_var0: float
    k0: float               # initial TAS scale, 1/s0


def px4_wind_estimator(flight, *, fuse_rate_hz=10.0, wind_nsd=0.1, scale_nsd=1e-4,
                       tas_noise_mps=1.4, gate_sd=4.0, gps_vel_var=0.01, heading_err_deg=10.0,
                       sideslip_err_deg=15.0, scale_var0=1e-4, initial_scale=1.0,
                       check_reset_s=100.0, max_scale_step=0.05):
    """PX4-style airspeed-selector wind estimator: EKF [wind N, wind E, TAS scale k].

    Parameters
    ----------
    flight : Flight
    fuse_rate_hz : float
        Airspeed fusion rate (PX4 fuses at most at 10 Hz; covariance prediction runs at 1 Hz).
    wind_nsd, scale_nsd : float
        Process noise spectral densities of the wind, m/s^2/sqrt(Hz), and of the scale,
        1/s/sqrt(Hz) (ASPD_WIND_NSD 0.1, ASPD_SCALE_NSD 1e-4): P grows by nsd^2 · dt.
    tas_noise_mps : float
        TAS measurement noise (ASPD_TAS_NOISE 1.4 m/s).
    gate_sd : float
        Innovation gate in standard deviations (ASPD_TAS_GATE 4); rejected samples are skipped.
    gps_vel_var : float
        Horizontal GPS velocity variance used at initialisation, (m/s)^2.
    heading_err_deg, sideslip_err_deg : float
        1-sigma heading and sideslip errors assumed at initialisation (guess: the source's
        constants are not in the files read; course over ground stands in for heading here).
    scale_var0 : float
        Initial variance of the scale state (guess from older releases: 1e-4).
    initial_scale : float
        The CAS scale s = 1/k assumed before validation (ASPD_SCALE, default 1).
    check_reset_s, max_scale_step : float
        The 12-course-bin validation restarts every `check_reset_s`; each accepted step of the
        validated scale is limited to `max_scale_step` (PX4: 100 s, 0.05).

    Returns
    -------
    BaselineTrack
        With `k1_validated`: the scale PX4 would apply after its course-bin check. The model
        and its choices: module docstring.
    """
    check_flight(flight, "px4_wind_estimator")
    for what, value in (("fuse_rate_hz", fuse_rate_hz), ("wind_nsd", wind_nsd),
                        ("scale_nsd", scale_nsd), ("tas_noise_mps", tas_noise_mps),
                        ("gate_sd", gate_sd), ("gps_vel_var", gps_vel_var),
                        ("heading_err_deg", heading_err_deg),
                        ("sideslip_err_deg", sideslip_err_deg), ("scale_var0", scale_var0),
                        ("initial_scale", initial_scale)):
        positive(what, value)
    t, qci, vn, ve, vd, rho = causal_samples(flight, fuse_rate_hz)
    tas_raw = np.sqrt(2.0 * qci / rho)
    tuning = _Tuning(
        r_tas=tas_noise_mps ** 2, q_wind=wind_nsd ** 2, q_scale=scale_nsd ** 2, gate_sd=gate_sd,
        gps_vel_var=gps_vel_var,
        angle_var=np.radians(heading_err_deg) ** 2 + np.radians(sideslip_err_deg) ** 2,
        scale_var0=scale_var0, k0=1.0 / initial_scale)
    states, covs, n_rejected, n_resets = _run_filter(t, vn, ve, vd, tas_raw, tuning)
    validated = _validated_scale(t, vn, ve, vd, tas_raw, states[:, 2], initial_scale,
                                 check_reset_s, max_scale_step)
    ok = np.isfinite(states[:, 0])
    if not np.any(ok):
        raise PitotcalError("px4_wind_estimator: ground speed never exceeded 3 m/s, the filter "
                            "never initialised")
    states, covs, t, validated = states[ok], covs[ok], t[ok], validated[ok]
    k = states[:, 2]
    return BaselineTrack(
        name="px4", time_s=t, wind_n_mps=states[:, 0], wind_e_mps=states[:, 1],
        wind_var_n=covs[:, 0, 0], wind_var_e=covs[:, 1, 1],
        k1=1.0 - k ** 2, k1_std=2.0 * np.abs(k) * np.sqrt(covs[:, 2, 2]),
        k1_validated=1.0 - validated ** 2, state=states, covariance=covs,
        n_rejected=n_rejected, n_resets=n_resets)


def _run_filter(t, vn, ve, vd, tas_raw, tuning):
    """The EKF over all samples: states and covariances (NaN before it initialises), and the
    counts of gated-out samples and of re-initialisations."""
    m = t.size
    states = np.full((m, 3), np.nan)
    covs = np.full((m, 3, 3), np.nan)
    x = P = t_last_predict = None
    n_rejected = n_resets = 0
    for i in range(m):
        if x is None:
            x, P = _initial_state(vn[i], ve[i], tas_raw[i], tuning)
            t_last_predict = t[i]
        else:
            if t[i] - t_last_predict >= 1.0 - 1e-9:     # covariance prediction at 1 Hz
                dt = t[i] - t_last_predict
                t_last_predict = t[i]
                P = P + np.diag([tuning.q_wind * dt, tuning.q_wind * dt, tuning.q_scale * dt])
            x, P, outcome = _fuse(x, P, vn[i], ve[i], vd[i], tas_raw[i], tuning)
            if outcome == "reset":
                x, P = _initial_state(vn[i], ve[i], tas_raw[i], tuning)
                n_resets += 1
            n_rejected += outcome == "rejected"
        if x is not None:
            states[i] = x
            covs[i] = P
    return states, covs, n_rejected, n_resets


def _initial_state(vn, ve, tas_raw, tuning):
    """(x0, P0) from one sample: the wind that closes the triangle with the course over ground
    as heading, and its covariance; (None, None) below 3 m/s ground speed."""
    gs = np.hypot(vn, ve)
    if gs < _MIN_GROUND_SPEED_MPS:
        return None, None
    c, s = vn / gs, ve / gs
    x0 = np.array([vn - tas_raw * c, ve - tas_raw * s, tuning.k0])
    across, along = np.array([s, -c]), np.array([c, s])
    P0 = np.zeros((3, 3))
    P0[:2, :2] = (tuning.gps_vel_var * np.eye(2)
                  + tas_raw ** 2 * tuning.angle_var * np.outer(across, across)
                  + tuning.r_tas * np.outer(along, along))
    P0[2, 2] = tuning.scale_var0
    return x0, _cap_variances(P0)


def _fuse(x, P, vn, ve, vd, tas_raw, tuning):
    """One TAS fusion: (x, P, outcome) with outcome "fused", "rejected" (innovation gate) or
    "reset" (the caller re-initialises)."""
    dn, de = vn - x[0], ve - x[1]
    norm3 = np.sqrt(dn * dn + de * de + vd * vd)
    H = np.array([-x[2] * dn / norm3, -x[2] * de / norm3, norm3])
    PH = P @ H
    S = H @ PH + tuning.r_tas
    innov = tas_raw - x[2] * norm3
    if S < 1e-7:
        return x, P, "reset"
    if innov * innov > tuning.gate_sd * tuning.gate_sd * S:
        return x, P, "rejected"
    K = PH / S
    x = x + K * innov
    P = P - np.outer(K, H @ P)
    if np.any(np.diag(P) < 0) or not np.all(np.isfinite(x)):
        return x, P, "reset"
    return x, _cap_variances(0.5 * (P + P.T)), "fused"


def _validated_scale(t, vn, ve, vd, tas_raw, k, initial_scale, check_reset_s, max_scale_step):
    """The TAS scale PX4 would apply at each sample after its 12-course-bin check (k: the
    filter's scale state, NaN before it initialises)."""
    validated = np.full(t.size, 1.0 / initial_scale)
    bins_gs = np.full(N_COURSE_BINS, np.nan)
    bins_tas = np.full(N_COURSE_BINS, np.nan)
    t_check = t[0]
    s_valid = initial_scale
    for i in range(t.size):
        if k[i] > 0:
            if t[i] - t_check > check_reset_s:
                bins_gs[:], bins_tas[:], t_check = np.nan, np.nan, t[i]
            course = np.arctan2(ve[i], vn[i]) % (2.0 * np.pi)
            j = min(int(N_COURSE_BINS * course / (2.0 * np.pi)), N_COURSE_BINS - 1)
            bins_gs[j] = np.sqrt(vn[i] ** 2 + ve[i] ** 2 + vd[i] ** 2)
            bins_tas[j] = tas_raw[i]
            if np.all(np.isfinite(bins_gs)):
                s_new = 1.0 / k[i]
                gs_sum, tas_sum = bins_gs.sum(), bins_tas.sum()
                if abs(gs_sum - tas_sum * s_new) < abs(gs_sum - tas_sum * s_valid):
                    s_valid = float(np.clip(s_new, s_valid - max_scale_step,
                                            s_valid + max_scale_step))
                bins_gs[:], bins_tas[:], t_check = np.nan, np.nan, t[i]
        validated[i] = 1.0 / s_valid
    return validated


def _cap_variances(P):
    """Limit P's diagonal to the caps by scaling each offending row and column (stays PSD)."""
    f = np.sqrt(np.minimum(1.0, _VARIANCE_CAPS / np.maximum(np.diag(P), 1e-300)))
    return P * np.outer(f, f)
