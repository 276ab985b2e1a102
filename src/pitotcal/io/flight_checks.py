"""The flight CSV's checks: the time window, unusable rows, time order and the units.

`pitotcal.io.flight_csv` parses the file; this module judges what it parsed (the rules are in
that module's docstring). Every data problem is a `FlightDataError` naming the file, the column
and, where there is one, the row.
"""

import warnings

import numpy as np

from pitotcal.core import checks
from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.core.measurement import impact_pressure_pa, tas_squared
from pitotcal.core.units import (G0_MPS2, R_AIR_JKGK, isa_altitude_m, isa_pressure_pa,
                                 isa_temperature_k)

__all__ = ["MAX_BAD_FRACTION", "PLAUSIBLE", "QCI_MIN_FLYING_PA", "check_plausible",
           "check_time_by_acceleration", "check_time_units",
           "check_units", "check_vertical_speed", "check_window", "drop_bad_rows", "looks_utf16"]

MAX_BAD_FRACTION = 0.01      # more unusable rows than this is a bad column, not a glitch
QCI_MIN_FLYING_PA = 20.0     # 0.5 * 1.225 * (11 kt)^2: nothing that flies is slower
# Read when present but never used in the fit (plots, checks): a bad cell there is NaN in
# `Flight.alt_m`, not a reason to drop the row or reject the file.
INFORMATIVE = ("alt_m",)
_POSITIVE = ("qc_pa", "rho_kgm3", "ps_pa", "oat_k", "ps_ref_pa")
# A cell outside these bounds is no measurement of a flying aircraft (a logger
# glitch, a corrupt cell): unusable like NaN. GNSS receivers stop reporting velocity above
# 515 m/s (the COCOM limit, 1000 kt); 2e5 Pa is the impact pressure of Mach 1.6 at sea level;
# 2.5 kg/m^3 and 1.2e5 Pa are beyond any air at any airfield (ISA -90 degC at 1.08 bar is
# 2.05 kg/m^3); 400 K is 127 degC, and 150 K (-123 degC) is colder than any air flown in
# (the coldest measured is about -90 degC), so a cell below it is a degC value among kelvin.
PLAUSIBLE = {"qc_pa": (0.0, 2e5), "gps_vn_mps": (-515.0, 515.0),
             "gps_ve_mps": (-515.0, 515.0), "gps_vd_mps": (-515.0, 515.0),
             "rho_kgm3": (0.0, 2.5), "ps_pa": (0.0, 1.2e5), "ps_ref_pa": (0.0, 1.2e5),
             "oat_k": (150.0, 400.0), "alt_m": (-1000.0, 1e5)}

# Unit diagnosis (see the flight_csv module docstring). q_ci / (0.5 rho |V_g|^2) of a flying
# aircraft is 1 / (1 + (W/V)^2) on a full circle and at worst (1 -/+ W/V)^-2 on one leg:
# 0.35-4 covers winds up to ~70 % of the airspeed while knots (0.26) and every pressure unit
# fall outside.
_RATIO_OK = (0.35, 4.0)
# (unit, Pa per unit) and (unit, m/s per unit): what a logger or a hand conversion writes
_PRESSURE_UNITS = (("Pa", 1.0), ("hPa (mbar)", 100.0), ("kPa", 1000.0), ("psi", 6894.757),
                   ("inH2O", 249.089), ("mmH2O", 9.80665), ("inHg", 3386.389))
# static pressure: the same, plus mmHg (a barometer's unit; as an impact pressure it is
# within the wind's factor of hPa, so it is not guessed for q_ci)
_STATIC_UNITS = (*_PRESSURE_UNITS[1:], ("mmHg", 133.3224))
_SPEED_UNITS = (("m/s", 1.0), ("knots", 1852.0 / 3600.0), ("km/h (or ft/s)", 1.0 / 3.6),
                ("mph", 0.44704), ("cm/s", 0.01))
_WRONG_UNIT_COST = 0.2
# named only as the one wrong column: paired with a wrong speed unit they would explain
# almost any factor (speeds x 6 fit mmH2O with knots within 3 %)
_ALONE_ONLY = ("mmH2O", "inHg")
_PS_RANGE_PA = (5e3, 1.2e5)          # a static pressure of flight: 0 to 20 km, any weather


