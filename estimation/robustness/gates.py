"""Robust identification: plausibility gates before the fit, trimming after it.

A single sample can decide an output-error fit: a q_ci glitch of 0.01 Pa has a leverage of
1/q_ci on the inverse coefficient, a density of 1e6 multiplies its predicted q_c by a million.
`gate_flight` drops the samples no flying aircraft can produce before the fit; `outliers`
finds the samples whose standardized residual under the fitted noise model is beyond what
Gaussian noise gives, so `estimation.identify` can refit without them. Every drop is one
warning per kind, naming how many and when.
"""

import numpy as np

from pitotcal.core.information import normal_isf
from pitotcal.core.measurement import impact_pressure_pa, tas_squared
from pitotcal.core.units import G0_MPS2, ISA_TOP_M, isa_density_kgm3
from pitotcal.io.flight_checks import PLAUSIBLE

__all__ = ["DENSITY_MARGIN", "FALSE_TRIM_RATE", "MAX_ACCEL_G", "MAX_TRIM_FRACTION",
           "QCI_RATIO_RANGE", "gate_flight", "outliers", "spans_text", "trim_threshold"]

# q_ci / (0.5 rho |V_g|^2) of a flying aircraft, relative to the flight's median ratio: a
# wind of 70 % of the airspeed on one leg gives (1 -/+ 0.7)^-2 / 1 = 0.35 to 11; a glitch of
# 0.01 or 1 Pa among ~1000 Pa samples is 1e-5 to 1e-3.
QCI_RATIO_RANGE = (0.05, 20.0)
# Density against ISA at the flight's altitude (or its median without one): ISA -/+ 50 K
# and a humid day stay inside +-30 %.
DENSITY_MARGIN = 0.35
# Ground-velocity accelerations no calibration flight flies, in g, over a half-second
# window around each sample (the GPS fix's own noise is allowed on top).
MAX_ACCEL_G = 3.0
_ACCEL_WINDOW_S = 0.5
# Trimming: the chance that a clean flight loses any sample, under Gaussian noise (a bound).
FALSE_TRIM_RATE = 0.01
# More samples beyond the threshold than this is not a few glitches: the noise model is wrong.
MAX_TRIM_FRACTION = 0.02
_SPIKE_SAMPLES = 5           # running median of an isolated spike's neighbours (0.1 s at 50 Hz)
_FLIGHT_NAMES = {"qc_pa": "qci_pa"}     # the CSV's column names -> Flight's


def gate_flight(flight):
    """(the flight without implausible samples, warnings): one warning per kind of gate.

    Gates: a channel outside `pitotcal.io.flight_checks.PLAUSIBLE`; density outside ISA at
    the flight's altitude +- `DENSITY_MARGIN`; q_ci / (0.5 rho |V_g|^2) outside
    `QCI_RATIO_RANGE` times its median; a ground velocity off its half-second running median
    by more than `MAX_ACCEL_G` g times a quarter second plus six times the GPS noise.
    """
    n = flight.n
    kinds = []
    bad = np.zeros(n, dtype=bool)
    for column, (lo, hi) in PLAUSIBLE.items():
        name = _FLIGHT_NAMES.get(column, column)
        values = getattr(flight, name, None)
        if values is None or name == "alt_m" or values.shape != (n,):
            continue
        with np.errstate(invalid="ignore"):
            off = np.isfinite(values) & ((values < lo) | (values > hi)) & ~bad
        kinds.append((off, f"{name} outside the plausible {lo:g} to {hi:g}"))
        bad |= off
    for off, text in (_density_gate(flight, bad), _qci_gate(flight, bad), _gps_gate(flight, bad)):
        off &= ~bad
        kinds.append((off, text))
        bad |= off
    warns = tuple(f"{flight.source}: {int(off.sum())} samples dropped before the fit: {text} "
                  f"(first at t = {flight.time_s[np.argmax(off)]:.2f} s)"
                  for off, text in kinds if off.any())
    return (flight.select(~bad) if bad.any() else flight), warns


