"""The predicted information of a calibration flight: how well a planned trajectory determines
the pressure-error coefficients and the wind, before it is flown.

The output is the measured impact pressure q_ci predicted from the GPS ground velocity through
the measurement model (core.measurement, core.models), in either air-data mode (default the
shared `DEFAULT_AIR_DATA`, the one `identify` fits). Its sensitivities to the unknowns
theta = (k..., wind_n, wind_e) along the trajectory form J; the residual of an unmodelled gust
u along the flight path is q_c - q_c(no gust) ~ rho V u, so the residuals are colored:

    Sigma_ij = rho^2 V_i V_j sigma_u^2 exp(-|t_i - t_j| / tau) + s_i^2 delta_ij

(Dryden's along-path autocorrelation, exp(-xi / L_u) in distance, is AR(1) in time with
tau = L_u / V), s_i the white part (transducer and GPS noise per grid sample). The estimate is
least squares, so its covariance is the sandwich (J^T J)^-1 J^T Sigma J (J^T J)^-1 - what the
colored-residual covariance of `estimation` estimates from the residuals after the flight.

`gust_covariance` writes the same residual as `estimation.uncertainty.residual_noise` does: a velocity
disturbance reaching q_ci through the wind sensitivities w_i (the last two columns of J), the
along-path gust g_i as |w_i| g_i and the GPS velocity noise as white noise of variance
|w_i|^2 sigma_gps^2, plus the transducer's white noise; `reported_covariance` widens the
sandwich for the degrees of freedom of a noise model fitted to one record, as `identify` does
(Student-t at N / tau, `student_t_widening`, which the estimator imports from here).

numpy only; no import of maneuvers or estimation (layers).
"""

import numpy as np

from .measurement import (
    DEFAULT_AIR_DATA,
    IncompressibleAir,
    StaticAir,
    TotalPressureAir,
    isa_air_of_density,
    predict_qci_pa,
)
from .models import delta_v_kt, qci_from_qc_pa
from .propagation import band, gradient

__all__ = [
    "DOF_TAUS",
    "ResidualNoise",
    "ar1_times",
    "delta_v_band_kt",
    "gust_covariance",
    "least_squares_covariance",
    "normal_isf",
    "predicted_qci_pa",
    "qci_sensitivities",
    "reported_covariance",
    "residual_covariance",
    "residual_covariances",
    "sandwich",
    "student_t_widening",
]

# Degrees of freedom of the fitted model's long-run variance (Student-t widening): one per
# long-run-weighted correlation time in the record (estimation.uncertainty.residual_noise and the design's
# prediction both use it). Measured on 60 flights per case (GPS 0.5 m/s
# + 0.5 m/s turbulence, Gauss-Markov GPS in calm air, T-2 in 1 m/s turbulence): the covariance
# module's one per 4 made k1/k2 1.2-1.5x too wide (rms z 0.6-0.9), none left the wind of the
# Gauss-Markov case at 85% coverage. Re-measured on 100 flights each of the own simulator and
# JSBSim in 1 m/s turbulence (docs/measured.md): one per 1 gives k1/k2 rms z
# 1.04 / 1.00 and 0.89 / 0.87; one per 1/4 1.12 / 1.07 and 0.94 / 0.91.
DOF_TAUS = 1.0


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


def _air(air, air_data):
    """An air-data object of `core.measurement` as it is; a density (kg/m³) as the ISA air of
    that density in the mode `air_data` (`measurement.isa_air_of_density`)."""
    if isinstance(air, (IncompressibleAir, StaticAir, TotalPressureAir)):
        return air
    return isa_air_of_density(air, air_data)


def predicted_qci_pa(theta, gps_vn, gps_ve, air, model, air_data=DEFAULT_AIR_DATA):
    """q_ci the model predicts from GPS ground velocity `gps_vn`, `gps_ve` (m/s) for
    theta = (k..., wind_n_mps, wind_e_mps): `core.measurement.predict_qci_pa` with the air
    data `air` (an air-data object, or a density taken as the ISA air of that density in the
    mode `air_data`)."""
    theta = np.asarray(theta, dtype=float)
    return predict_qci_pa(model, theta[:-2], gps_vn, gps_ve, theta[-2], theta[-1],
                          _air(air, air_data))


