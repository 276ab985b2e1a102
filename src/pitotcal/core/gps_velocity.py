"""The GPS velocity channels as the measurement model uses them: which samples carry a new fix,
the velocity interpolated between held fixes, and the noise sigma_v estimated from the data.

GPS velocity noise enters the predicted impact pressure squared (q_c = rho |V_g - W|^2 / 2), so
it does not average out: it biases k1, k2 by about rho sigma_v^2 / q_c (docs/measured.md), an
error in the variables. The output-error problem removes that bias when it knows sigma_v
(`estimation.identification.oe`, Notes); this module estimates sigma_v from the velocity's
high-frequency content.
"""

import logging

import numpy as np

__all__ = ["estimate_gps_noise_std", "gps_update_mask", "interpolate_held"]

log = logging.getLogger(__name__)

# Below this fraction of update samples the GPS is taken as sample-and-hold (5 Hz GPS: 0.1 of
# 50 Hz data, 0.71 of 7 Hz data; 0.7 left the 7 Hz case held and biased k2 by ~2 sigma).
# Independent noisy channels repeat both values only when held.
HELD_FRACTION = 0.95
# Fewer distinct GPS updates than this give a noise estimate too rough to be worth using.
MIN_UPDATES = 30


def gps_update_mask(*channels):
    """Samples where a new GPS fix arrived, shape (N,) bool.

    GPS is often logged at 5 Hz inside 50 Hz data as sample-and-hold: a fix repeats until the
    next one. A sample is an update when any velocity channel differs from the previous sample;
    the first sample is always an update.

    Parameters
    ----------
    *channels : ndarray, shape (N,)
        Velocity components, m/s (north, east[, down]).
    """
    changed = np.zeros(channels[0].size, dtype=bool)
    changed[0] = True
    for c in channels:
        changed[1:] |= np.diff(c) != 0.0
    return changed


def estimate_gps_noise_std(time_s, *channels):
    """White-noise standard deviation of one GPS velocity component, m/s.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Sample times, s (only the update samples' order matters).
    *channels : ndarray, shape (N,)
        GPS velocity components, m/s.

    Returns
    -------
    float
        sigma_v, m/s (0.0 when it cannot be told from the motion).

    Notes
    -----
    On the distinct updates only (sample-and-hold repeats would fake a smooth signal), the
    variogram of each component, gamma(h) = mean((v[i+h] - v[i])^2) / 2 for h = 1, 2, 3, is
    fitted by gamma(h) = sigma_v^2 + a h + b h^2 and extrapolated to h = 0 (the "nugget").
    White noise is the only part that does not vanish at lag 0: smooth turning motion grows as
    h^2 and Gauss-Markov turbulence or a random walk as h, so neither leaks into sigma_v,
    unlike a plain second- or third-difference variance (which sees the turbulence's
    increments). The channels' estimates are pooled (one noise level per receiver).
    """
    del time_s   # the variogram is taken in update counts; GPS updates are regular
    update = gps_update_mask(*channels)
    if update.sum() < MIN_UPDATES:
        log.info("only %d GPS updates: GPS noise not estimated", update.sum())
        return 0.0
    lags = np.arange(1, 4)
    design = np.column_stack([np.ones(lags.size), lags, lags ** 2])
    nugget = []
    for c in channels:
        v = c[update]
        gamma = np.array([0.5 * np.mean((v[h:] - v[:-h]) ** 2) for h in lags])
        nugget.append(np.linalg.solve(design, gamma)[0])
    var = float(np.mean(nugget))
    return float(np.sqrt(var)) if var > 0 else 0.0


def interpolate_held(time_s, *channels):
    """Undo sample-and-hold: interpolate GPS velocity between its updates (cubic Hermite).

    Parameters
    ----------
    time_s : ndarray, shape (N,)
    *channels : ndarray, shape (N,)
        GPS velocity components, m/s.

    Returns
    -------
    channels : tuple of ndarray
        The interpolated components (the inputs themselves when GPS is not held).
    noise_factor : float
        Mean over samples of the GPS noise variance after interpolation relative to
        sigma_v^2 (below 1: interpolation averages neighbouring fixes).

    Notes
    -----
    A held fix is on average half an update period old (0.1 s at 5 Hz). While the airspeed
    sweeps, that lag shifts |V_g| by dV/dt * 0.1 s, which biased k1 by about 4 sigma at
    N = 16,000 in the constant model (measured, tests/synthetic.py). Linear interpolation
    cuts the chord of the turn and shortens |V_g| (-12 sigma without GPS noise, measured);
    a cubic (Catmull-Rom) Hermite curve through the fixes does neither. Each update sample
    is taken as the fix time; after the last update the value is held. The noise factor is
    measured by passing a fixed white sequence through the same (linear) interpolation.
    """
    update = gps_update_mask(*channels)
    if update.mean() > HELD_FRACTION or update.sum() < 4:
        return channels, 1.0
    t_fix = time_s[update]
    last = time_s <= t_fix[-1]
    weights = _hermite_weights(t_fix, time_s[last])
    out = []
    for c in channels:
        v = c.copy()
        v[last] = _apply(weights, c[update])
        out.append(v)
    white = np.random.default_rng(0).standard_normal(t_fix.size)
    spread = _apply(weights, white)
    factor = (np.sum(spread ** 2) / np.mean(white ** 2) + np.sum(~last)) / time_s.size
    return tuple(out), float(factor)


def _hermite_weights(t_fix, t):
    """Catmull-Rom weights: each t as a combination of the fixes i-1, i, i+1, i+2 around it."""
    m = t_fix.size
    i = np.clip(np.searchsorted(t_fix, t, side="right") - 1, 0, m - 2)
    h = t_fix[i + 1] - t_fix[i]
    s = (t - t_fix[i]) / h
    h00, h10 = 2 * s ** 3 - 3 * s ** 2 + 1, s ** 3 - 2 * s ** 2 + s
    h01, h11 = -2 * s ** 3 + 3 * s ** 2, s ** 3 - s ** 2
    # tangents by central differences (one-sided at the ends), scaled to the interval
    im, ip = np.maximum(i - 1, 0), np.minimum(i + 2, m - 1)
    d0 = h / (t_fix[i + 1] - t_fix[im])          # m_i = (v[i+1] - v[im]) * d0 / h ...
    d1 = h / (t_fix[ip] - t_fix[i])
    idx = np.stack([im, i, i + 1, ip])
    w = np.stack([-h10 * d0, h00 - h11 * d1, h01 + h10 * d0, h11 * d1])
    return idx, w


def _apply(weights, values):
    """Σ_j w_j values[idx_j], one row at a time: no 4 × N gather and product at once (the
    same additions in the same order as summing those rows)."""
    idx, w = weights
    out = w[0] * values[idx[0]]
    for j in range(1, len(w)):
        out += w[j] * values[idx[j]]
    return out
