"""core.information: sensitivities against the analytic derivative, the sandwich covariance
against the textbook formulas for white and AR(1) noise."""

import numpy as np

from pitotcal.core.information import (
    ResidualNoise,
    delta_v_band_kt,
    least_squares_covariance,
    qci_sensitivities,
    residual_covariance,
)
from pitotcal.core.models import delta_v_kt, get_model

RHO = 1.2


def test_wind_sensitivity_is_the_analytic_one():
    # constant model (f = k1): q_ci = (1 - k1) rho |Vg - W|^2 / 2, d/dW_n = -(1 - k1) rho V cos
    psi = np.linspace(0, 2 * np.pi, 37)
    jac = qci_sensitivities(np.full(37, 40.0), psi, RHO, get_model("constant"), (0.02,),
                            (3.0, -4.0))
    np.testing.assert_allclose(jac[:, 1], -0.98 * RHO * 40.0 * np.cos(psi), rtol=1e-6,
                               atol=1e-6)
    np.testing.assert_allclose(jac[:, 2], -0.98 * RHO * 40.0 * np.sin(psi), rtol=1e-6,
                               atol=1e-6)
    np.testing.assert_allclose(jac[:, 0], -0.5 * RHO * 40.0 ** 2, rtol=1e-6)


def test_white_noise_gives_the_cramer_rao_covariance():
    rng = np.random.default_rng(0)
    jac = rng.normal(size=(200, 3))
    cov = least_squares_covariance(jac, 4.0 * np.eye(200))
    np.testing.assert_allclose(cov, 4.0 * np.linalg.inv(jac.T @ jac), rtol=1e-10)


def test_ar1_noise_variance_of_a_mean():
    # the mean of N samples of AR(1) noise, a = exp(-dt / tau): the textbook variance
    n, tau = 400, 5.0
    t = np.arange(n, dtype=float)
    noise = ResidualNoise(turbulence_mps=1.0, tau_s=tau, qc_noise_pa=0.0, gps_noise_mps=0.0)
    sigma = residual_covariance(t, np.full(n, 1.0 / RHO), RHO, noise)
    var = least_squares_covariance(np.ones((n, 1)), sigma)[0, 0]
    a = np.exp(-1.0 / tau)
    k = np.arange(1, n)
    expected = (1 + 2 * np.sum((1 - k / n) * a ** k)) / n
    assert abs(var / expected - 1) < 1e-10
    # about 2 tau per independent sample
    assert 1.5 * tau < var * n < 2.5 * tau


def test_delta_v_band_matches_a_monte_carlo_of_k():
    model, k = get_model("inverse"), np.array([0.02, -15.0])
    cov = np.array([[1e-4, -0.05], [-0.05, 40.0]])
    vi = np.array([70.0, 85.0, 100.0])
    band = delta_v_band_kt(model, k, cov, vi)
    draws = np.random.default_rng(1).multivariate_normal(k, cov, 4000)
    dv = np.array([delta_v_kt(model, d, vi) for d in draws])
    np.testing.assert_allclose(band, 2 * dv.std(axis=0), rtol=0.05)