def qci_sensitivities(tas_mps, heading_rad, air, model, k, wind_ne_mps,
                      air_data=DEFAULT_AIR_DATA):
    """J = d q_ci / d theta, theta = (k..., wind_n, wind_e), shape (N, p + 2), Pa per unit.

    Implicit differentiation of the measurement model q_ci = q_c(V_t²) (1 - f(k, q_ci))
    (`core.measurement`) at the ground velocity of the planned trajectory (air velocity at
    `heading_rad` plus the wind), V_t² = |V_g - W|²:

        d q_ci / d k_i = -q_c df/dk_i / D,   d q_ci / d W = (1 - f) q_c' (-2 (V_g - W)) / D,
        D = 1 + q_c df/dq_ci,   q_c' = dq_c/dV_t² (ρ/2 incompressible),

    f's own derivatives by central differences (one solve of the fixed point, not one per
    unknown). V_g - W is the air velocity, so `wind_ne_mps` does not enter; it names the
    trajectory's wind for the reader and for `predicted_qci_pa`'s theta. `air` is an air-data
    object of `core.measurement` or a density (kg/m³), then the ISA air of that density in
    the mode `air_data` (default the shared `DEFAULT_AIR_DATA`, as `identify` fits).
    """
    tas = np.asarray(tas_mps, dtype=float)
    psi = np.asarray(heading_rad, dtype=float)
    k = np.asarray(k, dtype=float)
    air = _air(air, air_data)
    qc = air.qc_pa(tas ** 2)
    qci = qci_from_qc_pa(model, k, qc)
    f = model(k, qci)
    h = 1e-6 * qci
    denom = 1.0 + qc * (model(k, qci + h) - model(k, qci - h)) / (2.0 * h)
    cols = []
    for i in range(k.size):
        step = 1e-6 * max(abs(k[i]), 1e-2)
        up, dn = k.copy(), k.copy()
        up[i] += step
        dn[i] -= step
        cols.append(-qc * (model(up, qci) - model(dn, qci)) / (2.0 * step) / denom)
    gain = (1.0 - f) / denom * 2.0 * air.derivatives(tas ** 2)[0] * tas
    return np.column_stack(cols + [-gain * np.cos(psi), -gain * np.sin(psi)])


