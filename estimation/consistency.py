"""Consistency of the calibration over the flight (issue 15, item 2): a step-change test.

One calibration for the whole record is the model; a leak, an iced or blocked port or a
drift that starts mid-flight breaks it while the global fit stays tight, because the
coefficients bend to absorb it. At the global optimum the residual is close to linear in the
unknowns, so the test adds one regressor, a change of scale from t0 on, dr/ds = q_ci 1[t >=
t0], to the output sensitivities and refits by one linear step: its coefficient s is the
fraction by which q_ci changed at t0, and s / sigma_s, with sigma_s from the colored-residual
covariance of the augmented fit, is standard normal when the calibration is one. t0 is
scanned over `ONSETS` of the record (the plain-noise z picks the onset; one colored
covariance is computed, at it) and the threshold is Bonferroni over the scan, so a clean
flight is flagged at most at the rate `ALPHA` (measured: docs/measured.md).
"""

import numpy as np

from pitotcal.core.models import get_model

from .covariance import colored_covariance
from .residual import flight_channels, sensitivities

__all__ = ["ALPHA", "ONSETS", "step_test"]

# Onsets scanned, as fractions of the record: at least a fifth of it on each side.
ONSETS = np.linspace(0.2, 0.8, 13)
# The false-flag rate aimed at on a consistent flight.
ALPHA = 0.01
# The one-exponential noise model: a third of the multiscale's cost (the identification's
# 1.5x budget), and measured as good for this test (docs/measured.md).
_WINDOW = "exponential"


def step_test(flight, result, air_data):
    """(warning or None, details): a change of q_ci's scale during the flight.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
        The samples `result` was fitted on.
    result : IdentificationResult
    air_data : str
        As `estimation.residual.flight_channels` takes it.

    Returns
    -------
    warning : str or None
        Names the onset and the size when |z| exceeds the threshold.
    details : dict
        ``onset_s``, ``step`` (fraction, q_ci low when positive), ``z``, ``threshold``.
    """
    from scipy.stats import norm

    model = get_model(result.model)
    ch = flight_channels(flight, result.gps_noise_std_mps, air_data)
    jac = sensitivities(model, result.internal_params, *ch.args)
    r = result.residuals_pa
    t = flight.time_s
    info = jac.T @ jac
    onset_s, i0 = _best_onset(jac, info, r, ch.qci, t)
    step_col = np.where(np.arange(t.size) >= i0, ch.qci, 0.0)
    aug = np.column_stack([jac, step_col])
    info_aug = aug.T @ aug
    beta = np.linalg.solve(info_aug, aug.T @ r)
    fitted = r - aug @ beta
    threshold = float(norm.isf(ALPHA / (2.0 * ONSETS.size)))
    # white-noise z first: the colored variance of a step (a low-frequency regressor) is
    # larger under the positively correlated residuals of flight, so below the threshold
    # here is below it there, and the FFT covariance is spent only on candidates
    var_plain = float(fitted @ fitted) / max(r.size - aug.shape[1], 1) \
        * np.linalg.inv(info_aug)[-1, -1]
    z = float(beta[-1] / np.sqrt(var_plain))
    if abs(z) > threshold:
        cov = colored_covariance(aug, fitted, window=_WINDOW, information=info_aug,
                                 velocity=jac[:, -2:]).covariance
        z = float(beta[-1] / np.sqrt(max(cov[-1, -1], var_plain)))
    details = {"onset_s": onset_s, "step": float(-beta[-1]), "z": z, "threshold": threshold}
    if not abs(z) > threshold:
        return None, details
    side = "low" if beta[-1] < 0 else "high"
    return (f"{flight.source}: the calibration changes during the flight: from about "
            f"t = {onset_s:.0f} s to the end ({t[-1]:.0f} s) q_ci reads "
            f"{100 * abs(beta[-1]):.1f}% {side} against before (z = {z:+.1f}, beyond "
            f"{threshold:.1f}): a leak, icing, blockage or drift? One calibration for the "
            "whole record does not hold, and its bounds are not honest"), details


def _best_onset(jac, info, r, qci, t):
    """(onset time, first index after it) of the largest plain-noise |z| of the step."""
    info_inv = np.linalg.inv(info)
    proj = jac @ (info_inv @ (jac.T @ r))
    best = (-1.0, 0.0, 0)
    for frac in ONSETS:
        onset = t[0] + frac * (t[-1] - t[0])
        i0 = int(np.searchsorted(t, onset))
        g = np.where(np.arange(t.size) >= i0, qci, 0.0)
        # the step regressor after removing what the coefficients and the wind explain
        g_res = g - jac @ (info_inv @ (jac.T @ g))
        denom = float(g_res @ g_res)
        if denom <= 0:
            continue
        score = float(g_res @ (r - proj)) ** 2 / denom
        if score > best[0]:
            best = (score, float(onset), i0)
    return best[1], best[2]
