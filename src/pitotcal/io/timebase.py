"""One time base for a log's streams: clean a stream, carry it onto other times, cut samples.

Used by `pitotcal.io.logs` (the module notes there say why GPS is interpolated, not held, by
default). Every cut is logged at INFO with its sample count and time spans.
"""

import logging
from typing import NamedTuple

import numpy as np

from pitotcal.core.errors import FlightDataError

from .resample import latest_index

__all__ = ["GpsOnTimes", "apply_cuts", "clean", "gps_onto", "onto", "spans"]

log = logging.getLogger("pitotcal.io.logs")      # cuts are reported under the log reader


def clean(t, *arrays):
    """Sort by time and drop repeated times and non-finite rows of a stream."""
    good = np.isfinite(t)
    for a in arrays:
        good &= np.isfinite(a)
    t = t[good]
    arrays = [a[good] for a in arrays]
    order = np.argsort(t, kind="stable")
    t = t[order]
    arrays = [a[order] for a in arrays]
    first = np.ones(t.size, dtype=bool)
    first[1:] = np.diff(t) > 0
    return (t[first], *[a[first] for a in arrays])


def onto(t, ts, values, max_gap_s, hold):
    """`values` (at sorted times `ts`) at times `t`, and where that is trustworthy.

    Linear: between two neighbours at most `max_gap_s` apart. Hold: the last sample at or
    before t (`pitotcal.io.resample`), at most `max_gap_s` old.
    """
    prev, has_prev = latest_index(ts, t)
    if hold:
        return values[prev], has_prev & (t - ts[prev] <= max_gap_s)
    nxt = np.minimum(prev + 1, ts.size - 1)
    has_next = prev + 1 < ts.size
    exact = has_prev & (ts[prev] == t)
    ok = exact | (has_prev & has_next & (ts[nxt] - ts[prev] <= max_gap_s))
    return np.interp(t, ts, values), ok


class GpsOnTimes(NamedTuple):
    """GPS on the pressure times, and where a valid fix backs it."""

    vn: np.ndarray
    ve: np.ndarray
    vd: np.ndarray
    alt: np.ndarray
    ok: np.ndarray


def gps_onto(t, s, name, gps_resample, gps_latency_s):
    """The valid GPS fixes of the streams `s` carried onto the times `t`, as `GpsOnTimes`.

    A time gets GPS data only when both neighbouring valid fixes are at most
    max(0.5 s, 3 GPS periods) apart (`onto`), so an interpolation never bridges a lost fix.
    """
    if s.gps_t is None or s.gps_t.size == 0:
        raise FlightDataError(f"{name}: no GPS velocity in the log")
    vd_in = s.gps_vd if s.gps_vd is not None else np.zeros_like(s.gps_t)
    alt_in = s.gps_alt_m if s.gps_alt_m is not None else np.zeros_like(s.gps_t)
    valid = np.asarray(s.gps_ok, bool)
    tg, *fixes = clean(np.asarray(s.gps_t, float)[valid] - gps_latency_s, s.gps_vn[valid],
                       s.gps_ve[valid], vd_in[valid], alt_in[valid])
    if tg.size < 2:
        raise FlightDataError(f"{name}: no valid GPS velocity in the log "
                              f"({int(valid.sum())} fixes with a 3D fix of {valid.size})")
    gap = max(0.5, 3.0 * float(np.median(np.diff(tg))))
    hold = gps_resample == "hold"
    on = [onto(t, tg, values, gap, hold) for values in fixes]
    return GpsOnTimes(*(values for values, _ in on), ok=on[0][1])


def spans(t, mask, limit=4):
    """'a-b s' strings of the runs of `mask` (at most `limit`, then '...')."""
    if not mask.any():
        return ""
    edges = np.flatnonzero(np.diff(np.r_[0, mask.view(np.int8), 0]))
    runs = [f"{t[a]:.1f}-{t[b - 1]:.1f} s" for a, b in zip(edges[::2], edges[1::2])]
    return ", ".join(runs[:limit]) + (", ..." if len(runs) > limit else "")


def apply_cuts(name, t, cuts):
    """Cut the samples of each reason in `cuts` ({reason: mask}), in order.

    Each cut sample is counted once, under the first reason that applies. Returns (keep,
    excluded, attributed): the samples kept, {reason: count} and {reason: mask of the samples
    counted under it}; every cut is logged at INFO with its spans.
    """
    keep = np.ones(t.size, bool)
    excluded, attributed = {}, {}
    for reason, mask in cuts.items():
        new = mask & keep
        if new.any():
            excluded[reason], attributed[reason] = int(new.sum()), new
            log.info("%s: cut %d of %d samples for %s (%s)", name, new.sum(), t.size, reason,
                     spans(t, new))
        keep &= ~new
    return keep, excluded, attributed
