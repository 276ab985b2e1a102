"""The multiscale noise model: its reported sigma against the actual scatter of estimates when
the residuals mix time scales (the failure of the one-exponential model, issue 11)."""

import numpy as np
from pitotcal.estimation.uncertainty.covariance import colored_covariance, student_t_widening
from pitotcal.estimation.uncertainty.residual_noise import block_means, nnls


def _ou(rng, n, tau, shape=()):
    from scipy.signal import lfilter
    a = np.exp(-1.0 / tau)
    e = rng.standard_normal((n + int(10 * tau), *shape))
    return lfilter([np.sqrt(1 - a * a)], [1, -a], e, axis=0)[-n:]


def _case(rng, n):
    """A slow ramp and a circling heading; residual = strong short noise (4 samples) + white +
    a weak velocity error of 150 samples seen through the heading (u . d)."""
    t = np.arange(n)
    heading = 2 * np.pi * t / 600.0
    u = np.column_stack([np.cos(heading), np.sin(heading)])
    jac = np.column_stack([1.0 + t / n, u])
    noise = (1.0 * _ou(rng, n, 4.0) + 0.3 * rng.standard_normal(n)
             + 0.4 * np.sum(u * _ou(rng, n, 150.0, (2,)), axis=1))
    return jac, u, noise


def test_sigma_matches_scatter_with_two_time_scales():
    rng = np.random.default_rng(11)
    n, runs = 2400, 80
    est, sig, sig_exp = [], [], []
    for _ in range(runs):
        jac, u, noise = _case(rng, n)
        beta = np.linalg.lstsq(jac, noise, rcond=None)[0]
        r = noise - jac @ beta
        got = colored_covariance(jac, r, velocity=u)
        est.append(beta)
        sig.append(np.sqrt(np.diag(got.covariance)) / student_t_widening(got.dof))
        exp = colored_covariance(jac, r, window="exponential")
        sig_exp.append(np.sqrt(np.diag(exp.covariance)) / student_t_widening(exp.dof))
    scatter = np.std(est, axis=0)
    ratio = np.median(sig, axis=0) / scatter
    assert np.all(ratio > 0.8) and np.all(ratio < 1.25), ratio
    # the one-exponential model follows the short scale and misses the slow one
    assert np.median(sig_exp, axis=0)[1] / scatter[1] < 0.75


def test_white_noise_reduces_to_plain_and_nnls_is_exact():
    rng = np.random.default_rng(3)
    jac = np.column_stack([np.ones(5000), np.linspace(0, 1, 5000)])
    got = colored_covariance(jac, rng.standard_normal(5000))
    assert got.lag == 0 and np.isfinite(got.covariance).all()
    a = rng.standard_normal((40, 5))
    x = np.array([1.0, 0.0, 2.0, 0.0, 0.5])
    np.testing.assert_allclose(nnls(a, a @ x), x, atol=1e-9)
    assert np.all(nnls(a, -a @ x) >= 0)
    np.testing.assert_allclose(block_means(np.arange(7.0), 3), [1.0, 4.0])


def test_stated_slow_velocity_error_is_counted():
    """A velocity error slower than the record can show (tau = its length) looks like
    the wind: unstated, the wind's sigma comes out well short of the scatter; stated as
    known_velocity (sigma, tau), it matches."""
    rng = np.random.default_rng(5)
    n, runs, sigma, tau = 1200, 50, 0.5, 1200.0
    t = np.arange(n)
    heading = 2 * np.pi * t / 300.0
    u = np.column_stack([np.cos(heading), np.sin(heading)])
    jac = np.column_stack([1.0 + t / n, u])
    est, sig, sig_unstated = [], [], []
    for _ in range(runs):
        noise = 0.3 * rng.standard_normal(n) + sigma * np.sum(u * _ou(rng, n, tau, (2,)), axis=1)
        beta = np.linalg.lstsq(jac, noise, rcond=None)[0]
        r = noise - jac @ beta
        est.append(beta)
        got = colored_covariance(jac, r, velocity=u, known_velocity=(sigma, tau))
        sig.append(np.sqrt(np.diag(got.covariance)))
        sig_unstated.append(np.sqrt(np.diag(colored_covariance(jac, r, velocity=u).covariance)))
    scatter = np.std(est, axis=0)
    ratio = np.median(sig, axis=0)[1:] / scatter[1:]
    assert np.all(ratio > 0.8) and np.all(ratio < 1.25), ratio
    assert np.all(np.median(sig_unstated, axis=0)[1:] / scatter[1:] < 0.7), ratio