def check_window(start_s=None, end_s=None):
    """The time window as floats (or None): finite numbers with start_s < end_s.

    Raises `PitotcalError` naming the parameter (`param`), so the command line shows its flag.
    """
    start_s = None if start_s is None else checks.number("start_s", start_s)
    end_s = None if end_s is None else checks.number("end_s", end_s)
    if start_s is not None and end_s is not None and start_s >= end_s:
        raise PitotcalError(f"start_s {start_s:g} must be before end_s {end_s:g}",
                            param="start_s")
    return start_s, end_s


def window_text(start_s, end_s):
    """'start_s=10, end_s=20' (the bounds given) for messages."""
    given = [f"{name}={value:g}" for name, value in (("start_s", start_s), ("end_s", end_s))
             if value is not None]
    return ", ".join(given) or "the whole file"


def _row_problem(table, data_row, r, use):
    """(column, problem) of a row, or None if it is usable."""
    if r in table.bad and table.bad[r][0] not in INFORMATIVE:
        return table.bad[r]
    for c, v in zip(use, data_row):
        if c in INFORMATIVE:
            continue
        if np.isnan(v):
            return c, "NaN"
        if np.isinf(v):
            return c, f"{'-' if v < 0 else ''}infinite"
        if c == "qc_pa" and v <= 0:
            return c, f"q_ci = {v:g} Pa is not positive"
        if c in _POSITIVE and v <= 0:
            return c, f"{v:g} is not positive"
        if c in PLAUSIBLE and not _plausible(c, v):
            lo, hi = PLAUSIBLE[c]
            return c, f"{v:g} is outside the plausible {lo:g} to {hi:g}"
    return None


def _glitches(data, use):
    """Rows with an implausible cell in a column where such cells are glitches (at most
    `MAX_BAD_FRACTION` of the rows); more is a unit or a column problem, said by the unit
    checks or `check_plausible`."""
    out = np.zeros(data.shape[0], dtype=bool)
    for j, c in enumerate(use):
        if c in PLAUSIBLE and c not in INFORMATIVE:
            off = np.isfinite(data[:, j]) & ~_plausible(c, data[:, j])
            if off.sum() <= MAX_BAD_FRACTION * data.shape[0]:
                out |= off
    return out


def check_plausible(name, table, data, rows, use):
    """Refuse a file with cells outside `PLAUSIBLE` left after the unit checks, naming the
    first (column, row, value) and how many."""
    for j, c in enumerate(use):
        if c in PLAUSIBLE and c not in INFORMATIVE:
            off = np.flatnonzero(~_plausible(c, data[:, j]))
            if off.size:
                lo, hi = PLAUSIBLE[c]
                r = int(off[0])
                raise FlightDataError(f"{name}: column {c}, {table.where(rows[r])}: "
                                      f"{data[r, j]:g} is outside the plausible {lo:g} to {hi:g} "
                                      f"({off.size} of {data.shape[0]} rows)")


def _plausible(column, value):
    """True (elementwise) where `value` is inside the column's `PLAUSIBLE` range."""
    lo, hi = PLAUSIBLE.get(column, (-np.inf, np.inf))
    with np.errstate(invalid="ignore"):
        return (value >= lo) & (value <= hi)


def _bad_rows(table, data, rows, use):
    """Boolean mask of the unusable rows; bad informative cells become NaN in `data`."""
    col = {c: j for j, c in enumerate(use)}
    used = [j for j, c in enumerate(use) if c not in INFORMATIVE]
    bad = ~np.isfinite(data[:, used]).all(axis=1)
    for c in _POSITIVE:
        if c in col:
            bad |= data[:, col[c]] <= 0
    bad |= _glitches(data, use)
    if table.bad:
        # a row whose first problem is in an informative column has no problem elsewhere
        # (cells are checked in `use` order, informative columns last)
        bad |= np.isin(rows, [r for r, (c, _) in table.bad.items() if c not in INFORMATIVE])
    for c in INFORMATIVE:
        if c in col:            # informative only: a bad cell is NaN there, the row stays
            v = data[:, col[c]]
            data[:, col[c]] = np.where(np.isfinite(v) & _plausible(c, v), v, np.nan)
    return bad