def residual_covariance(time_s, tas_mps, rho_kgm3, noise, *, stationary=True):
    """Sigma (N x N, Pa^2) of the q residuals on a grid of times (see the module notes).

    The white parts are scaled to the grid spacing dt: a sample on the grid stands for
    dt * rate_hz transducer samples (variance / that count) and for dt * gps_rate_hz GPS fixes.
    `stationary` (default) gives every sample the flight's mean-square gust pressure
    rho^2 <V^2> sigma_u^2 (one autocovariance for all residuals: a stationary noise model without
    velocity terms); False keeps rho^2 V_i^2 sigma_u^2 at each sample. The
    design scores with `reported_covariance`.
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
    return sandwich(jac, jac.T @ sigma @ jac)


def sandwich(jac, middle):
    """(J^T J)^-1 M (J^T J)^-1 for M = J^T Sigma J given, columns scaled for conditioning."""
    scale = np.sqrt(np.sum(jac ** 2, axis=0))
    scale[scale == 0] = 1.0
    js = jac / scale
    inv = np.linalg.pinv(js.T @ js)
    cov = inv @ (middle / np.outer(scale, scale)) @ inv
    return cov / np.outer(scale, scale)


def delta_v_band_kt(model, k, cov_k, vi_kt, air_data=DEFAULT_AIR_DATA):
    """Two-sigma half-width of the airspeed correction ΔV at indicated `vi_kt` (delta method,
    the coefficients' covariance `cov_k`), ΔV by the law of `air_data` as `identify` reports
    it (`core.models.delta_v_kt`)."""
    g = gradient(lambda kk: delta_v_kt(model, kk, vi_kt, air_data), k)
    return 2.0 * band(g, cov_k)


def gust_covariance(time_s, wind_sens, noise):
    """Sigma (N x N, Pa^2) of the q_ci residuals through the wind sensitivities.

    Sigma_ij = |w_i| |w_j| sigma_u^2 exp(-|t_i - t_j| / tau)
               + delta_ij (s_q^2 / (dt f_q) + |w_i|^2 sigma_gps^2 / (dt f_gps)),

    w_i = d q_ci / d wind at sample i (shape (N, 2), Pa per m/s): the along-path gust changes
    the airspeed, not the ground velocity; a GPS velocity error in any direction reaches q_ci
    through w_i . e. The white parts are per grid sample of spacing dt (a sample stands for
    dt f transducer samples or GPS fixes, at least one).
    """
    gust, white = _gust_parts(time_s, wind_sens, noise)
    sigma = np.outer(gust, gust) * _ar1_kernel(time_s, noise.tau_s)
    sigma[np.diag_indices_from(sigma)] += white
    return sigma


def _gust_parts(time_s, wind_sens, noise):
    """(|w| sigma_u, white variance) per sample of `gust_covariance`."""
    t = np.asarray(time_s, dtype=float)
    w = np.sqrt(np.sum(np.asarray(wind_sens, dtype=float) ** 2, axis=1))
    dt = float(np.median(np.diff(t)))
    white = noise.qc_noise_pa ** 2 / max(dt * noise.rate_hz, 1.0)
    if noise.gps_rate_hz > 0:
        white = white + (w * noise.gps_noise_mps) ** 2 / max(dt * noise.gps_rate_hz, 1.0)
    return w * noise.turbulence_mps, white * np.ones_like(w)


def _ar1_kernel(time_s, tau_s):
    """exp(-|t_i - t_j| / tau), N x N."""
    t = np.asarray(time_s, dtype=float)
    return np.exp(-np.abs(t[:, None] - t[None, :]) / max(tau_s, 1e-9))


def ar1_times(time_s, tau_s, x):
    """K @ x for K = exp(-|t_i - t_j| / tau) on increasing `time_s`, x of shape (N, p), in
    O(N p): the causal and the anti-causal exponential sums (K x = F + B - x), each a
    cumulative sum scaled by exp(t / tau) in stretches of at most 50 tau (no overflow)."""
    s = np.asarray(time_s, dtype=float) / max(tau_s, 1e-9)
    x = np.asarray(x, dtype=float)
    return _causal(s, x) + _causal(-s[::-1], x[::-1])[::-1] - x


def _causal(s, x):
    """F_i = sum_(j <= i) exp(-(s_i - s_j)) x_j for increasing s."""
    out = np.empty_like(x)
    edges = np.flatnonzero(np.diff(np.floor((s - s[0]) / 50.0))) + 1
    carry, last = np.zeros(x.shape[1:]), s[0]
    for a, b in zip(np.r_[0, edges], np.r_[edges, s.size]):
        e = np.exp(s[a:b] - s[a])[:, None]
        terms = e * x[a:b]
        terms[0] += carry * np.exp(-(s[a] - last))      # what came before the stretch
        out[a:b] = np.cumsum(terms, axis=0) / e
        carry, last = out[b - 1], s[b - 1]
    return out


def reported_covariance(jac, time_s, noise):
    """(reported, actual) covariance of theta for the sensitivities `jac` (N, p + 2) on the
    grid `time_s` under `gust_covariance`: the sandwich (actual: the estimate's scatter) and
    the sandwich widened by `student_t_widening` at N / (DOF_TAUS tau) degrees of freedom
    (reported: what `identify` reports, its noise model fitted to the same residuals)."""
    gust, white = _gust_parts(time_s, jac[:, -2:], noise)
    x = jac * gust[:, None]
    cov = sandwich(jac, x.T @ ar1_times(time_s, noise.tau_s, x)
                   + (jac * white[:, None]).T @ jac)
    t = np.asarray(time_s, dtype=float)
    dof = (t[-1] - t[0]) / (DOF_TAUS * max(noise.tau_s, 1e-9))
    return cov * student_t_widening(dof) ** 2, cov


def normal_isf(p):
    """z with P(Z > z) = p for a standard normal Z (scipy's norm.isf, from the standard
    library: importing scipy.stats costs ~0.6 s of every identify run)."""
    from statistics import NormalDist

    return -NormalDist().inv_cdf(float(p))


def student_t_widening(dof, z=2.0):
    """t_dof(Phi(z)) / z by the Cornish-Fisher expansion (within 1% of the exact value for
    dof >= 3); 1 for infinite dof. The estimator's widening too (`estimation.uncertainty.covariance`)."""
    if not np.isfinite(dof):
        return 1.0
    v = max(float(dof), 3.0)
    t = (z + (z ** 3 + z) / (4 * v) + (5 * z ** 5 + 16 * z ** 3 + 3 * z) / (96 * v ** 2)
         + (3 * z ** 7 + 19 * z ** 5 + 17 * z ** 3 - 15 * z) / (384 * v ** 3))
    return t / z
