"""The Mach-dependent static error's spline basis and its knots (core/models.py)."""

import numpy as np
import pytest

from pitotcal.core.models import mach_knots, mach_spline_basis


def test_the_basis_is_cardinal_and_reproduces_a_line():
    knots = np.array([0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.925, 0.95, 1.0, 1.05])
    assert mach_spline_basis(knots, knots) == pytest.approx(np.eye(knots.size), abs=1e-11)
    m = np.linspace(0.45, 1.1, 131)             # beyond the end knots: linear continuation
    line = 0.01 + 0.03 * (knots - 0.5)
    assert mach_spline_basis(m, knots) @ line == pytest.approx(0.01 + 0.03 * (m - 0.5),
                                                               abs=1e-12)


def test_casadi_gives_the_numpy_values():
    import casadi as ca

    knots = [0.5, 0.7, 0.9, 0.95, 1.0]
    x = ca.MX.sym("m")
    f = ca.Function("b", [x], [ca.vertcat(*mach_spline_basis(x, knots))])
    for m in (0.52, 0.93, 1.04):
        assert np.array(f(m)).ravel() == pytest.approx(
            mach_spline_basis(np.array([m]), knots)[0], abs=1e-13)


def test_knots_are_dense_through_the_transonic_region_and_hold_data():
    m = np.random.default_rng(0).uniform(0.52, 1.05, 9000)
    assert mach_knots(m) == pytest.approx([m.min(), 0.6, 0.7, 0.8, 0.85, 0.9, 0.925, 0.95,
                                           0.975, 1.0, 1.025, m.max()])
    sparse = np.r_[np.linspace(0.5, 0.9, 1000), np.linspace(0.9, 0.96, 30)]
    assert mach_knots(sparse) == pytest.approx([0.5, 0.6, 0.7, 0.8, 0.85, 0.96])
    assert mach_knots(np.linspace(0.2, 0.4, 100)) == pytest.approx([0.2, 0.3, 0.4])