def drop_bad_rows(name, table, data, rows, use):
    """Drop the unusable rows (at most `MAX_BAD_FRACTION`), else reject the file.

    Returns (data, rows, n_dropped, warning): `warning` is the one warning text given (also
    issued with `warnings.warn`), or None.
    """
    bad = _bad_rows(table, data, rows, use)
    n_bad, n = int(bad.sum()), data.shape[0]
    if n_bad == 0:
        return data, rows, 0, None
    first = int(np.flatnonzero(bad)[0])
    c, problem = _row_problem(table, data[first], rows[first], use)
    where = f"column {c}, {table.where(rows[first])}: {problem}"
    if n_bad > MAX_BAD_FRACTION * n:
        whole = _whole_column_bad(table, data, rows, use)
        if whole:
            raise FlightDataError(f"{name}: column {whole}: no usable value in any row (first: "
                                  f"{table.where(rows[first])}: {problem})")
        raise FlightDataError(f"{name}: {where} ({n_bad} of {n} rows unusable, more than "
                              f"{MAX_BAD_FRACTION:.0%}; fix them or cut them out with "
                              "start_s/end_s)")
    text = f"{name}: dropped {n_bad} of {n} rows with unusable values (first: {where})"
    warnings.warn(text, stacklevel=4)
    keep = ~bad
    return data[keep], rows[keep], n_bad, text


def _whole_column_bad(table, data, rows, use):
    for j, c in enumerate(use):
        if c in INFORMATIVE:
            continue
        v = data[:, j]
        ok = np.isfinite(v) & ((v > 0) if c in _POSITIVE else True)
        ok &= ~np.isin(rows, [r for r, (cc, _) in table.bad.items() if cc == c])
        if not ok.any():
            return c
    return None


def check_time(name, table, t, rows):
    """Time strictly increasing, else the first offending row."""
    step = np.diff(t)
    back = np.flatnonzero(step <= 0)
    if back.size:
        k = int(back[0]) + 1
        how = "duplicates" if step[k - 1] == 0 else "is before"
        raise FlightDataError(f"{name}: column time_s, {table.where(rows[k])}: time {t[k]:.6g} s "
                              f"{how} the previous row's {t[k - 1]:.6g} s; time must be strictly "
                              "increasing")


def check_rho(name, rho):
    med = float(np.median(rho))
    if 0.15 <= med <= 1.6:
        return
    # the density in another unit: g/m^3, lb/ft^3 (1 lb/ft^3 = 16.0185 kg/m^3), slug/ft^3
    units = (("g/m^3", 1e-3), ("lb/ft^3", 16.0185), ("slug/ft^3", 515.379))
    unit = next((f" (looks like {u}: x {k:g} to kg/m^3)" for u, k in units
                 if 0.15 <= med * k <= 1.6), "")
    raise FlightDataError(f"{name}: column rho_kgm3: median {med:.4g} is not an air density in "
                          f"kg/m^3 (0.15-1.6){unit}")


def check_ps_oat(name, ps, oat, column="ps_pa", *, rho=None, alt=None):
    """Static pressure in Pa (not hPa, kPa, psi, inHg, mmHg) and temperature in K (not degC,
    degF).

    kPa, psi and inHg overlap in value (14 is psi at sea level or kPa at 14 km), so a pressure
    in another unit is named by the unit whose value in Pa is nearest to a reference: rho R T
    of a `rho_kgm3` column (`rho`), else the ISA pressure at the median `alt` (m), else sea
    level (then every unit that fits is named).
    """
    med = float(np.median(ps))
    if not _PS_RANGE_PA[0] <= med <= _PS_RANGE_PA[1]:
        raise FlightDataError(f"{name}: column {column}: median {med:.5g} "
                              f"{_static_unit_text(med, oat, rho, alt)}; expected Pa (about "
                              "101325 at sea level)")
    _check_oat(name, float(np.median(oat)), med)


def _static_unit_text(med, oat, rho, alt):
    """'looks like psi (x 6894.757 to Pa; ...)' or 'is not a static pressure'."""
    fits = [(u, f) for u, f in _STATIC_UNITS if _PS_RANGE_PA[0] <= med * f <= _PS_RANGE_PA[1]]
    if not fits:
        return "is not a static pressure"
    ref, against = _reference_ps(oat, rho, alt)
    fits.sort(key=lambda uf: abs(np.log(med * uf[1] / ref)))
    unit, factor = fits[0]
    text = f"looks like {unit} (x {factor:g} to Pa"
    if against:
        return text + f"; {med * factor:.0f} Pa against {ref:.0f} Pa from {against})"
    others = ", ".join(f"{u} (x {f:g})" for u, f in fits[1:])
    return text + (f"; or {others}" if others else "") + ")"


