"""The unknowns' layout and the internal-to-reported transform."""

import numpy as np
import pytest
from pitotcal.estimation.identification.unknowns import COEFS, WIND, WIND_E, WIND_N, theta_scales, to_reported

from pitotcal.core.models import get_model


@pytest.mark.parametrize("model, coefs", [("constant", [0.02]), ("inverse", [0.02, -15.0])])
def test_named_slices_split_theta(model, coefs):
    theta = np.array(coefs + [-5.0, 1.0])
    assert list(theta[COEFS]) == coefs
    assert list(theta[WIND]) == [-5.0, 1.0]
    assert (theta[WIND_N], theta[WIND_E]) == (-5.0, 1.0)
    assert list(theta_scales(get_model(model))) == list(get_model(model).scales) + [1.0, 1.0]


@pytest.mark.parametrize("wn, we, from_deg", [(-5.0, 0.0, 0.0), (0.0, -5.0, 90.0), (5.0, 0.0, 180.0),
                                               (0.0, 5.0, 270.0), (-5.0, 0.00872665, 359.9)])
def test_wind_transform(wn, we, from_deg):
    cov = np.diag([1e-8, 0.04, 0.01])
    params, rep = to_reported(np.array([0.02, wn, we]), cov)
    assert params[1] == pytest.approx(np.hypot(wn, we))
    assert params[2] == pytest.approx(from_deg, abs=1e-3)
    # numerical Jacobian check of the propagated covariance
    def f(x):
        return to_reported(x, cov)[0]
    x0 = np.array([0.02, wn, we])
    def diff(e):
        d = f(x0 + e) - f(x0 - e)
        d[2] = (d[2] + 180.0) % 360.0 - 180.0       # direction wraps at north
        return d / 2e-6
    jac = np.column_stack([diff(e) for e in np.eye(3) * 1e-6])
    assert np.allclose(rep, jac @ cov @ jac.T, rtol=1e-4, atol=1e-12)


def test_wind_from_stays_below_360():
    params, _ = to_reported(np.array([0.02, -5.0, 1e-16]), np.eye(3) * 1e-4)
    assert 0.0 <= params[2] < 360.0
