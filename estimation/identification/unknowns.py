"""The unknowns of the output-error problem, where each sits, and how they are reported.

The solver's vector theta holds the structure's coefficients k, then the wind velocity vector
(wind_n, wind_e) in m/s: the air-mass velocity, the way it blows TO (no singularity in calm
air). The wind is always last, so one set of named slices serves every structure, on numpy
arrays and CasADi MX alike. The reported parameters replace the wind vector by its speed and
the direction it blows FROM.
"""

import numpy as np

from pitotcal.core.units import wind_polar

__all__ = [
    "COEFS", "WIND", "WIND_E", "WIND_INTERNAL", "WIND_N", "WIND_NAMES", "theta_scales", "to_reported",
]

COEFS = slice(0, -2)        # theta[COEFS]: k1, k2, ...
WIND = slice(-2, None)      # theta[WIND]: (wind_n, wind_e)
WIND_N, WIND_E = -2, -1

WIND_NAMES = ("wind_speed_mps", "wind_from_deg")   # reported
WIND_INTERNAL = ("wind_n_mps", "wind_e_mps")       # in theta


def theta_scales(model):
    """Typical size of each unknown: the structure's coefficient scales, 1 m/s for the wind.
    The solver works on theta / theta_scales (order 1)."""
    return np.array(list(model.scales) + [1.0, 1.0])


def to_reported(theta, cov):
    """Internal (k..., wind_n, wind_e) to reported (k..., wind_speed_mps, wind_from_deg).

    The reported direction is where the wind blows FROM, degrees true in [0, 360). The
    covariance is carried through with the Jacobian (delta method); in calm air the direction's
    variance is large, as it should be.

    Returns
    -------
    params : ndarray, shape (p,)
    covariance : ndarray, shape (p, p)
    """
    theta = np.asarray(theta, dtype=float)
    wn, we = theta[WIND]
    speed, from_deg = map(float, wind_polar(wn, we))
    s2 = max(speed * speed, 1e-24)
    jac = np.eye(theta.size)
    jac[WIND_N, WIND] = [wn / max(speed, 1e-12), we / max(speed, 1e-12)]
    jac[WIND_E, WIND] = np.degrees([-we / s2, wn / s2])
    params = np.concatenate([theta[COEFS], [speed, from_deg]])
    return params, jac @ cov @ jac.T