def _reference_ps(oat, rho, alt):
    """(pressure, Pa, what it comes from) to tell the units apart; ('', sea level) if none."""
    t_med = float(np.median(oat)) if oat is not None else np.nan
    if rho is not None and 150.0 <= t_med <= 400.0:
        r = float(np.median(rho))
        if 0.15 <= r <= 1.6:
            return r * R_AIR_JKGK * t_med, "rho_kgm3 R oat_k"
    if alt is not None and np.isfinite(alt).any():
        h = float(np.nanmedian(alt))
        if -500.0 <= h <= 20000.0:
            return float(isa_pressure_pa(h)), f"the ISA at alt_m {h:.0f} m"
    return float(isa_pressure_pa(0.0)), ""


def _check_oat(name, med, ps_pa):
    """The outside air temperature in K: degC and degF are named (the one nearer the ISA
    temperature at the static pressure `ps_pa`)."""
    if med < 150:
        t_isa = float(isa_temperature_k(isa_altitude_m(ps_pa)))
        as_c, as_f = med + 273.15, (med - 32.0) / 1.8 + 273.15
        if abs(as_f - t_isa) < abs(as_c - t_isa) and 180.0 <= as_f <= 330.0:
            raise FlightDataError(f"{name}: column oat_k: median {med:.4g} looks like degrees "
                                  "Fahrenheit; expected kelvin (K = (degF - 32) / 1.8 + 273.15)")
        raise FlightDataError(f"{name}: column oat_k: median {med:.4g} looks like degrees Celsius; "
                              "expected kelvin (K = degC + 273.15)")
    if med > 400:
        raise FlightDataError(f"{name}: column oat_k: median {med:.4g} K is not an air temperature "
                              "(expected 180-330 K)")


def check_units(name, qci, vn, ve, rho):
    """Catch q_ci and GPS speeds in the wrong unit by comparing them with each other.

    The GPS dynamic pressure is the measurement model's q_c with no wind (½ ρ |V_g|²).
    """
    q_med = float(np.median(qci))
    # a glitch cell (1e200) squares to inf here and is named by `check_plausible` after this
    # check; the medians do not need it, so numpy's overflow line would only precede our one
    with np.errstate(over="ignore", invalid="ignore"):
        q_gps = float(np.median(impact_pressure_pa(rho, tas_squared(vn, ve, 0.0, 0.0))))
        gs_med = float(np.median(np.hypot(vn, ve)))
    ratio = q_med / q_gps if q_gps > 0 else np.inf
    if _RATIO_OK[0] <= ratio <= _RATIO_OK[1]:
        if q_med < QCI_MIN_FLYING_PA:
            raise FlightDataError(
                f"{name}: column qc_pa: median q_ci {q_med:.3g} Pa and ground speed "
                f"{gs_med:.3g} m/s: the aircraft is not flying; select the flight with "
                "start_s/end_s")
        return
    # the unit pair that makes q_ci and the GPS dynamic pressure agree best; one wrong column
    # is likelier than two (inHg alone fits as well as inH2O with km/h), so each wrong unit
    # costs a factor 1.22
    best = min(((abs(np.log(ratio * a / b ** 2)) if np.isfinite(ratio) else np.inf, pu, su)
                for pu, a in _PRESSURE_UNITS for su, b in _SPEED_UNITS
                if su == "m/s" or pu not in _ALONE_ONLY),
               key=lambda x: x[0] + _WRONG_UNIT_COST * ((x[1] != "Pa") + (x[2] != "m/s")))
    misfit, p_unit, s_unit = best
    implied = np.sqrt(2.0 * q_med / float(np.median(rho)))
    if misfit < np.log(2.0) and (p_unit, s_unit) != ("Pa", "m/s"):
        parts = []
        if p_unit != "Pa":
            parts.append(f"column qc_pa: median {q_med:.4g} looks like {p_unit} (x "
                         f"{dict(_PRESSURE_UNITS)[p_unit]:g} to Pa), expected Pa")
        if s_unit != "m/s":
            parts.append(f"columns gps_vn_mps/gps_ve_mps: median ground speed {gs_med:.4g} looks "
                         f"like {s_unit} (x {dict(_SPEED_UNITS)[s_unit]:.4g} to m/s), expected "
                         "m/s")
        raise FlightDataError(f"{name}: {'; '.join(parts)} (q_ci / (0.5 rho Vg^2) = "
                              f"{ratio:.3g}, should be near 1)")
    raise FlightDataError(
        f"{name}: columns qc_pa and gps_vn_mps/gps_ve_mps disagree: median q_ci {q_med:.4g} Pa "
        f"implies {implied:.3g} m/s true airspeed but the median ground speed is {gs_med:.3g} "
        "m/s; check their units")


