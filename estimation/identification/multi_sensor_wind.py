"""The wind model several airspeed sensors share, and their joint instrumental-variable step.

The unknowns of the joint problem are x = (theta, d): theta = [k_1..., k_2..., ..., wind_n,
wind_e] (`multi_sensor`) and d the drift of the first sensor's chosen wind basis
(`wind_drift.DriftBasis`: drift knots and/or one wind per calibration window; empty for a
constant wind), north values then east. Every sensor sees W(t) = W_mean + B(t) d at its own
sample times, so a sensor's residual depends on its own coefficients, the mean wind and d; its
sensitivities to d are its wind columns times B (`wind_drift.drift_columns`).

`joint_gauss_newton` estimates (theta, d) from all sensors' residuals, each weighted by its
noise 1 / sigma_s; `joint_iv` solves the estimating equations of the whole problem: each
sensor's coefficient rows with its instruments (`iv.instruments`: the sensitivities built from
q_ci averaged over `iv.IV_WINDOW_S`), the mean-wind and drift rows the weighted sum of the
sensors' corrected scores (the objective's GPS-noise spread term included, its drift rows the
wind rows times B).
"""

import numpy as np

from .iv import IV_TOL, IV_WINDOW_S, instruments, smooth_in_time, spread_gradient
from .residual import residual, sensitivities
from .unknowns import theta_scales
from .wind_drift import GN_WIND_TOL_MPS, drift_columns, gauss_newton_step, shifted

__all__ = ["joint_gauss_newton", "joint_iv", "sensor_terms", "shared_drift", "smoothed_qci",
           "x_scales"]

_GN_ITERATIONS = 8
_IV_ITERATIONS = 10


def shared_drift(result):
    """(basis, d) of the first sensor's fitted wind model (`result.drift`), or (None, an empty
    d) for a constant wind."""
    if result.drift is None:
        return None, np.zeros(0)
    basis, d = result.drift
    return basis, np.asarray(d, dtype=float)


def smoothed_qci(parts):
    """Each sensor's q_ci averaged over `IV_WINDOW_S` (the instruments' flight condition)."""
    return [smooth_in_time(p.ch.qci, p.flight.time_s, IV_WINDOW_S) for p in parts]


def x_scales(parts, n_drift):
    """The typical size of each unknown of x (coefficient scales; 1 m/s for the wind)."""
    return np.concatenate([theta_scales(p.model)[:-2] for p in parts] + [np.ones(2 + n_drift)])


def sensor_terms(part, sl, x, n_theta, q_smooth=None):
    """(r, S, Z, th, ch) of one sensor at x: its residual (N,), its sensitivities and
    instruments in the columns of x (N, x.size; Z = S without `q_smooth`), its own
    (k, W_mean) and its channels with the drift taken out."""
    m = part.b.shape[1]
    d = x[n_theta:]
    th = np.concatenate([x[sl], x[n_theta - 2:n_theta]])
    ch = shifted(part.ch, part.b, d)
    s_own = sensitivities(part.model, th, *ch.args)
    r = residual(part.model, th, *ch.args)

    def embed(cols):
        out = np.zeros((r.size, x.size))
        out[:, sl] = cols[:, :-2]
        out[:, n_theta - 2:n_theta] = cols[:, -2:]
        out[:, n_theta:] = drift_columns(cols, part.b)
        return out

    s = embed(s_own)
    z = s if q_smooth is None else embed(instruments(part.model, th, q_smooth, s_own))
    return r, s, z, th, ch


def joint_gauss_newton(parts, slices, x, n_theta):
    """x = (theta, d) by Gauss-Newton on every sensor's residual weighted by 1 / sigma_s,
    from `x`; stops when the wind (mean and drift) moves less than `_GN_WIND_TOL_MPS`."""
    x = np.asarray(x, dtype=float).copy()
    for _ in range(_GN_ITERATIONS):
        rows, res = [], []
        for p, sl in zip(parts, slices):
            r, s = sensor_terms(p, sl, x, n_theta)[:2]
            w = 1.0 / np.sqrt(p.sigma2)
            rows.append(s * w)
            res.append(r * w)
        step = gauss_newton_step(np.vstack(rows), np.concatenate(res))
        if not np.all(np.isfinite(step)):
            break
        x = x + step
        if np.max(np.abs(step[n_theta - 2:])) < GN_WIND_TOL_MPS:
            break
    return x


def _equations(parts, slices, x, n_theta, smooth):
    """(g, A): the joint estimating equations at x (module Notes), each sensor's weighted
    by 1 / sigma_s², and their Jacobian sum_s Z_s^T S_s / sigma_s²."""
    g, a = np.zeros(x.size), np.zeros((x.size, x.size))
    for p, sl, q in zip(parts, slices, smooth):
        r, s, z, th, ch = sensor_terms(p, sl, x, n_theta, q)
        m = p.b.shape[1]
        gs = z.T @ r
        # the objective's GPS-noise spread term: the wind rows, and the drift rows (x B)
        en, ee = spread_gradient(p.model, th, ch)
        gs[n_theta - 2] += float(np.sum(en))
        gs[n_theta - 1] += float(np.sum(ee))
        gs[n_theta:n_theta + m] += p.b.T @ en
        gs[n_theta + m:] += p.b.T @ ee
        g += gs / p.sigma2
        a += (z.T @ s) / p.sigma2
    return g, a


def joint_iv(parts, slices, x, n_theta, smooth):
    """(x, converged): the joint estimating equations solved by Newton steps from `x` (the
    output-error optimum); `x` itself and False when they do not converge."""
    scales = x_scales(parts, x.size - n_theta)
    out = np.asarray(x, dtype=float).copy()
    for _ in range(_IV_ITERATIONS):
        g, a = _equations(parts, slices, out, n_theta, smooth)
        try:
            step = np.linalg.solve(a, g)
        except np.linalg.LinAlgError:
            return x, False
        if not np.all(np.isfinite(step)):
            return x, False
        out = out - step
        if np.max(np.abs(step / scales)) < IV_TOL:
            return out, True
    return x, False
