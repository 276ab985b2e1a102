"""The predicted information of a calibration flight: how well a planned trajectory determines
the pressure-error coefficients and the wind, before it is flown.

The output is the measured impact pressure q_ci predicted from the GPS ground velocity through
the measurement model (core.measurement, core.models). Its sensitivities to the unknowns
theta = (k..., wind_n, wind_e) along the trajectory form J; the residual of an unmodelled gust
u along the flight path is q_c - q_c(no gust) ~ rho V u, so the residuals are colored:

    Sigma_ij = rho^2 V_i V_j sigma_u^2 exp(-|t_i - t_j| / tau) + s_i^2 delta_ij

(Dryden's along-path autocorrelation, exp(-xi / L_u) in distance, is AR(1) in time with
tau = L_u / V), s_i the white part (transducer and GPS noise per grid sample). The estimate is
least squares, so its covariance is the sandwich (J^T J)^-1 J^T Sigma J (J^T J)^-1 - what the
colored-residual covariance of `estimation` estimates from the residuals after the flight.

numpy only; no import of maneuvers or estimation (layers).
"""

import numpy as np

from pitotcal.core.measurement import impact_pressure_pa, tas_squared
from pitotcal.core.models import delta_v_kt, qci_from_qc_pa
from pitotcal.core.propagation import band, gradient

__all__ = ["ResidualNoise", "delta_v_band_kt", "least_squares_covariance",
           "predicted_qci_pa", "qci_sensitivities", "residual_covariance",
           "residual_covariances"]


class ResidualNoise:
    """The residual noise model of a flight: turbulence and white sensor noise.

    Parameters
    ----------
    turbulence_mps : float
        RMS gust along the flight path, sigma_u, m/s.
    tau_s : float
        Correlation time of that gust, L_u / V, s.
    qc_noise_pa : float
        White transducer noise per sample, Pa, at `rate_hz`.
    rate_hz : float
        Sample rate of the transducer.
    gps_noise_mps, gps_rate_hz : float
        GPS velocity noise per component and its rate (each fix held until the next).
    """

    def __init__(self, turbulence_mps=0.5, tau_s=6.0, qc_noise_pa=0.5, rate_hz=50.0,
                 gps_noise_mps=0.05, gps_rate_hz=5.0):
        self.turbulence_mps, self.tau_s = float(turbulence_mps), float(tau_s)
        self.qc_noise_pa, self.rate_hz = float(qc_noise_pa), float(rate_hz)
        self.gps_noise_mps, self.gps_rate_hz = float(gps_noise_mps), float(gps_rate_hz)


def predicted_qci_pa(theta, gps_vn, gps_ve, rho_kgm3, model):
    """q_ci the model predicts from GPS ground velocity `gps_vn`, `gps_ve` (m/s) for
    theta = (k..., wind_n_mps, wind_e_mps): V_t^2, q_c = rho V_t^2 / 2, the sensor's q_ci."""
    theta = np.asarray(theta, dtype=float)
    qc = impact_pressure_pa(rho_kgm3, tas_squared(gps_vn, gps_ve, theta[-2], theta[-1]))
    return qci_from_qc_pa(model, theta[:-2], qc)


def qci_sensitivities(tas_mps, heading_rad, rho_kgm3, model, k, wind_ne_mps):
    """J = d q_ci / d theta, theta = (k..., wind_n, wind_e), shape (N, p + 2), Pa per unit.

    Central differences of the measurement model at the ground velocity of the planned
    trajectory (air velocity at `heading_rad` plus the wind).
    """
    tas = np.asarray(tas_mps, dtype=float)
    psi = np.asarray(heading_rad, dtype=float)
    vn = tas * np.cos(psi) + wind_ne_mps[0]
    ve = tas * np.sin(psi) + wind_ne_mps[1]
    theta = np.r_[np.asarray(k, dtype=float), np.asarray(wind_ne_mps, dtype=float)]
    cols = []
    for i in range(theta.size):
        h = 1e-4 * max(abs(theta[i]), 1e-2 if i < theta.size - 2 else 1.0)
        up, dn = theta.copy(), theta.copy()
        up[i] += h
        dn[i] -= h
        cols.append((predicted_qci_pa(up, vn, ve, rho_kgm3, model)
                     - predicted_qci_pa(dn, vn, ve, rho_kgm3, model))
                    / (2 * h))
    return np.column_stack(cols)


def residual_covariance(time_s, tas_mps, rho_kgm3, noise, *, stationary=True):
    """Sigma (N x N, Pa^2) of the q residuals on a grid of times (see the module notes).

    The white parts are scaled to the grid spacing dt: a sample on the grid stands for
    dt * rate_hz transducer samples (variance / that count) and for dt * gps_rate_hz GPS fixes.
    `stationary` (default) gives every sample the flight's mean-square gust pressure
    rho^2 <V^2> sigma_u^2, as the colored-residual covariance of `estimation` assumes (it fits
    one autocovariance to all residuals): the bounds `identify` will report. False keeps
    rho^2 V_i^2 sigma_u^2 at each sample: the estimate's actual scatter.
    """
    both = residual_covariances(time_s, tas_mps, rho_kgm3, noise)
    return both[0] if stationary else both[1]


def residual_covariances(time_s, tas_mps, rho_kgm3, noise):
    """(stationary, actual) `residual_covariance` of one grid, sharing the AR(1) kernel."""
    t = np.asarray(time_s, dtype=float)
    v = np.asarray(tas_mps, dtype=float)
    dt = float(np.median(np.diff(t)))
    gust = rho_kgm3 * v * noise.turbulence_mps
    kernel = np.exp(-np.abs(t[:, None] - t[None, :]) / max(noise.tau_s, 1e-9))
    white = noise.qc_noise_pa ** 2 / max(dt * noise.rate_hz, 1.0)
    if noise.gps_rate_hz > 0:
        # q_c = rho V^2 / 2: a velocity error e along the track moves it by rho V e
        white = white + (rho_kgm3 * v * noise.gps_noise_mps) ** 2 / max(dt * noise.gps_rate_hz,
                                                                         1.0)
    out = []
    for g in (np.full_like(v, np.sqrt(np.mean(gust ** 2))), gust):
        sigma = np.outer(g, g) * kernel
        sigma[np.diag_indices_from(sigma)] += white
        out.append(sigma)
    return tuple(out)


def least_squares_covariance(jac, sigma):
    """Covariance of the least-squares estimate with residual covariance `sigma`:
    (J^T J)^-1 J^T Sigma J (J^T J)^-1, columns scaled for conditioning."""
    scale = np.sqrt(np.sum(jac ** 2, axis=0))
    scale[scale == 0] = 1.0
    js = jac / scale
    inv = np.linalg.pinv(js.T @ js)
    cov = inv @ (js.T @ sigma @ js) @ inv
    return cov / np.outer(scale, scale)


def delta_v_band_kt(model, k, cov_k, vi_kt):
    """Two-sigma half-width of the airspeed correction ΔV at indicated `vi_kt` (delta method,
    the coefficients' covariance `cov_k`)."""
    g = gradient(lambda kk: delta_v_kt(model, kk, vi_kt), k)
    return 2.0 * band(g, cov_k)