# The time column's unit. A calibration flight is sampled at 0.5-2000 Hz: a median
# step above 2 "s" is a log in milliseconds or microseconds, one below 0.5 ms is a log in
# minutes (50 Hz in minutes is a step of 0.00033; slower logs in minutes overlap real
# 1-2 kHz logs and are told by their climb, `check_vertical_speed`); a first time after
# 1e8 s (1973) is a clock (Unix time), not seconds since the log started.
_TIME_STEP_MAX_S = 2.0
_TIME_STEP_MIN_S = 5e-4
_UNIX_TIME_MIN_S = 1e8


def check_time_units(name, t):
    """Refuse a time column in ms, µs or minutes (naming the unit and the rate it implies); return a
    warning text for Unix time in seconds (used as it is: only time differences matter), or
    None."""
    step = float(np.median(np.diff(t)))
    if step > _TIME_STEP_MAX_S:
        for unit, scale in (("milliseconds", 1e3), ("microseconds", 1e6)):
            if step / scale <= _TIME_STEP_MAX_S:
                clock = " (Unix time)" if t[0] / scale >= _UNIX_TIME_MIN_S else ""
                raise FlightDataError(
                    f"{name}: column time_s: median step {step:.6g} looks like {unit}"
                    f"{clock} ({scale / step:.3g} Hz); expected seconds (time_s = value / "
                    f"{scale:g})")
        raise FlightDataError(f"{name}: column time_s: median step {step:.6g} s between samples; "
                              f"a flight is sampled at least every {_TIME_STEP_MAX_S:g} s")
    if step < _TIME_STEP_MIN_S:
        if 60.0 * step >= _TIME_STEP_MIN_S:
            raise FlightDataError(
                f"{name}: column time_s: median step {step:.3g} looks like minutes "
                f"({1.0 / (60.0 * step):.3g} Hz); expected seconds (time_s = value x 60)")
        raise FlightDataError(f"{name}: column time_s: median step {step:.3g} s between samples "
                              f"({1.0 / step:.3g} Hz); a flight is sampled at most at "
                              f"{1.0 / _TIME_STEP_MIN_S:g} Hz")
    if t[0] >= _UNIX_TIME_MIN_S:
        import datetime

        start = datetime.datetime.fromtimestamp(float(t[0]), datetime.UTC)
        text = (f"{name}: column time_s looks like Unix time in seconds (starts "
                f"{start:%Y-%m-%d %H:%M:%S} UTC); used as seconds (only differences matter)")
        warnings.warn(text, stacklevel=3)
        return text
    return None


# A calibration flight's horizontal acceleration (GPS velocity change over about a second):
# a 45 deg banked turn pulls 1 g; sustained over a tenth of the record, more than 3 g is no
# calibration flight in seconds, while a clock in minutes makes an ordinary turn 60 times that.
_ACCEL_MAX_MPS2 = 3.0 * G0_MPS2
_ACCEL_QUANTILE = 90.0


def check_time_by_acceleration(name, t, vn, ve):
    """Refuse a time column in minutes that the step rule cannot tell (a log at 1-16 Hz
    steps 1-17 ms in minutes, as a 60-1000 Hz log in seconds does), by what the clock makes of
    the GPS velocity: the velocity change over a window of one time unit (a quarter of the
    record when shorter), divided by it, is in a tenth of the record above 3 g, where a 60th
    of it would fly.

    Notes
    -----
    Independent of `alt_m` and `gps_vd_mps` (a level flight has neither signal) and of the
    GPS noise (a 0.1 m/s velocity noise differenced over 1 s is 0.14 m/s^2).
    """
    span = float(t[-1] - t[0])
    # in minutes a log of 1 Hz or more steps 1/60 or less: slower ones are no calibration log
    if t.size < 10 or not span > 0.0 or not float(np.median(np.diff(t))) <= 1.001 / 60.0:
        return
    window = min(1.0, span / 4.0)
    later = t[t <= t[-1] - window]
    if later.size < 5:
        return
    dv = np.hypot(np.interp(later + window, t, vn) - np.interp(later, t, vn),
                  np.interp(later + window, t, ve) - np.interp(later, t, ve))
    accel = float(np.percentile(dv / window, _ACCEL_QUANTILE))
    if accel > _ACCEL_MAX_MPS2 and accel / 60.0 <= _ACCEL_MAX_MPS2:
        raise FlightDataError(
            f"{name}: column time_s looks like minutes: with it in seconds the GPS velocity "
            f"(gps_vn_mps, gps_ve_mps) changes at {accel / G0_MPS2:.3g} g in a tenth of the "
            f"record ({accel / 60.0 / G0_MPS2:.2g} g in minutes); expected seconds "
            "(time_s = value x 60)")


