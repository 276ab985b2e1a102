"""Abrupt level changes of q_ci: a leak that opens at once.

A leak, a blocked port or a loose line that sets in at once moves q_ci by a few percent from
one sample to the next and keeps it there. The fit bends its coefficients to the change of
scale, and in turbulence the slow noise hides that change from `consistency.step_test`; but
sample to sample q_ci of a flying aircraft moves little (its airspeed cannot jump), so the
jump itself stands out. q_ci rather than the residual: the residual also steps at every
update of a GPS velocity held at 5 Hz.

The statistic at sample i is the smaller of two standardized jumps of one sign: the first
difference q_(i+1) - q_i, and the difference of the medians of the `SPAN` samples after and
before (a spike of up to SPAN // 2 samples moves neither median: it is not a step), each
centred on its running mean over 2 `CENTER` + 1 samples (the airspeed's own rate of change)
and divided by 1.4826 times its median absolute deviation over the record. The threshold is
the Gaussian Bonferroni bound over the record plus `MARGIN` for heavier tails
(docs/measured.md: the largest statistic of 300 simulated clean flights of two maneuvers in
calm air, 0.5 and 1 m/s turbulence was 4.8, and of 40 synthetic ones 3.4, against 5.9).
"""

import numpy as np

from pitotcal.core.information import normal_isf

__all__ = ["ALPHA", "CENTER", "GAP", "MARGIN", "MAX_HELD", "MIN_STEP", "POWER", "SPAN",
           "detectable_jump_pa", "jump_test"]

# The samples on each side of a jump whose medians are compared.
SPAN = 5
# Samples on each side of the running mean that takes the airspeed's own change out.
CENTER = 25
# Aimed false-flag rate on a consistent flight (before the margin).
ALPHA = 0.01
# Standard deviations added to the Gaussian bound for the heavier tails of flight residuals.
MARGIN = 1.0
# The detection probability at which the smallest flagged jump is stated (`detectable_jump_pa`,
# used by the statement of what a maneuver hides).
POWER = 0.95
# Smallest jump named, as a fraction of q_ci (0.5 % of airspeed): on a quiet transducer a jump
# of a few tenths of a pascal stands far above the noise (z = -39 for -0.3 Pa on a simulated
# leg flight), but it moves no calibration; the leaks that matter are a few percent.
MIN_STEP = 0.01
# A step in time longer than this many median steps is a gap: no jump is sought across it.
GAP = 1.5
# Above this fraction of repeated q_ci values (held or coarsely quantized samples) the
# sample-to-sample differences have no usable scale: the test is not run.
MAX_HELD = 0.2


def jump_test(flight):
    """(warning or None, details): the largest abrupt, lasting jump of q_ci.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
        The samples fitted (time_s, qci_pa).

    Returns
    -------
    warning : str or None
        Names the time of the jump, its size and z when it is over the threshold.
    details : dict
        ``time_s``, ``jump_pa``, ``step`` (fraction of q_ci, q_ci low when positive),
        ``z``, ``threshold``, ``flagged``; ``skipped`` (the reason) when not run.
    """
    qci = r = np.asarray(flight.qci_pa, dtype=float)
    n = r.size
    threshold = float(normal_isf(ALPHA / (2.0 * n))) + MARGIN
    if n < 4 * SPAN:
        return None, {"skipped": "too few samples", "threshold": threshold, "flagged": False}
    if np.mean(np.diff(qci) == 0.0) > MAX_HELD:
        return None, {"skipped": "q_ci held or quantized: no sample-to-sample scale",
                      "threshold": threshold, "flagged": False}
    # across a time gap the airspeed may have changed by anything: no jump there, and the
    # gap's difference is kept out of every running mean and scale
    dt = np.diff(flight.time_s)
    ok = dt <= GAP * np.median(dt)
    z1, scale1 = _standardized(np.diff(r), ok)       # z1[i]: r[i+1] - r[i]
    med = np.median(np.lib.stride_tricks.sliding_window_view(r, SPAN), axis=1)
    jump = med[SPAN:] - med[:-SPAN]                  # jump[k]: between k+SPAN-1 and k+SPAN
    straddles = np.convolve(~ok, np.ones(2 * SPAN - 1), "valid")[:jump.size] > 0
    zm, scale_m = _standardized(jump, ~straddles)
    i = np.arange(SPAN - 1, SPAN - 1 + zm.size)      # the same jump's index in z1
    a = z1[i]
    stat = np.where(np.sign(a) == np.sign(zm), np.minimum(np.abs(a), np.abs(zm)), 0.0)
    k = int(np.argmax(stat))
    at = i[k] + 1                                    # first sample after the jump
    step = float(-jump[k] / med[k])                  # against the median before the jump
    details = {"time_s": float(flight.time_s[at]), "jump_pa": float(jump[k]), "step": step,
               "z": float(np.sign(jump[k]) * stat[k]), "threshold": threshold,
               "flagged": bool(stat[k] > threshold and abs(step) >= MIN_STEP),
               "detectable_pa": detectable_jump_pa(threshold, scale1, scale_m)}
    if not details["flagged"]:
        return None, details
    side = "low" if step > 0 else "high"
    return (f"{flight.source}: q_ci jumps at t = {details['time_s']:.2f} s and stays: it "
            f"steps by {details['jump_pa']:+.1f} Pa at once (q_ci {100 * abs(step):.1f}% "
            f"{side}, z = {details['z']:+.1f}, beyond {threshold:.1f}): a leak, a blockage or "
            "a loose line? One calibration for the whole record does not hold; calibrate "
            "before and after it apart (`start_s`, `end_s`)"), details


def detectable_jump_pa(threshold, scale1, scale_m, power=POWER):
    """The smallest lasting jump of q_ci (Pa) the test flags in about `power` of flights: both
    of its standardized differences must pass `threshold`, each with its own unit-variance
    noise, so the jump stands (threshold + z_power) scales above the larger one; infinite
    when a scale is unknown (no sample-to-sample spread)."""
    scale = max(scale1, scale_m)
    if not scale > 0.0:
        return float("inf")
    return float((threshold + normal_isf(1.0 - power)) * scale)


def _standardized(d, ok):
    """((d - its running mean over 2 CENTER + 1) / (1.4826 MAD) where `ok`, 0 elsewhere; the
    scale 1.4826 MAD): a robust z, unmoved by the few jumps sought; the running mean takes out
    the airspeed's own rate of change, and the entries not `ok` (across a time gap) enter
    neither."""
    d = np.where(ok, d, 0.0)
    c = np.concatenate([[0.0], np.cumsum(d)])
    w = np.concatenate([[0], np.cumsum(ok)])
    lo = np.clip(np.arange(d.size) - CENTER, 0, d.size)
    hi = np.clip(np.arange(d.size) + CENTER + 1, 0, d.size)
    d = d - (c[hi] - c[lo]) / np.maximum(w[hi] - w[lo], 1)
    mad = 1.4826 * float(np.median(np.abs(d[ok]))) if ok.any() else 0.0
    return (np.where(ok, d / mad, 0.0) if mad > 0 else np.zeros_like(d)), mad