def _density_gate(flight, skip):
    rho = flight.rho_kgm3
    alt = flight.alt_m
    ok = ~skip & np.isfinite(rho)
    if alt is not None and alt.shape == rho.shape and np.isfinite(alt[ok]).any():
        ref = isa_density_kgm3(np.clip(np.nan_to_num(alt, nan=np.nanmedian(alt[ok])), -1000,
                                       ISA_TOP_M))
        where = "ISA at the flight's altitude"
    else:
        ref = np.full_like(rho, np.median(rho[ok]) if ok.any() else 1.0)
        where = "the flight's median density"
    with np.errstate(invalid="ignore", divide="ignore"):
        off = ok & (np.abs(rho / ref - 1.0) > DENSITY_MARGIN)
    return off, f"density more than {100 * DENSITY_MARGIN:.0f}% from {where}"


def _qci_gate(flight, skip):
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        ratio = flight.qci_pa / impact_pressure_pa(
            flight.rho_kgm3, tas_squared(flight.gps_vn_mps, flight.gps_ve_mps, 0.0, 0.0))
    ok = ~skip & np.isfinite(ratio) & (ratio > 0)
    if not ok.any():
        return np.zeros_like(ok), "q_ci"
    rel = ratio / np.median(ratio[ok])
    lo, hi = QCI_RATIO_RANGE
    off = ok & ((rel < lo) | (rel > hi))
    return off, (f"q_ci outside {lo:g} to {hi:g} times the impact pressure 0.5 rho |V_g|^2 "
                 "implies (the flight's median ratio)")


def _gps_gate(flight, skip):
    """Samples whose ground velocity jumps off its running median faster than MAX_ACCEL_G."""
    from .running import running_median

    n = flight.n
    dt = float(np.median(np.diff(flight.time_s))) if n > 1 else 1.0
    width = max(3, round(_ACCEL_WINDOW_S / max(dt, 1e-9)) | 1)
    off = np.zeros(n, dtype=bool)
    for v in (flight.gps_vn_mps, flight.gps_ve_mps, flight.gps_vd_mps):
        if v is None or v.shape != (n,) or not np.isfinite(v).all():
            continue
        dev = np.abs(v - running_median(v, width))
        noise = 1.4826 * np.median(dev)
        off |= dev > MAX_ACCEL_G * G0_MPS2 * _ACCEL_WINDOW_S / 2 + 6.0 * noise
    return off & ~skip, (f"GPS velocity jumps of more than {MAX_ACCEL_G:g} g "
                         f"(off its {_ACCEL_WINDOW_S:g} s running median)")


def trim_threshold(n, rate=FALSE_TRIM_RATE):
    """|z| beyond which a sample is trimmed: `rate` clean samples per flight of `n`."""
    return float(normal_isf(rate / (2.0 * max(n, 1))))


def outliers(residuals_pa):
    """Boolean mask of the isolated residual spikes beyond `trim_threshold`.

    Standardized residual: (r - median r) / (1.4826 x the median absolute deviation), the
    fitted noise's scale unmoved by the outliers it has to find; Gaussian under the noise
    model, so the per-flight false-trim rate is at most `FALSE_TRIM_RATE` (a union bound).
    A sample is trimmed only when it also stands off its `_SPIKE_SAMPLES`-sample running
    median by half the threshold: the residual of flight is correlated (gusts, GPS error, a
    curved maneuver), and a sustained excursion is that noise, which the colored-residual
    covariance counts, not a glitch.
    """
    from .running import running_median

    r = np.asarray(residuals_pa, dtype=float)
    dev = np.abs(r - np.median(r))
    scale = 1.4826 * np.median(dev)
    if not scale > 0:
        return np.zeros(r.size, dtype=bool)
    threshold = trim_threshold(r.size) * scale
    spike = np.abs(r - running_median(r, _SPIKE_SAMPLES))
    return (dev > threshold) & (spike > 0.5 * threshold)


def spans_text(time_s, mask, limit=5):
    """'t = 12.30-12.34 s, 80.02 s, ...' for the runs of True in `mask` (at most `limit`)."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return ""
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], [idx[-1]]])
    parts = [f"{time_s[a]:.2f} s" if a == b else f"{time_s[a]:.2f}-{time_s[b]:.2f} s"
             for a, b in zip(starts[:limit], ends[:limit])]
    more = f" and {starts.size - limit} more" if starts.size > limit else ""
    return "t = " + ", ".join(parts) + more
