"""GPS legs from a flight time series: steady segments detected or given, one leg row each.

A leg is a stretch of steady flight: ground track, ground speed and indicated airspeed each
inside a band of ± tolerance about their values over the stretch, for at least a minimum time.
`detect_segments` finds them on 1 s means smoothed over `smooth_s` (gusts and GPS noise would
otherwise break every band), greedily from the earliest start, and trims `smooth_s / 2 + 1 s`
from each end (the smoothing and the 1 s bins carry the turn into the leg's edges). `legs_from_flight` turns each
segment into one row of the leg CSV (`pitotcal.io.legs_csv.LegData`):

- ground speed and track from the mean ground velocity vector over the segment;
- groundspeed_sd_kt, the standard uncertainty of that mean per component: the samples of one
  leg are far from independent (gusts), so the variance of the mean comes from the colored-
  residual covariance of the identify method (white noise plus an exponential decay fitted to
  the autocovariance), pooled over north and east and then over every leg of the flight (one
  turbulence and one GPS: the pooled value has the degrees of freedom one leg lacks);
- IAS from the mean q_ci by the standard CAS law, pressure altitude from the mean static-port
  pressure `ps_pa`, OAT from `oat_k`;
- points: segments whose IAS lie within `point_tol_kt` and pressure altitudes within
  `POINT_ALT_TOL_FT` of a point's first segment join it (points numbered in time order),
  unless the windows name their points.

The default tolerances (`DETECT_DEFAULTS`) follow the GPS-leg write-ups' flying technique —
straight and level at one airspeed and altitude, about a minute per leg once stabilised
(Gray 1998; Lewis, NTPS 2003; FAA AC 23-8) — widened to what light turbulence (0.5 m/s rms)
leaves on smoothed data; they are options, to tighten for smooth air.
"""

import csv

import numpy as np

from pitotcal.core import airdata
from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.core.units import FT_TO_M, KT_TO_MPS
from pitotcal.io.legs_csv import LegData

__all__ = ["DETECT_DEFAULTS", "POINT_ALT_TOL_FT", "analyze_leg_flight", "detect_segments",
           "leg_samples", "legs_from_flight", "parse_windows", "pool_sd", "read_windows"]

DETECT_DEFAULTS = {"min_leg_s": 30.0, "track_tol_deg": 3.0, "groundspeed_tol_kt": 3.0,
                   "ias_tol_kt": 2.0, "smooth_s": 5.0}
POINT_TOL_KT = 3.0            # IAS within which segments are one calibration point
POINT_ALT_TOL_FT = 500.0      # ... and pressure altitude
MIN_IAS_KT = 30.0             # slower is taxiing or parked, not a leg


def _require_air_data(flight):
    for name in ("ps_pa", "oat_k"):
        if getattr(flight, name) is None:
            raise FlightDataError(
                f"{flight.source}: no {name}: the leg methods need the static pressure (pressure "
                f"altitude) and the outside air temperature of every leg")


def _second_means(flight):
    """(bin start times, mean vn, ve, IAS kt per 1 s bin; NaN for an empty bin)."""
    t = flight.time_s
    b = np.floor(t - t[0]).astype(int)
    count = np.bincount(b).astype(float)
    with np.errstate(invalid="ignore"):
        means = [np.bincount(b, weights=x) / count
                 for x in (flight.gps_vn_mps, flight.gps_ve_mps, flight.qci_pa)]
    ias = np.full(count.size, np.nan)
    seen = count > 0                       # a gap in the record leaves empty bins
    ias[seen] = airdata.cas_from_qc_mps(np.clip(means[2][seen], 0.0, None)) / KT_TO_MPS
    return t[0] + np.arange(count.size), means[0], means[1], ias


