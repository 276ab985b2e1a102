"""The calibration's output residuals on a grid of short blocks: what the airspeed monitor
designs its thresholds from (the result record's ``"noise_model"``).

The relative residual e = (q_ci − predicted)/predicted of each block, and the same in airspeed,
ΔV_i = e V_i/2 (turbulence moves the airspeed by about the same m/s at every speed, so its
fraction of q_ci changes along a speed sweep), are autoregressive (turbulence is colored:
correlation times of seconds), e_k = Σ φ_i e_{k−i} + w_k; the log of the in-block (detrended)
variance of the measured q_ci, the signal's high-frequency "liveness", is roughly normal.
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import incompressible_cas_mps

__all__ = ["AR_ORDER", "BLOCK_S", "Blocks", "airspeed_residual_mps", "block_residual_stats",
           "block_stats", "robust_std"]

BLOCK_S = 0.5          # the monitor's block: long enough to average GPS noise, short for speed
_MIN_PER_BLOCK = 4     # samples a block needs (the detrended variance has n - 2 dof)
# Order of the residual's autoregressive model. Block means of turbulence are smoother at short
# lags and decorrelate faster at long ones than one AR(1) coefficient (fitted at lag one) says:
# AR(2) follows both, and the ramp test's information grows by ~20 % (docs/measured.md).
AR_ORDER = 2
# A block's relative variance below this is numerical zero (a relative std of 1e-6)
BAND_REL_VAR_FLOOR = 1e-12


@dataclass(frozen=True)
class Blocks:
    """A record cut into BLOCK_S blocks: `start`/`stop` sample indices, `time_s` (block end,
    when its decision is known), `qci_pa` (block mean) and `band_rel_var` (variance of q_ci
    about its in-block linear trend, over the block mean squared)."""

    start: np.ndarray
    stop: np.ndarray
    time_s: np.ndarray
    qci_pa: np.ndarray
    band_rel_var: np.ndarray


def block_stats(time_s, qci_pa, block_s=BLOCK_S, t0=None):
    """Cut a record into blocks of `block_s` from `t0` (default its first time) on; blocks with
    fewer than 4 samples are left out."""
    t = np.asarray(time_s, float)
    q = np.asarray(qci_pa, float)
    idx = np.floor((t - (t[0] if t0 is None else t0)) / block_s + 1e-9).astype(np.int64)
    cuts = np.flatnonzero(np.diff(idx)) + 1
    starts = np.concatenate([[0], cuts])
    stops = np.concatenate([cuts, [t.size]])
    means, band = _block_line_fits(t, q, starts, stops)
    keep = (stops - starts) >= _MIN_PER_BLOCK
    starts, stops = starts[keep], stops[keep]
    means, band = means[keep], band[keep]
    return Blocks(starts, stops, t[stops - 1], means, band)


def _block_line_fits(t, q, starts, stops):
    """(mean, variance about the least-squares line over the mean squared) of `q` against `t`
    in each block [start, stop) of a partition of the record: closed-form per-block least
    squares on block-centred data, in O(N) vectorised sums rather than one fit per block."""
    n = stops - starts
    block_means = _block_means(q, starts, n)
    tc = t - np.repeat(_block_means(t, starts, n), n)
    qc = q - np.repeat(block_means, n)
    sxx = np.add.reduceat(tc * tc, starts)
    sxy = np.add.reduceat(tc * qc, starts)
    slope = np.divide(sxy, sxx, out=np.zeros_like(sxy), where=sxx > 0)
    resid = qc - np.repeat(slope, n) * tc
    ss = np.add.reduceat(resid * resid, starts)
    band = ss / np.maximum(n - 2, 1) / np.maximum(block_means ** 2, 1e-9)
    return block_means, band


def _block_means(x, starts, n):
    """The mean of `x` over each block [starts, starts + n) (disjoint, increasing)."""
    edges = np.column_stack([starts, starts + n]).ravel()
    return np.add.reduceat(np.append(x, 0.0), edges)[::2] / n


def block_residual_stats(result, block_s=BLOCK_S):
    """The statistics of the calibration's residuals on the monitor's block grid, from which the
    monitor designs its thresholds (the JSON's ``"noise_model"``).

    Returns
    -------
    dict
        block_s; rel_std (std of the blocks' relative residual e); ar1 (a, lag-one
        correlation of e); ar (φ_1..φ_p, least-squares AR(AR_ORDER) coefficients of e);
        innovation_rel_std (robust std of w = e_k − Σ φ_i e_{k−i}); std_mps, ar_mps and
        innovation_std_mps (the same of the residual in airspeed, ΔV_i = e V_i / 2, m/s: the
        unit the monitor tests in); band_log_mean and band_log_std (median and robust std of
        log of the blocks' relative band variance); n_blocks.
    """
    qci = np.asarray(result.qci_pa, float)
    pred = qci - np.asarray(result.residuals_pa, float)
    blocks = block_stats(result.time_s, qci, block_s)
    pred_b = _block_means(pred, blocks.start, blocks.stop - blocks.start)
    e = (blocks.qci_pa - pred_b) / pred_b
    if e.size < 10:
        raise PitotcalError(f"a noise model needs >= 10 blocks of {block_s:g} s, got {e.size}")
    e = e - e.mean()
    a, phi, w = _ar_model(e)
    dv = airspeed_residual_mps(e, pred_b)      # the same in airspeed: the monitor's unit
    _, phi_v, w_v = _ar_model(dv - dv.mean())
    # floored: a noise-free record (a synthetic one) has blocks of zero variance, whose log
    # would be -inf in the record and warn on the console
    log_band = np.log(np.maximum(blocks.band_rel_var, BAND_REL_VAR_FLOOR))
    return {"block_s": block_s, "rel_std": float(np.std(e)), "ar1": a, "ar": list(phi),
            "innovation_rel_std": robust_std(w),
            "std_mps": float(np.std(dv)), "ar_mps": list(phi_v),
            "innovation_std_mps": robust_std(w_v),
            "band_log_mean": float(np.median(log_band)), "band_log_std": robust_std(log_band),
            "n_blocks": int(e.size)}


def airspeed_residual_mps(e, pred_pa):
    """The relative residual `e` of q_ci as airspeed, ΔV_i = e V_i / 2 (q_ci ∝ V_i², V_i of the
    predicted q_ci `pred_pa`), m/s: the unit the monitor tests in."""
    return e * 0.5 * incompressible_cas_mps(pred_pa)


def _ar_model(e):
    """(lag-one correlation, AR(AR_ORDER) coefficients, innovations) of `e`; AR(1) at the
    lag-one correlation when the AR(AR_ORDER) fit is not stationary."""
    a = float(np.clip(np.corrcoef(e[:-1], e[1:])[0, 1], 0.0, 0.98))
    phi, w = _ar_fit(e, AR_ORDER)
    if phi is None:
        phi, w = [a], e[1:] - a * e[:-1]
    return a, phi, w


def _ar_fit(e, p):
    """Least-squares AR(p) coefficients of `e` and its innovations; (None, None) when the fit is
    not stationary (a root of 1 − Σ φ_i z^i inside the unit circle)."""
    x = np.column_stack([e[p - i:e.size - i] for i in range(1, p + 1)])
    phi, *_ = np.linalg.lstsq(x, e[p:], rcond=None)
    roots = np.roots(np.concatenate([-phi[::-1], [1.0]]))
    if np.any(np.abs(roots) <= 1.0 / 0.995):
        return None, None
    return [float(v) for v in phi], e[p:] - x @ phi


def robust_std(x):
    """1.4826 × median absolute deviation: the std of normal data, unmoved by outliers."""
    x = np.asarray(x, float)
    return float(1.4826 * np.median(np.abs(x - np.median(x))))
