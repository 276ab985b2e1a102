"""Whole-flight logs: the calibration windows, chosen from the log itself.

Most logs are of ordinary flights: take-off, climb, cruise, loiters, a descent, landing. When
no window (`start_s`, `end_s`) is given, `pitotcal.io.logs.load_log` keeps only the steady
flight and groups it into calibration windows. The take-off and landing are already cut by
the autopilot's flight state and the airspeed gate (`pitotcal.io.airborne`); on top of that:

Steady flight, sample by sample (rates over `SMOOTH_S`; each cut widened by `PAD_S` on both
sides, so the transition into and out of it goes too):

- climb or dive: flight-path angle beyond `MAX_PATH_ANGLE_DEG`, from the GPS vertical
  velocity (else the GPS altitude's rate) and ground speed: a full-power climb puts the pitot
  in the propeller wash at a high angle of attack, a dive beyond what calibration flies;
- steep turn: bank beyond `MAX_BANK_DEG`, from the GPS course rate (tan φ = V ω / g): large
  angle of attack and sideslip at the probe;
- rapid airspeed change: |dIAS/dt| beyond `MAX_IAS_RATE_MPS2`: the tubing's pneumatic lag and
  unsteady flow, not the steady pressure error;
- near stall: IAS below `STALL_MARGIN` times the autopilot's minimum airspeed parameter;
- full throttle, where the log has the throttle (ArduPilot ``CTUN.ThO``; PX4
  ``vehicle_thrust_setpoint.xyz[0]`` or ``actuator_controls_0.control[3]``): at or above
  `FULL_THROTTLE` the propeller wash over a nose or wing pitot is at its strongest.

Windows: runs of steady samples shorter than `MIN_RUN_S` are cut; runs closer than
`JOIN_GAP_S` join into one window. A window shorter than `MIN_WINDOW_S`, or whose ground track
turns through no more than `MIN_TRACK_SPREAD_DEG` (the estimator cannot separate its wind
from the calibration otherwise), is cut. Several windows share one calibration and keep their
own wind (`Flight.segment`). When no window qualifies alone, every steady sample is kept as
one window, with a warning: the estimator then says whether the wind separates.

Velocity is the GPS receiver's (`pitotcal.io.timebase.gps_onto`), never the EKF's: the EKF's
velocity carries its own wind and airspeed model, and before it fuses GPS it is no ground
velocity at all.
"""

import numpy as np

from pitotcal.core.flight import MIN_TRACK_SPREAD_DEG, track_spread_deg
from pitotcal.core.units import G0_MPS2, incompressible_cas_mps

__all__ = ["FULL_THROTTLE", "JOIN_GAP_S", "MAX_BANK_DEG", "MAX_IAS_RATE_MPS2",
           "MAX_PATH_ANGLE_DEG", "MIN_RUN_S", "MIN_WINDOW_S", "PAD_S", "SMOOTH_S",
           "STALL_MARGIN", "choose_windows", "steady_cuts", "windows_record", "windows_text"]

SMOOTH_S = 2.0
PAD_S = 2.0
MAX_PATH_ANGLE_DEG = 15.0
MAX_BANK_DEG = 50.0     # above the autopilots' default bank limits (ArduPlane 45 deg)
MAX_IAS_RATE_MPS2 = 2.0
STALL_MARGIN = 0.9
FULL_THROTTLE = 0.95
MIN_RUN_S = 10.0
JOIN_GAP_S = 30.0
MIN_WINDOW_S = 60.0