def _smooth(x, n):
    """Centred moving average over n bins; NaN where the window holds a NaN."""
    if n <= 1:
        return x
    kernel = np.ones(n) / n
    gaps = np.convolve(np.isnan(x).astype(float), np.ones(n), mode="same") > 0.5
    gaps[:n // 2] = gaps[x.size - (n - 1) // 2:] = True     # the window runs off the record
    return np.where(gaps, np.nan, np.convolve(np.nan_to_num(x), kernel, mode="same"))


def detect_segments(flight, min_leg_s=30.0, track_tol_deg=3.0, groundspeed_tol_kt=3.0,
                    ias_tol_kt=2.0, smooth_s=5.0):
    """Steady segments of a flight (module docstring).

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
    min_leg_s : float
        Shortest segment kept, s (after trimming).
    track_tol_deg, groundspeed_tol_kt, ias_tol_kt : float
        Half-widths of the bands the smoothed track, ground speed and IAS must stay in.
    smooth_s : float
        Moving-average length, s.

    Returns
    -------
    ndarray, shape (n, 2)
        (start_s, end_s) of each segment, in time order.
    """
    t0, vn, ve, ias = _second_means(flight)
    # at most the record's own length in 1 s bins: a longer window smooths nothing more
    # (and no segment then fits in the record), but would cost its length in memory
    n = max(1, min(round(float(smooth_s)), t0.size))
    vn, ve, ias = _smooth(vn, n), _smooth(ve, n), _smooth(ias, n)
    gs = np.hypot(vn, ve) / KT_TO_MPS
    track = np.degrees(np.arctan2(ve, vn))
    ok = np.isfinite(gs) & np.isfinite(ias) & (ias >= MIN_IAS_KT)
    trim = 0.5 * smooth_s + 1.0        # the smoothing's reach, and the 1 s bins'
    need = min_leg_s + 2.0 * trim
    out, i = [], 0
    while i < t0.size:
        if not ok[i]:
            i += 1
            continue
        j = _extend(i, ok, track, gs, ias, track_tol_deg, groundspeed_tol_kt, ias_tol_kt)
        if t0[j] + 1.0 - t0[i] >= need:
            out.append((t0[i] + trim, t0[j] + 1.0 - trim))
            i = j + 1
        else:
            i += 1
    return np.array(out, dtype=float).reshape(-1, 2)


def _extend(i, ok, track, gs, ias, track_tol, gs_tol, ias_tol):
    """Last bin j such that bins i..j stay inside every band."""
    lo = np.array([0.0, gs[i], ias[i]])
    hi = lo.copy()
    j = i
    while j + 1 < ok.size and ok[j + 1]:
        x = np.array([(track[j + 1] - track[i] + 180.0) % 360.0 - 180.0, gs[j + 1], ias[j + 1]])
        nlo, nhi = np.minimum(lo, x), np.maximum(hi, x)
        if (nhi - nlo > 2.0 * np.array([track_tol, gs_tol, ias_tol])).any():
            break
        lo, hi, j = nlo, nhi, j + 1
    return j


def parse_windows(text, option="windows"):
    """'t0-t1,t2-t3,...' (seconds of the flight's time base) -> list of (t0, t1, None)."""
    out = []
    for part in str(text).split(","):
        bits = part.strip().split("-")
        try:
            if len(bits) != 2:
                raise ValueError
            lo, hi = float(bits[0]), float(bits[1])
        except ValueError:
            raise PitotcalError(f"{option}: {part.strip()!r} is not a window START-END in "
                                f"seconds (e.g. 120-180)", param="windows") from None
        if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
            raise PitotcalError(f"{option}: window {part.strip()}: the end must come after the "
                                f"start", param="windows")
        out.append((lo, hi, None))
    return out


def read_windows(path):
    """A windows CSV: columns start_s, end_s and optional point -> list of (t0, t1, point)."""
    name = str(path)
    with open(path, newline="", encoding="utf-8-sig") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise FlightDataError(f"{name}: empty windows file (columns start_s, end_s, point)")
    header = [c.strip() for c in rows[0]]
    for c in ("start_s", "end_s"):
        if c not in header:
            raise FlightDataError(f"{name}: missing column {c}; a windows file has start_s, "
                                  f"end_s and optionally point")
    out = []
    for r, row in enumerate(rows[1:], start=1):
        cells = dict(zip(header, (c.strip() for c in row)))
        (lo, hi, _), = parse_windows(f"{cells.get('start_s', '')}-{cells.get('end_s', '')}",
                                     option=f"{name}: row {r}")
        label = cells.get("point") or None
        out.append((lo, hi, label))
    if not out:
        raise FlightDataError(f"{name}: header only, no windows")
    return out


def _segment_mask(flight, lo, hi):
    return (flight.time_s >= lo) & (flight.time_s <= hi)


def _mean_velocity_sd(vn, ve):
    """Standard uncertainty of the mean velocity per component, m/s: the variance of a mean
    under colored noise (`estimation.uncertainty.covariance.colored_covariance` with a column of ones:
    gusts keep a leg's samples correlated for seconds), pooled over north and east."""
    from ..uncertainty.covariance import colored_covariance, student_t_widening

    ones = np.ones((vn.size, 1))
    var = []
    for x in (vn, ve):
        c = colored_covariance(ones, x - x.mean())
        # without the Student-t widening for one leg's few correlation times: the legs' errors
        # are pooled by the point and global fits, whose own degrees of freedom set the bounds
        var.append(c.covariance[0, 0] / student_t_widening(c.dof) ** 2)
    return float(np.sqrt(np.mean(var)))


def legs_from_flight(flight, windows, point_tol_kt=POINT_TOL_KT, pool=True):
    """One leg per window (module docstring).

    Parameters
    ----------
    flight : Flight
        With `ps_pa` and `oat_k`.
    windows : sequence of (start_s, end_s, point or None)
        Point labels given for every window are used; otherwise points are grouped by IAS.
    point_tol_kt : float
    pool : bool
        Give every leg the pooled groundspeed_sd (`pool_sd`); else each leg its own.

    Returns
    -------
    (LegData, ndarray shape (n, 2))
        The legs (duration_s the window's sampled span) and each leg's (start_s, end_s).
    """
    _require_air_data(flight)
    if not len(windows):
        raise FlightDataError(f"{flight.source}: no legs (no steady segments found, or no "
                              f"windows given)")
    rows = []
    for lo, hi, label in windows:
        m = _segment_mask(flight, lo, hi)
        if m.sum() < 10:
            raise FlightDataError(f"{flight.source}: window {lo:g}-{hi:g} s holds {int(m.sum())} "
                                  f"samples (need 10 or more)")
        vn, ve, t = flight.gps_vn_mps[m], flight.gps_ve_mps[m], flight.time_s[m]
        rows.append((float(vn.mean()), float(ve.mean()), _mean_velocity_sd(vn, ve),
                     float(flight.qci_pa[m].mean()), float(flight.ps_pa[m].mean()),
                     float(flight.oat_k[m].mean()), float(t[-1] - t[0]), label, lo, hi))
    r = np.array([row[:7] for row in rows])
    ias = airdata.cas_from_qc_mps(r[:, 3]) / KT_TO_MPS
    alt_m = airdata.pressure_altitude_m(r[:, 4])
    given = [row[7] for row in rows]
    labels = (tuple(str(p) for p in given) if all(p is not None for p in given)
              else _group(ias, alt_m, point_tol_kt))
    legs = LegData(point=labels, ias_kt=ias, qci_pa=r[:, 3], pressure_alt_m=alt_m,
                   oat_k=r[:, 5], groundspeed_mps=np.hypot(r[:, 0], r[:, 1]),
                   track_deg=np.degrees(np.arctan2(r[:, 1], r[:, 0])) % 360.0,
                   duration_s=r[:, 6], groundspeed_sd_mps=r[:, 2], source=flight.source,
                   sd_from="samples")
    return pool_sd(legs) if pool else legs, np.array([row[8:10] for row in rows], dtype=float)


def pool_sd(legs):
    """`legs` with every groundspeed_sd replaced by their root mean square.

    Each leg's own value rests on a few correlation times of gusts; weighting the legs by such
    noisy estimates made the global fit's bounds too small (study legs-flight, 100 runs: 85 %
    coverage with each leg's own, 94.5 % pooled).
    """
    from dataclasses import replace

    pooled = float(np.sqrt(np.mean(legs.groundspeed_sd_mps ** 2)))
    return replace(legs, groundspeed_sd_mps=np.full(legs.n, pooled))


def _group(ias, alt_m, tol_kt):
    """Point labels '1', '2', ... in time order: a segment joins the first point whose first
    segment is within `tol_kt` and `POINT_ALT_TOL_FT`."""
    refs, labels = [], []
    for v, h in zip(ias, alt_m):
        for j, (rv, rh) in enumerate(refs):
            if abs(v - rv) <= tol_kt and abs(h - rh) <= POINT_ALT_TOL_FT * FT_TO_M:
                labels.append(str(j + 1))
                break
        else:
            refs.append((v, h))
            labels.append(str(len(refs)))
    return tuple(labels)


def _drop_short_points(legs, spans):
    """Detected points with fewer than three legs (a straight climb, a lone cruise leg) left
    out, each with a note; (legs, spans, notes)."""
    from dataclasses import replace

    keep, notes = [], []
    for label in legs.points():
        idx = legs.indices(label)
        if idx.size >= 3:
            keep += list(idx)
            continue
        when = ", ".join(f"{spans[i, 0]:.0f}-{spans[i, 1]:.0f} s" for i in idx)
        notes.append(f"detected point {label} ({legs.ias_kt[idx[0]]:.0f} KIAS) has "
                     f"{idx.size} leg{'s' * (idx.size > 1)} ({when}): left out, three are needed")
    if not keep:
        raise FlightDataError(f"{legs.source}: no indicated airspeed was flown on three or more "
                              f"steady legs; {'; '.join(notes)}")
    keep = np.sort(keep)
    arrays = ("ias_kt", "qci_pa", "pressure_alt_m", "oat_k", "groundspeed_mps", "track_deg",
              "duration_s", "groundspeed_sd_mps")
    legs = replace(legs, point=tuple(legs.point[i] for i in keep),
                   **{a: getattr(legs, a)[keep] for a in arrays})
    return legs, spans[keep], notes


def leg_samples(flight, spans):
    """The flight restricted to the samples inside the legs' (start_s, end_s) spans."""
    mask = np.zeros(flight.n, dtype=bool)
    for lo, hi in spans:
        mask |= _segment_mask(flight, lo, hi)
    return flight.select(mask)


def analyze_leg_flight(flight, windows=None, model="inverse", wind="per-band",
                       point_tol_kt=POINT_TOL_KT, **detect):
    """Legs of a flight (detected, or the given windows), the classic per-point solutions, the
    leg-level global fit, and the output-error fit of the legs' own samples.

    Parameters
    ----------
    flight : Flight
        With `ps_pa` and `oat_k`.
    windows : sequence of (start_s, end_s, point or None), optional
        The legs; detected with `detect` (`DETECT_DEFAULTS` keys) when None.
    model, wind :
        As `estimation.legs.report.analyze_legs`.

    Returns
    -------
    dict
        legs (LegData), spans (n, 2), points, fit (LegFit or None), series
        (IdentificationResult or None: `identify` on the legs' samples, one wind, colored-
        residual bounds), notes (list of str), detection (the options used, or "windows"),
        leg_sd_own_mps (each leg's own sd of the mean velocity; `legs` carries the pooled one).
    """
    import warnings

    from pitotcal.core.errors import ObservabilityError

    from ..identification.identify import identify
    from .report import analyze_legs

    _require_air_data(flight)
    options = {**DETECT_DEFAULTS, **detect}
    if windows is None:
        spans = detect_segments(flight, **options)
        windows = [(lo, hi, None) for lo, hi in spans]
        detection = options
    else:
        detection = "windows"
    if not len(windows):
        raise FlightDataError(
            f"{flight.source}: no steady segment of {options['min_leg_s']:g} s or more (track "
            f"±{options['track_tol_deg']:g}°, ground speed ±{options['groundspeed_tol_kt']:g} "
            f"kt, IAS ±{options['ias_tol_kt']:g} kt): give the legs' time windows, or widen "
            f"the tolerances")
    legs, spans = legs_from_flight(flight, windows, point_tol_kt=point_tol_kt, pool=False)
    dropped = []
    if detection != "windows":
        legs, spans, dropped = _drop_short_points(legs, spans)
    own_sd = legs.groundspeed_sd_mps
    legs = pool_sd(legs)
    points, fit, notes = analyze_legs(legs, model=model, wind=wind)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            series = identify(leg_samples(flight, spans), model, air="compressible")
        extra = [f"time-series fit: {w}" for w in series.warnings]
    except (ObservabilityError, FlightDataError) as exc:
        series = None
        extra = [f"no time-series fit: {exc}"]
    for note in dropped + extra:
        warnings.warn(note, stacklevel=2)
    notes = dropped + notes + extra
    if fit is not None and len(fit.group_labels) > 1 and series is not None:
        extra.append(f"the time-series fit has one wind for the record, but the legs span "
                     f"{len(fit.group_labels)} altitude bands ({', '.join(fit.group_labels)}): "
                     f"compare it with the leg-level fit, which has a wind per band")
        warnings.warn(extra[-1], stacklevel=2)
        notes.append(extra[-1])
    return {"legs": legs, "spans": spans, "points": points, "fit": fit, "series": series,
            "notes": notes, "detection": detection, "leg_sd_own_mps": own_sd}
