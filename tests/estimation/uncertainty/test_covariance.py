"""Covariance: plain and colored-residual forms against direct computations."""

import numpy as np
import pytest
from pitotcal.estimation.uncertainty.covariance import (
    colored_covariance,
    plain_covariance,
    residual_acf,
    student_t_widening,
)


def _ou(n, a, rng):
    e = rng.standard_normal(n)
    out = np.empty(n)
    out[0] = e[0]
    for i in range(1, n):
        out[i] = a * out[i - 1] + np.sqrt(1 - a * a) * e[i]
    return out


def test_acf_matches_direct_sum():
    r = np.random.default_rng(0).standard_normal(500)
    acf = residual_acf(r, 5)
    direct = [r[: r.size - k] @ r[k:] / r.size for k in range(6)]
    assert np.allclose(acf, direct)


@pytest.mark.parametrize("window", ["bartlett", "parzen"])
def test_colored_equals_n2_double_sum(window):
    rng = np.random.default_rng(1)
    n = 400
    jac = rng.standard_normal((n, 3)) + np.linspace(0, 1, n)[:, None]
    r = _ou(n, 0.8, rng)
    got = colored_covariance(jac, r, window=window, lag=20)
    from pitotcal.estimation.uncertainty.covariance import lag_weights
    h = lag_weights(20, window) * residual_acf(r, 20) * n / (n - 3)
    toeplitz = np.zeros((n, n))
    for k in range(21):
        toeplitz += np.diag(np.full(n - k, h[k]), k) + (np.diag(np.full(n - k, h[k]), -k) if k else 0)
    m_inv = np.linalg.inv(jac.T @ jac)
    assert np.allclose(got.covariance, m_inv @ jac.T @ toeplitz @ jac @ m_inv)


def test_white_residuals_reduce_to_plain():
    rng = np.random.default_rng(2)
    jac = rng.standard_normal((20000, 2))
    r = rng.standard_normal(20000)
    got = colored_covariance(jac, r)
    assert got.lag == 0
    assert np.allclose(got.covariance, plain_covariance(jac, r))


def test_correlated_residuals_widen_the_bounds():
    rng = np.random.default_rng(3)
    n = 20000
    jac = np.column_stack([np.ones(n), np.linspace(-1, 1, n)])
    r = _ou(n, 0.99, rng) + 0.3 * rng.standard_normal(n)
    got = colored_covariance(jac, r)
    ratio = np.sqrt(np.diag(got.covariance) / np.diag(plain_covariance(jac, r)))
    # long-run variance of AR(1) a = 0.99 over white: (1 + a) / (1 - a) ~ 199 -> std x ~13
    assert np.all(ratio > 8) and np.all(ratio < 18)
    assert 0.985 < got.ar1 < 0.995
    assert np.all(np.linalg.eigvalsh(got.covariance) > 0)


def test_reported_sigma_matches_the_scatter_of_estimates_under_projection():
    """Least squares on a slow ramp with Gauss-Markov noise of 200 samples in N = 4000: only ~20
    independent blocks, so fitting the ramp removes a visible share of the noise from the
    residuals. The corrected sigma must still match the actual scatter of the estimates
    (a fit to the raw residual autocovariance gave ~0.8 of it)."""
    from scipy.signal import lfilter

    rng = np.random.default_rng(7)
    n, a, runs = 4000, np.exp(-1 / 200), 300
    jac = np.column_stack([np.ones(n), np.linspace(-1, 1, n)])
    estimates, sigmas, unwidened = [], [], []
    for _ in range(runs):
        noise = lfilter([np.sqrt(1 - a * a)], [1, -a], rng.standard_normal(n + 2000))[2000:]
        noise += 0.2 * rng.standard_normal(n)
        beta = np.linalg.lstsq(jac, noise, rcond=None)[0]
        estimates.append(beta)
        got = colored_covariance(jac, noise - jac @ beta)
        # the Student-t widening for the noise model's few degrees of freedom is deliberate;
        # the sigma before it must match the scatter
        sigmas.append(np.sqrt(np.diag(got.covariance)))
        unwidened.append(sigmas[-1] / student_t_widening(got.dof))
    # one flight's sigma is itself uncertain with ~20 blocks, so compare the median reported
    # sigma with the actual scatter, and check the coverage of the widened bounds
    ratio = np.median(unwidened, axis=0) / np.std(estimates, axis=0)
    assert np.all(ratio > 0.85) and np.all(ratio < 1.2), ratio
    inside = np.abs(np.array(estimates)) < 2 * np.array(sigmas)
    assert np.all(inside.mean(axis=0) >= 0.88) and inside.mean() <= 0.99, inside.mean(axis=0)


def _stretches_warning(n, seed, tau=40.0):
    """The few-stretches warning of AR(1) residuals of correlation time `tau` samples."""
    e = _ou(n, np.exp(-1.0 / tau), np.random.default_rng(seed))
    return colored_covariance(np.column_stack([np.ones(n), np.linspace(-1, 1, n)]), e).warning


@pytest.mark.parametrize("seed", range(5))
def test_no_few_stretches_warning_when_the_record_holds_many(seed):
    """Truth: 2 tau = (1 + a)/(1 - a) = 80 samples, 250 stretches in 20,000. The fitted noise
    model's long-run-weighted time said ~6,300 samples for seed 2 (its slowest term at the
    edge of its grid)."""
    assert _stretches_warning(20000, seed) is None


@pytest.mark.parametrize("seed", range(6))
def test_few_stretches_warning_names_the_true_correlation(seed):
    """Truth: 200 samples hold 2.5 stretches of 2 tau = 80 samples; the warning's length is
    measured (a short record's autocorrelation reads short: 25-50 samples)."""
    import re

    warning = _stretches_warning(200, seed)
    two_tau, stretches = map(float, re.match(r"residuals correlated over ~(\d+) samples: only "
                                             r"~(\d+) independent stretches", warning).groups())
    assert 20.0 <= two_tau <= 100.0 and stretches < 10


@pytest.mark.parametrize("seed", [5, 10, 11])
def test_no_few_stretches_warning_in_turbulence_the_record_resolves(seed):
    """A 240 s flight in 0.5 m/s gusts of L = 300 m: the truth is 2 tau = 2 L / V ~ 14 s, ~18
    stretches. These seeds were warned of ~3,100-3,900 samples (62-78 s) before the warning
    measured the residuals themselves."""
    from pitotcal.estimation import identify
    from synthetic import synthetic_flight

    flight, _ = synthetic_flight(seed=seed, n=12000, turns=2.0, turbulence_mps=0.5,
                                 gps_rate_hz=5.0, gps_noise_mps=0.05, qc_noise_pa=0.5)
    tas_mps = np.sqrt(2.0 * flight.qci_pa / flight.rho_kgm3)
    a = np.exp(-1.0 / (50.0 * 300.0 / tas_mps.mean()))              # the gusts' AR(1), 50 Hz
    assert flight.n / ((1 + a) / (1 - a)) >= 10                     # the truth: no warning
    assert not [w for w in identify(flight).warnings if "independent stretches" in w]