def steady_cuts(t, qci_pa, gps, s, min_airspeed_mps):
    """{reason: mask} of the samples at times `t` that are not steady flight (module notes).

    Parameters
    ----------
    t, qci_pa : ndarray, shape (N,)
        The pressure samples' times, s, and impact pressures, Pa.
    gps : GpsOnTimes
        GPS on those times (`pitotcal.io.timebase.gps_onto`); NaN-free where `gps.ok`.
    s : LogStreams
        The log's streams: the throttle (``throttle_t``, ``throttle``) where it has one.
    min_airspeed_mps : float
        The autopilot's minimum airspeed, m/s; 0: no near-stall cut.

    Returns
    -------
    dict
        Reason text -> boolean mask of shape (N,), only the reasons that cut something.
    """
    ok = gps.ok & np.isfinite(gps.vn) & np.isfinite(gps.ve)
    vn, ve = _smooth(t, gps.vn, ok), _smooth(t, gps.ve, ok)
    gs = np.maximum(np.hypot(vn, ve), 1.0)
    if s.gps_vd is not None:
        vd = _smooth(t, gps.vd, ok)
    else:
        vd = -_rate(t, _smooth(t, gps.alt, ok))
    path_deg = np.degrees(np.arctan2(np.abs(vd), gs))
    omega = (vn * _rate(t, ve) - ve * _rate(t, vn)) / gs ** 2
    bank_deg = np.degrees(np.arctan(np.abs(gs * omega) / G0_MPS2))
    ias = incompressible_cas_mps(np.maximum(qci_pa, 0.0))
    ias_rate = np.abs(_rate(t, _smooth(t, ias, np.ones(t.size, bool))))
    masks = {
        f"climb or dive (flight-path angle > {MAX_PATH_ANGLE_DEG:g} deg)":
            ok & (path_deg > MAX_PATH_ANGLE_DEG),
        f"steep turn (bank > {MAX_BANK_DEG:g} deg)": ok & (bank_deg > MAX_BANK_DEG),
        f"rapid airspeed change (> {MAX_IAS_RATE_MPS2:g} m/s^2)": ias_rate > MAX_IAS_RATE_MPS2,
    }
    if min_airspeed_mps:
        floor = STALL_MARGIN * min_airspeed_mps
        masks[f"near stall (IAS < {floor:.1f} m/s)"] = ias < floor
    throttle = _throttle_on(t, s)
    if throttle is not None:
        masks[f"full throttle ({s.throttle_source} >= {100 * FULL_THROTTLE:.0f} %)"] = \
            throttle >= FULL_THROTTLE
    return {reason: _widen(t, m, PAD_S) for reason, m in masks.items() if m.any()}


def choose_windows(t, keep, vn_mps, ve_mps):
    """The calibration windows among the kept samples (module notes).

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times, s.
    keep : ndarray of bool, shape (N,)
        The samples every other cut left.
    vn_mps, ve_mps : ndarray, shape (N,)
        GPS ground velocity, m/s.

    Returns
    -------
    (cuts, windows, fallback)
        cuts: {reason: mask} of the kept samples the windows leave out; windows: a list of
        dicts (``start_s``, ``end_s``, ``n_samples``, ``track_spread_deg``, ``reason``) in time
        order, each with ``mask`` (its samples); fallback: True when no window qualified alone
        and every steady sample is one window.
    """
    runs = _runs(keep)
    short = np.zeros(t.size, bool)
    long_runs = []
    for a, b in runs:
        if t[b - 1] - t[a] < MIN_RUN_S:
            short[a:b] = True
        else:
            long_runs.append([a, b])
    groups = []
    for a, b in long_runs:
        if groups and t[a] - t[groups[-1][1] - 1] <= JOIN_GAP_S:
            groups[-1][1] = b
        else:
            groups.append([a, b])
    cuts = {f"steady run shorter than {MIN_RUN_S:g} s": short}
    too_short = np.zeros(t.size, bool)
    no_turn = np.zeros(t.size, bool)
    windows = []
    for a, b in groups:
        mask = np.zeros(t.size, bool)
        mask[a:b] = keep[a:b] & ~short[a:b]
        spread = track_spread_deg(vn_mps[mask], ve_mps[mask])
        if t[b - 1] - t[a] < MIN_WINDOW_S:
            too_short |= mask
        elif spread <= MIN_TRACK_SPREAD_DEG:
            no_turn |= mask
        else:
            windows.append(_window(t, mask, spread, "steady and airborne, at least "
                                   f"{MIN_WINDOW_S:g} s, track turns more than "
                                   f"{MIN_TRACK_SPREAD_DEG:g} deg"))
    if not windows and (too_short | no_turn).any():
        mask = too_short | no_turn
        spread = track_spread_deg(vn_mps[mask], ve_mps[mask])
        return {k: v for k, v in cuts.items() if v.any()}, [_window(
            t, mask, spread, "all steady flight as one window: no window alone is "
            f"{MIN_WINDOW_S:g} s long and turns through {MIN_TRACK_SPREAD_DEG:g} deg")], True
    cuts[f"window shorter than {MIN_WINDOW_S:g} s"] = too_short
    cuts[f"window turns through <= {MIN_TRACK_SPREAD_DEG:g} deg"] = no_turn
    return {k: v for k, v in cuts.items() if v.any()}, windows, False


