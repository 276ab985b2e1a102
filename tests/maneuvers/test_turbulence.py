"""Dryden turbulence: MIL-F-8785C scales, filter variance and correlation length."""

import numpy as np
import pytest
from pitotcal.maneuvers.turbulence import (
    along_path_gust,
    discrete_dryden_filters,
    dryden_filters,
    dryden_gusts,
    dryden_scales,
)

from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import FT_TO_M

TAS = 40.0


def test_low_altitude_scales_follow_mil_f_8785c():
    h_ft = 800.0
    s = dryden_scales(h_ft * FT_TO_M, 0.5)
    base = 0.177 + 0.000823 * h_ft
    assert s.length_u_m == pytest.approx(h_ft / base ** 1.2 * FT_TO_M)
    assert s.length_u_m == pytest.approx(302.6, abs=0.5)           # T-2 case: 800 ft
    assert s.length_v_m == s.length_u_m
    assert s.length_w_m == pytest.approx(h_ft * FT_TO_M)
    assert s.sigma_w_mps == pytest.approx(0.5 * base ** 0.4)
    assert s.sigma_u_mps == s.sigma_v_mps == 0.5


def test_high_altitude_is_isotropic_and_length_override():
    s = dryden_scales(3000 * FT_TO_M, 1.0)
    assert s.length_u_m == pytest.approx(1750 * FT_TO_M)
    assert s.length_w_m == pytest.approx(1750 * FT_TO_M)
    assert s.sigma_w_mps == pytest.approx(1.0)
    assert dryden_scales(244.0, 1.0, length_m=123.0).length_u_m == 123.0


@pytest.mark.parametrize("args, match", [
    ((-1.0, 0.5), "alt_m -1 must be >= 0"),
    ((244.0, -0.1), "sigma_horizontal_mps -0.1 must be >= 0"),
    ((244.0, 0.5, 0.0), "length_m 0 must be > 0"),
    ((244.0, float("nan")), "sigma_horizontal_mps nan must be a finite number"),
])
def test_bad_scales_refused(args, match):
    with pytest.raises(PitotcalError, match=match):
        dryden_scales(*args)


def test_filters_have_the_spec_dc_gain():
    s = dryden_scales(244.0, 0.5)
    (num_u, den_u), (num_v, den_v), _ = dryden_filters(s, TAS)
    assert num_u[-1] / den_u[-1] == pytest.approx(0.5 * np.sqrt(2 * s.length_u_m / (np.pi * TAS)))
    assert num_v[-1] / den_v[-1] == pytest.approx(0.5 * np.sqrt(s.length_v_m / (np.pi * TAS)))


CASES = [(244.0, 0.5, 40.0, 0.02), (244.0, 1.5, 52.0, 0.1), (30.0, 0.8, 36.0, 0.2),
         (3048.0, 1.0, 150.0, 0.02)]