# A calibration is flown near level: the median |vertical speed| of a flight is a few percent
# of its ground speed. More than a quarter (a 14 deg median flight path) is another unit.
_VD_RATIO_MAX = 0.25


def check_vertical_speed(name, vd, vn, ve, t=None, alt=None):
    """Refuse `gps_vd_mps` in cm/s (or in another unit, or not a vertical speed).

    Two tests: its median magnitude against the ground speed, and, with `alt_m`, the
    altitude change against the integrated vertical speed (1 in m/s, 0.01 in cm/s; 60 is a
    time column in minutes, named as such).
    """
    gs = float(np.median(np.hypot(vn, ve)))
    vd_med = float(np.median(np.abs(vd)))
    slope = _altitude_slope(vd, t, alt)
    if vd_med <= _VD_RATIO_MAX * gs and (slope is None or 0.3 <= slope <= 3.0):
        return
    if slope is not None and 30.0 <= slope <= 120.0:       # 60: the clock, not the speed
        raise FlightDataError(f"{name}: column time_s looks like minutes (the altitude changes "
                              f"{slope:.3g} m per metre of the integrated gps_vd_mps; 60 in "
                              "minutes); expected seconds (time_s = value x 60)")
    if slope is not None and 0.003 <= slope <= 0.03 or \
            slope is None and vd_med / 100.0 <= _VD_RATIO_MAX * gs:
        how = (f"the altitude changes {slope:.3g} m per unit of its integral"
               if slope is not None else f"median |vd| {vd_med:.4g} against a median ground "
                                         f"speed {gs:.4g} m/s")
        raise FlightDataError(f"{name}: column gps_vd_mps looks like cm/s ({how}); expected "
                              "m/s, positive down")
    raise FlightDataError(f"{name}: column gps_vd_mps: median |vd| {vd_med:.4g} against a median "
                          f"ground speed {gs:.4g} m/s is not the vertical speed of a calibration "
                          "flight in m/s, positive down")


def _altitude_slope(vd, t, alt):
    """Altitude change per metre of integrated -vd (least squares), or None when the flight
    has no alt_m or too little vertical motion (< 20 m either way) to say."""
    if t is None or alt is None:
        return None
    ok = np.isfinite(alt)
    if ok.sum() < 10:
        return None
    climb = -np.concatenate([[0.0], np.cumsum(0.5 * (vd[1:] + vd[:-1]) * np.diff(t))])
    x, y = climb[ok] - climb[ok].mean(), alt[ok] - alt[ok].mean()
    if np.ptp(y) < 20.0 and np.ptp(x) < 20.0:
        return None
    if x @ x == 0:          # a column of zeros: a logger without vertical speed
        return None
    slope = float(x @ y / (x @ x))
    return slope if np.corrcoef(x, y)[0, 1] ** 2 > 0.8 else None


def looks_utf16(head):
    """True when the bytes `head` are UTF-16 text (a byte-order mark, or ASCII with every
    other byte zero: what Windows tools write as "Unicode")."""
    if head[:2] in (b"\xff\xfe", b"\xfe\xff"):
        return True
    even, odd = head[0:2000:2], head[1:2000:2]
    for text, zeros in ((even, odd), (odd, even)):
        if zeros and zeros.count(0) > 0.9 * len(zeros) and \
                sum(32 <= b < 127 or b in (9, 10, 13) for b in text) > 0.9 * len(text):
            return True
    return False


def implausible_samples(name, t, **columns):
    """Mask of the samples with a finite value outside `PLAUSIBLE` in any of `columns`
    ({column name: array}; None skipped), and the warning naming the first one (or None)."""
    mask = np.zeros(t.size, dtype=bool)
    first = None
    for c, v in columns.items():
        if v is None:
            continue
        v = np.asarray(v, dtype=float)
        off = np.isfinite(v) & ~_plausible(c, v)
        if off.any() and (first is None or np.argmax(off) < first[0]):
            first = (int(np.argmax(off)), c, float(v[np.argmax(off)]))
        mask |= off
    if first is None:
        return mask, None
    i, c, value = first
    lo, hi = PLAUSIBLE[c]
    text = (f"{name}: cut {int(mask.sum())} samples with implausible values (first: {c} "
            f"{value:g} at {t[i]:.2f} s, outside {lo:g} to {hi:g})")
    warnings.warn(text, stacklevel=3)
    return mask, text
