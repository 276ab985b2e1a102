"""core.information: sensitivities against the analytic derivative, the sandwich covariance
against the textbook formulas for white and AR(1) noise."""

import numpy as np
import pytest

from pitotcal.core.errors import PitotcalError
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
                            (3.0, -4.0), air_data="incompressible")
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


def test_gust_covariance_is_the_along_path_gust_and_gps_noise_through_the_wind_sensitivities():
    from pitotcal.core.information import gust_covariance

    t = np.arange(0.0, 20.0, 0.5)
    psi = np.linspace(0.0, 3.0, t.size)
    w = np.column_stack([-50.0 * np.cos(psi), -50.0 * np.sin(psi)])     # |w| = 50 Pa per m/s
    noise = ResidualNoise(turbulence_mps=0.5, tau_s=4.0, qc_noise_pa=1.0, rate_hz=50.0,
                          gps_noise_mps=0.1, gps_rate_hz=5.0)
    sigma = gust_covariance(t, w, noise)
    lag = np.abs(t[:, None] - t[None, :])
    # the gust's sign does not depend on the heading: |w_i||w_j|, not w_i . w_j
    expected = 2500.0 * 0.25 * np.exp(-lag / 4.0)
    expected[np.diag_indices_from(expected)] += 1.0 / 25.0 + 2500.0 * 0.01 / 2.5
    np.testing.assert_allclose(sigma, expected, rtol=1e-12)


def test_student_t_widening_is_the_t_quantile():
    from scipy.stats import norm, t

    from pitotcal.core.information import student_t_widening

    for dof in (3.0, 5.0, 10.0, 34.0, 200.0):
        exact = t.ppf(norm.cdf(2.0), dof) / 2.0
        assert abs(student_t_widening(dof) / exact - 1.0) < 0.01, dof
    assert student_t_widening(np.inf) == 1.0


def test_reported_covariance_is_the_sandwich_widened_for_the_records_correlation_times():
    from pitotcal.core.information import gust_covariance, reported_covariance, student_t_widening

    t = np.arange(0.0, 120.0, 1.0)
    psi = 0.1 * t
    jac = np.column_stack([np.full(t.size, -900.0), np.ones(t.size), -50.0 * np.cos(psi),
                           -50.0 * np.sin(psi)])
    noise = ResidualNoise(turbulence_mps=0.5, tau_s=6.0)
    reported, actual = reported_covariance(jac, t, noise)
    np.testing.assert_allclose(actual, least_squares_covariance(
        jac, gust_covariance(t, jac[:, -2:], noise)), rtol=1e-12)
    np.testing.assert_allclose(reported, actual * student_t_widening(119.0 / 6.0) ** 2,
                               rtol=1e-12)


def test_ar1_times_is_the_dense_kernel_product():
    from pitotcal.core.information import ar1_times

    rng = np.random.default_rng(3)
    for span, tau in ((240.0, 7.0), (3000.0, 2.0)):        # the second crosses stretches
        t = np.sort(rng.uniform(0.0, span, 700))
        x = rng.normal(size=(700, 3))
        dense = np.exp(-np.abs(t[:, None] - t[None, :]) / tau) @ x
        np.testing.assert_allclose(ar1_times(t, tau, x), dense, rtol=1e-9, atol=1e-9)


def test_quantiles_from_the_standard_library_are_scipy_stats_ones():
    # the light quantile routes (no scipy.stats import) against scipy.stats itself
    from scipy.stats import norm, t

    from pitotcal.core.information import normal_isf
    from pitotcal.core.student_t import student_t_isf

    for p in (0.45, 0.25, 0.05, 0.025, 1e-3, 1e-6, 1e-10, 1e-12):
        assert abs(normal_isf(p) / norm.isf(p) - 1) < 1e-12
        for dof in (3.0, 3.5, 4.7, 7.0, 39.9, 40.0, 150.0, 1e3, 1e4, 1e5):
            assert abs(student_t_isf(p, dof) / t.isf(p, dof) - 1) < 1e-12
        for dof in (1.01e5, 1e6, 1e8):         # the Cornish-Fisher route
            assert abs(student_t_isf(p, dof) / t.isf(p, dof) - 1) < 1e-12
    assert abs(student_t_isf(0.75, 5.0) / t.isf(0.75, 5.0) - 1) < 1e-12     # the lower half
    for dof in (1.0, 3.0, 1e5, 2e5, 1e8):    # the median, on both routes
        assert student_t_isf(0.5, dof) == t.isf(0.5, dof) == 0.0
    for p, dof in ((1e-20, 0.1), (1e-160, 1.0), (1e-300, 3.0)):    # t² or the density leaves
        with pytest.raises(PitotcalError, match="`p`"):                 # the float range
            student_t_isf(p, dof)