@pytest.mark.parametrize("alt_m, sigma, tas, dt", CASES)
def test_discrete_filters_match_python_control(alt_m, sigma, tas, dt):
    """The zero-order-hold coefficients are python-control's c2d of its tf, to 1e-12."""
    import control

    s = dryden_scales(alt_m, sigma)
    for (num, den), (numd, dend) in zip(dryden_filters(s, tas),
                                        discrete_dryden_filters(s, tas, dt)):
        hd = control.c2d(control.tf(num, den), dt, method="zoh")
        ref_num = np.atleast_1d(np.squeeze(hd.num[0][0]))
        ref_den = np.atleast_1d(np.squeeze(hd.den[0][0]))
        assert numd.shape == ref_num.shape and dend.shape == ref_den.shape
        np.testing.assert_allclose(numd, ref_num, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(dend, ref_den, rtol=1e-12, atol=1e-15)


def _gusts_with_python_control(n, dt, s, tas, rng):
    """The gust series by python-control's c2d, as the simulator made it with python-control."""
    import control
    from scipy.signal import lfilter

    tau = max(s.length_u_m, s.length_v_m, s.length_w_m) / tas
    burn = int(np.ceil(10.0 * tau / dt))
    noise = rng.standard_normal((3, burn + n)) * np.sqrt(np.pi / dt)
    out = np.empty((n, 3))
    for j, (num, den) in enumerate(dryden_filters(s, tas)):
        hd = control.c2d(control.tf(num, den), dt, method="zoh")
        out[:, j] = lfilter(np.atleast_1d(np.squeeze(hd.num[0][0])),
                            np.atleast_1d(np.squeeze(hd.den[0][0])), noise[j])[burn:]
    return out


def test_filter_is_lfilter():
    from scipy.signal import lfilter

    from pitotcal.maneuvers.turbulence import _filter

    x = np.random.default_rng(3).standard_normal(2000)
    for num, den in (([0.2], [1.0, -0.9]), ([0.02, -0.019], [1.0, -1.98, 0.9802])):
        np.testing.assert_allclose(_filter(num, den, x), lfilter(num, den, x), rtol=0,
                                   atol=1e-12)


@pytest.mark.parametrize("alt_m, sigma, tas, dt", CASES)
def test_gusts_match_python_control(alt_m, sigma, tas, dt):
    s = dryden_scales(alt_m, sigma)
    mine = dryden_gusts(5000, dt, s, tas, np.random.default_rng(11))
    ref = _gusts_with_python_control(5000, dt, s, tas, np.random.default_rng(11))
    np.testing.assert_allclose(mine, ref, rtol=0, atol=1e-9 * sigma)
    # and the statistics that follow from them
    np.testing.assert_allclose(mine.std(axis=0), ref.std(axis=0), rtol=1e-9)


def test_simulate_does_not_import_python_control(tmp_path):
    """`pitotcal simulate` end to end in a fresh interpreter: neither python-control nor
    scipy.signal loads."""
    import subprocess
    import sys

    from plans import circle_plan

    from pitotcal.io.plan_csv import write_plan

    plan_csv = write_plan(circle_plan(duration_s=30.0), tmp_path / "plan.csv")
    code = ("import sys\n"
            "from pitotcal.cli import main\n"
            f"status = main(['simulate', {str(plan_csv)!r}, '-o', {str(tmp_path / 'f.csv')!r}])\n"
            "assert status == 0, status\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'control'\n"
            "             or m.startswith('scipy.signal')))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env={**__import__("os").environ, "MPLBACKEND": "Agg"})
    assert out.stdout.strip().splitlines()[-1] == "[]"
    assert (tmp_path / "f.csv").exists()


@pytest.fixture(scope="module")
def long_gusts():
    s = dryden_scales(244.0, 0.8)
    dt = 0.1
    # ~2,700 correlation times: variance to ~3 %, correlations to ~0.02 (one sigma)
    return s, dt, dryden_gusts(200_000, dt, s, TAS, np.random.default_rng(7))


def _autocorr(x, lag):
    x = x - x.mean()
    return float(np.mean(x[:-lag] * x[lag:]) / np.mean(x * x))


def test_variance_matches_specification(long_gusts):
    s, _, g = long_gusts
    for j, sigma in enumerate((s.sigma_u_mps, s.sigma_v_mps, s.sigma_w_mps)):
        assert g[:, j].std() == pytest.approx(sigma, rel=0.08)
        assert abs(g[:, j].mean()) < 0.1 * sigma


def test_correlation_length_matches_specification(long_gusts):
    s, dt, g = long_gusts
    # R_u(xi) = exp(-xi/L), R_v(xi) = (1 - xi/2L) exp(-xi/L), xi = V * lag
    for frac in (0.5, 1.0, 2.0):
        lag = int(round(frac * s.length_u_m / TAS / dt))
        xi = lag * dt * TAS
        assert _autocorr(g[:, 0], lag) == pytest.approx(np.exp(-xi / s.length_u_m), abs=0.06)
        expected_v = (1 - xi / (2 * s.length_v_m)) * np.exp(-xi / s.length_v_m)
        assert _autocorr(g[:, 1], lag) == pytest.approx(expected_v, abs=0.06)
    # The integral scale of u (distance to 1/e) is L_u.
    r = np.array([_autocorr(g[:, 0], m) for m in range(1, 400)])
    l_est = (np.argmax(r < np.exp(-1)) + 1) * dt * TAS
    assert l_est == pytest.approx(s.length_u_m, rel=0.15)


def test_gusts_deterministic_by_generator_and_stationary_from_start():
    s = dryden_scales(244.0, 0.5)
    a = dryden_gusts(1000, 0.02, s, TAS, np.random.default_rng(3))
    b = dryden_gusts(1000, 0.02, s, TAS, np.random.default_rng(3))
    np.testing.assert_array_equal(a, b)
    # burn-in: the first sample is already spread like the process, not pinned at zero
    firsts = np.array([dryden_gusts(5, 0.02, s, TAS, np.random.default_rng(i))[0, 0]
                       for i in range(80)])
    assert firsts.std() == pytest.approx(0.5, rel=0.25)


def test_along_path_gust_is_the_u_column_without_python_control():
    """The numpy twin used by the plan command's auto-throttle check: same draws, same burn-in,
    the same recursion; only the filter coefficients are closed-form instead of c2d's."""
    s = dryden_scales(244.0, 0.5)
    full = dryden_gusts(2400, 0.1, s, TAS, np.random.default_rng(7))
    u = along_path_gust(2400, 0.1, s, TAS, np.random.default_rng(7))
    np.testing.assert_allclose(u, full[:, 0], rtol=0, atol=1e-12)
