"""Instrumental-variable refinement of the output-error coefficients.

An along-path gust changes the airspeed at once (the inertial speed cannot jump) and the speed
loop then restores it, so q_ci carries a high-passed copy of the very gust that is the output
error (r ~ -rho V u_gust). The coefficient sensitivities, built from q_ci, are then correlated
with the error and least squares moves k1 down and k2 up (measured on the simulator's T-2
flight, 200 runs, 1 m/s: z means -0.32 / +0.35; with the speed loop made perfect or the gust
kept out of the airspeed: -0.08 / +0.12, i.e. zero). The coefficient rows of the estimating
equations therefore use instruments: the same sensitivities built from q_ci averaged over
IV_WINDOW_S, which holds the flight condition but not the gust response (a speed loop with
integral action has zero DC gain from gust to airspeed). The wind rows keep the corrected
score. Measured: z means -0.03 / +0.04, same std; 10, 20, 40 s windows and the plan's own CAS
schedule as instrument give the same.
"""

import numpy as np

from pitotcal.core.models import qc_from_qci_pa

from .residual import ratio_columns, residual, residual_terms, sensitivities, spread_weights
from .unknowns import COEFS, WIND_E, WIND_N, theta_scales

__all__ = ["IV_NOT_CONVERGED", "IV_TOL", "IV_WINDOW_S", "equation_values", "estimating_equations",
           "instruments", "iv_refine", "smooth_in_time", "spread_gradient", "window_bounds"]

IV_WINDOW_S = 20.0
# Newton steps have converged when every unknown moves less than this in its scale (as IPOPT's
# tol: far below any sigma)
IV_TOL = 1e-6
# The start of the warning a result carries when the refinement did not converge
IV_NOT_CONVERGED = "instrumental-variable refinement did not converge"


def smooth_in_time(x, time_s, window_s, bounds=None):
    """Centred moving average over `window_s` seconds (truncated at the ends; gaps allowed).

    `bounds`: `window_bounds(time_s, window_s)` when already known (they depend on the times
    alone: the budget smooths many perturbed copies of one record).
    """
    c = np.concatenate([[0.0], np.cumsum(x)])
    lo, hi = window_bounds(time_s, window_s) if bounds is None else bounds
    return (c[hi] - c[lo]) / (hi - lo)


def window_bounds(time_s, window_s):
    """(lo, hi): the first and one past the last sample of each sample's centred window."""
    return (np.searchsorted(time_s, time_s - 0.5 * window_s, side="left"),
            np.searchsorted(time_s, time_s + 0.5 * window_s, side="right"))


def instruments(model, theta, q_smooth, jac):
    """The sensitivities `jac` with the coefficient columns rebuilt from the smoothed q_ci."""
    k = np.asarray(theta[COEFS], dtype=float)
    z = jac.copy()
    qc_smooth = qc_from_qci_pa(model, k, q_smooth)
    for j, col in enumerate(ratio_columns(model, k, q_smooth)):
        z[:, j] = qc_smooth * col
    return z


def estimating_equations(model, theta, channels, q_smooth):
    """(g, Z, S): the refined estimate's equations g(theta) = Z^T r + the wind rows' corrected
    score (zero at the estimate), the instruments Z and the sensitivities S at `theta`."""
    ch = channels
    r = residual(model, theta, *ch.args)
    s = sensitivities(model, theta, *ch.args)
    z = instruments(model, theta, q_smooth, s)
    g = z.T @ r
    en, ee = spread_gradient(model, theta, ch)
    g[WIND_N] += float(np.sum(en))
    g[WIND_E] += float(np.sum(ee))
    return g, z, s


def spread_gradient(model, theta, channels):
    """Per sample, the wind rows' (north, east) terms of the estimating equations from the
    objective's GPS-noise spread term (`residual.spread_weights`): their sums are its
    gradient."""
    ch = channels
    c, w = spread_weights(model, theta, ch)
    return c * w * (ch.vn - theta[WIND_N]), c * w * (ch.ve - theta[WIND_E])


def equation_values(model, theta, channels, q_smooth):
    """g(theta) of `estimating_equations` alone, by one dot product per row: no N x p
    instruments or sensitivities (the coefficient columns of S are not used by g; at N = 1e6
    each matrix is 40 MB and most of g's time)."""
    ch = channels
    r, a, _ = residual_terms(model, theta, *ch.args)
    k = np.asarray(theta[COEFS], dtype=float)
    qc_smooth = qc_from_qci_pa(model, k, q_smooth)
    g = np.empty(len(theta))
    for j, col in enumerate(ratio_columns(model, k, q_smooth)):
        g[j] = _dot(qc_smooth * col, r)
    ar = 2.0 * a * r                        # the wind columns of S are 2 a (V_g - wind)
    c, w = spread_weights(model, theta, ch)
    for row, v in ((WIND_N, ch.vn), (WIND_E, ch.ve)):
        dv = v - theta[row]
        g[row] = _dot(dv, ar) + c * _dot(w, dv)
    return g


def _dot(x, y):
    """Σ x y of two vectors by einsum, not BLAS: OpenBLAS's threaded dot costs ~10 ms per call
    on a loaded machine at any length (measured), and g takes a few per evaluation."""
    return float(np.einsum("i,i->", x, y))


def iv_refine(model, theta, channels, q_smooth, max_iter=10):
    """Solve Z^T r(theta) = corrected-score terms by Newton steps from the output-error optimum.

    Parameters
    ----------
    model : PressureErrorModel
    theta : ndarray, shape (p,)
        The output-error estimate (`estimation.identification.unknowns`).
    channels : estimation.identification.residual.Channels
    q_smooth : ndarray, shape (N,)
        q_ci averaged over IV_WINDOW_S (`smooth_in_time`).

    Returns
    -------
    (theta, Z, S) at the solution, or (theta_in, None, None) when it does not converge.
    """
    ch = channels
    scales = theta_scales(model)
    th = np.asarray(theta, dtype=float).copy()
    for _ in range(max_iter):
        g, z, s = estimating_equations(model, th, ch, q_smooth)
        try:
            step = np.linalg.solve(z.T @ s, g)
        except np.linalg.LinAlgError:
            return theta, None, None
        if not np.all(np.isfinite(step)):
            return theta, None, None
        th = th - step
        if np.max(np.abs(step / scales)) < IV_TOL:
            s = sensitivities(model, th, *ch.args)
            return th, instruments(model, th, q_smooth, s), s
    return theta, None, None