def _window(t, mask, spread, reason):
    idx = np.flatnonzero(mask)
    return {"start_s": float(t[idx[0]]), "end_s": float(t[idx[-1]]), "n_samples": int(idx.size),
            "track_spread_deg": round(float(spread), 1), "reason": reason, "mask": mask}


def _runs(mask):
    """[(a, b)] index ranges of the runs of True in `mask`."""
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    return list(zip(edges[::2], edges[1::2]))


def _smooth(t, x, ok):
    """Running mean of `x` over `SMOOTH_S` (centred) among the `ok` samples; NaN where none."""
    x = np.where(ok, x, 0.0)
    c = np.r_[0.0, np.cumsum(x)]
    n = np.r_[0, np.cumsum(ok.astype(int))]
    lo = np.searchsorted(t, t - SMOOTH_S / 2, side="left")
    hi = np.searchsorted(t, t + SMOOTH_S / 2, side="right")
    count = n[hi] - n[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, (c[hi] - c[lo]) / count, np.nan)


def _rate(t, x):
    """dx/dt, per s; zero where the neighbours are missing."""
    if t.size < 2:
        return np.zeros(t.size)
    out = np.gradient(x, t)
    return np.where(np.isfinite(out), out, 0.0)


def _widen(t, mask, pad_s):
    """`mask` grown by `pad_s` seconds on both sides of every True sample."""
    hit = np.r_[0, np.cumsum(mask.astype(int))]
    lo = np.searchsorted(t, t - pad_s, side="left")
    hi = np.searchsorted(t, t + pad_s, side="right")
    return (hit[hi] - hit[lo]) > 0


def _throttle_on(t, s):
    """The throttle (0-1) held onto times `t`, or None when the log has none."""
    tt, thr = getattr(s, "throttle_t", None), getattr(s, "throttle", None)
    if tt is None or thr is None or np.size(tt) < 2:
        return None
    good = np.isfinite(tt) & np.isfinite(thr)
    tt, thr = np.asarray(tt, float)[good], np.asarray(thr, float)[good]
    if tt.size < 2:
        return None
    order = np.argsort(tt, kind="stable")
    tt, thr = tt[order], thr[order]
    if np.nanmax(np.abs(thr)) > 1.5:        # logged in percent
        thr = thr / 100.0
    idx = np.clip(np.searchsorted(tt, t, side="right") - 1, 0, tt.size - 1)
    return thr[idx]


def windows_record(t, windows, attributed):
    """{"windows": [...], "cut_s": {reason: seconds}}: what `Flight.reading` records.

    Each window: ``start_s``, ``end_s``, ``n_samples``, ``track_spread_deg``, ``reason``; each
    cut: the seconds of samples cut for it (its samples times the median sample step).
    """
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    return {"windows": [{k: v for k, v in w.items() if k != "mask"}
                        | {"n_samples": int(w["mask"].sum())} for w in windows],
            "cut_s": {reason: round(float(mask.sum()) * step, 1)
                      for reason, mask in attributed.items()}}


def windows_text(reading):
    """One line per window and one for the cuts, from a `Flight.reading` or result record's
    ``windows`` and ``cut_s``; "" when the windows were not chosen from the log."""
    windows = (reading or {}).get("windows")
    if not windows:
        return ""
    lines = [f"window {i + 1}: {w['start_s']:.1f}-{w['end_s']:.1f} s, {w['n_samples']} "
             f"samples, track turns {w['track_spread_deg']:.0f} deg ({w['reason']})"
             for i, w in enumerate(windows)]
    cut = (reading or {}).get("cut_s") or {}
    if cut:
        lines.append("cut: " + "; ".join(f"{reason} {sec:.0f} s" for reason, sec in cut.items()))
    return "\n".join(lines)
