"""The leg CSV of the classic GPS methods (docs/interfaces.md, "Leg data"): `read_legs`.

One row per constant-speed leg, as flight-test engineers hand-enter them::

    # Cessna 172, 2024-05-02 (comment lines start with #)
    point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg
    1,80,3000,9.0,72.4,2.0
    1,80,3000,9.0,91.3,91.0
    1,80,3000,9.0,95.1,181.0

Required: `point` (any label; the legs of one calibration point share it), `ias_kt` (indicated,
instrument-corrected airspeed V_ic) or `qc_pa` (measured impact pressure q_ci), `pressure_alt_ft`
(indicated pressure altitude), `oat_c` or `oat_k` (outside static air temperature),
`groundspeed_kt` and `track_deg` (the leg's GPS ground speed and true track). In place of the
static OAT, `tat_c` or `tat_k`: the indicated total temperature a probe reads (an aircraft's OAT
gauge reads the air heated by the ram rise), converted as T_s = T_t / (1 + r 0.2 M²) with the
probe's recovery factor r (`temp_recovery`, default 1: a total-temperature probe; a bare OAT
gauge probe is nearer 0.7-0.9) and M the leg's Mach: `oat_k` at the indicated Mach (q_ci at the
pressure altitude), `LegData.static_oat_k` at the true one, which the solutions use (3 % of
position error moves the temperature by 0.04 K at 100 KIAS, 3,000 ft, 0.35 K at 250 KIAS,
10,000 ft). Optional:
`duration_s` (the leg's length in time) and `groundspeed_sd_kt` (the standard uncertainty of the
leg's ground velocity, per component, kt). Extra columns are ignored.

Every problem is a `FlightDataError` naming file, column and row (``legs.csv: column oat_c,
row 4 (line 6): 290 is not an outside air temperature in degC (looks like kelvin)``); rows count
data rows from 1, lines are the file's. Nothing is dropped: hand-entered data are few, and a bad
cell is a typo to fix. The file is opened read-only.
"""

import csv
import io
from dataclasses import dataclass

import numpy as np

from pitotcal.core import airdata
from pitotcal.core.errors import FlightDataError
from pitotcal.core.moist_air import total_temperature_ratio
from pitotcal.core.units import FT_TO_M, KT_TO_MPS
from .atomic import atomic_open
from .read_once import naming, open_binary, read_once

__all__ = ["DEFAULT_TEMP_RECOVERY", "LEG_COLUMNS", "LegData", "read_legs", "write_legs"]

# The columns a leg file needs (either of each pair in `_ALTERNATIVES`).
LEG_COLUMNS = ("point", "ias_kt", "pressure_alt_ft", "oat_c", "groundspeed_kt", "track_deg")
_ALTERNATIVES = {"ias_kt": ("qc_pa",), "oat_c": ("oat_k", "tat_c", "tat_k")}
DEFAULT_TEMP_RECOVERY = 1.0
_OPTIONAL = ("duration_s", "groundspeed_sd_kt")
# Plausible ranges of the hand-entered numbers (the hint says which unit a value looks like).
_RANGES = {
    "ias_kt": (10.0, 600.0, ""),
    "qc_pa": (50.0, 0.89 * airdata.P0_PA, " (hPa or kPa? give pascals)"),
    "pressure_alt_ft": (-2000.0, 104987.0, " (the ISA, -2,000 ft to 32 km, 104,987 ft)"),
    "oat_c": (-90.0, 60.0, ""),
    "oat_k": (180.0, 330.0, ""),
    "tat_c": (-90.0, 100.0, ""),
    "tat_k": (180.0, 375.0, ""),
    "groundspeed_kt": (1.0, 700.0, ""),
    "track_deg": (0.0, 360.0, ""),
    "duration_s": (0.0, 3600.0, ""),
    "groundspeed_sd_kt": (0.0, 50.0, ""),
}
# ... of which zero is not a value either
_POSITIVE = ("groundspeed_sd_kt",)


@dataclass(frozen=True)
class LegData:
    """Legs of the classic GPS methods, SI inside (one entry per leg, in file order).

    Attributes
    ----------
    point : tuple of str
        Calibration-point label of each leg.
    ias_kt : ndarray
        Indicated (instrument-corrected) airspeed V_ic, kt (from `qc_pa` by the CAS law when the
        file gives impact pressure).
    qci_pa : ndarray
        Measured impact pressure q_ci, Pa (from `ias_kt` by the CAS law when not given).
    pressure_alt_m : ndarray
        Indicated pressure altitude H_ic, m.
    oat_k : ndarray
        Outside static air temperature, K (from the total temperature when the file gives it).
    groundspeed_mps, track_deg : ndarray
        The leg's GPS ground speed, m/s, and true track, deg.
    duration_s : ndarray
        Leg duration, s (NaN where not given).
    groundspeed_sd_mps : ndarray
        Standard uncertainty of the leg's ground velocity per component, m/s (NaN where not
        given).
    source : str
    lines : tuple of int
        The file line of each leg, for messages.
    sd_from : {"stated", "samples"}
        Where `groundspeed_sd_mps` comes from: the leg file states it, or the legs' own GPS
        samples (`estimation.legs.flight`) estimate it. The bounds are labelled with it.
    temperature : str
        Where `oat_k` comes from: "oat_c", "oat_k", or the total-temperature column with its
        recovery factor ("tat_c, recovery factor 0.8").
    tat_k : ndarray or None
        The indicated total temperature, K, when the file gives it (`oat_k` is then its static
        temperature at the indicated Mach; `static_oat_k` at the true one).
    temp_recovery : float
        The probe's recovery factor of `tat_k`.
    """

    point: tuple
    ias_kt: np.ndarray
    qci_pa: np.ndarray
    pressure_alt_m: np.ndarray
    oat_k: np.ndarray
    groundspeed_mps: np.ndarray
    track_deg: np.ndarray
    duration_s: np.ndarray
    groundspeed_sd_mps: np.ndarray
    source: str = ""
    lines: tuple = ()
    sd_from: str = "stated"
    temperature: str = "oat_c"
    tat_k: np.ndarray | None = None
    temp_recovery: float = DEFAULT_TEMP_RECOVERY

    @property
    def n(self):
        return len(self.point)

    def points(self):
        """The point labels in order of first appearance."""
        return tuple(dict.fromkeys(self.point))

    def indices(self, label):
        """Indices of the legs of point `label`."""
        return np.array([i for i, p in enumerate(self.point) if p == label], dtype=int)

    def static_oat_k(self, qc_pa=None, idx=None):
        """Static OAT of the legs `idx` (all: None), K: `oat_k`; from `tat_k` with the true
        Mach of impact pressure `qc_pa` when given (the position error in the static source:
        p_s = p_s,ind + q_ci − q_c), T_s = T_t / (1 + r 0.2 M²)."""
        from pitotcal.core.moist_air import static_temperature_k

        sel = slice(None) if idx is None else idx
        if self.tat_k is None or qc_pa is None:
            return self.oat_k[sel]
        qci = self.qci_pa[sel]
        ps = airdata.static_pressure_pa(self.pressure_alt_m[sel]) + qci - qc_pa
        return static_temperature_k(self.tat_k[sel], qc_pa, ps, self.temp_recovery)

    def velocity_ne_mps(self):
        """Ground velocity (north, east), m/s, shape (n, 2)."""
        t = np.radians(self.track_deg)
        return np.column_stack([self.groundspeed_mps * np.cos(t), self.groundspeed_mps * np.sin(t)])

    def where(self, i):
        """'point P (line L)' of leg `i`, for messages."""
        return f"point {self.point[i]} (line {self.lines[i]})" if self.lines else f"point {self.point[i]}"


def read_legs(path, temp_recovery=DEFAULT_TEMP_RECOVERY):
    """Read a leg CSV (module docstring) into a `LegData`.

    Parameters
    ----------
    path : str or path-like
    temp_recovery : float
        Recovery factor of the probe of a `tat_c` / `tat_k` column, 0-1 (module docstring).

    Raises
    ------
    FlightDataError
        Unusable file, missing column, bad cell or implausible unit; one line naming file,
        column and row.
    """
    from pitotcal.core.checks import number

    temp_recovery = number("temp_recovery", temp_recovery, 0.0, 1.0)
    with naming(path):
        path = read_once(path)          # "-", a FIFO or a pipe: read whole once
        name = str(path)
        header, rows, lines = _read_rows(path, name)
    cols = _choose_columns(header, name)
    values = {c: _column(c, header, rows, lines, name) for c in cols if c != "point"}
    for c in _OPTIONAL:
        values[c] = (_column(c, header, rows, lines, name, optional=True) if c in header
                     else np.full(len(rows), np.nan))
    labels = tuple(row[header.index("point")].strip() for row in rows)
    for r, label in enumerate(labels):
        if not label:
            raise FlightDataError(f"{name}: column point, row {r + 1} (line {lines[r]}): empty")
    if "qc_pa" in values:
        qci = values["qc_pa"]
        ias_kt = airdata.cas_from_qc_mps(qci) / KT_TO_MPS
    else:
        ias_kt = values["ias_kt"]
        qci = airdata.qc_from_cas_pa(ias_kt * KT_TO_MPS)
    column = next(c for c in ("oat_k", "oat_c", "tat_k", "tat_c") if c in values)
    kelvin = values[column] + (273.15 if column.endswith("_c") else 0.0)
    alt_m = values["pressure_alt_ft"] * FT_TO_M
    temperature, tat_k = column, None
    if column.startswith("tat"):
        mach = airdata.mach_from_qc(qci, airdata.static_pressure_pa(alt_m))
        tat_k, kelvin = kelvin, kelvin / total_temperature_ratio(mach, temp_recovery)
        temperature = f"{column}, recovery factor {temp_recovery:g}"
    legs = LegData(point=labels, ias_kt=ias_kt, qci_pa=qci, pressure_alt_m=alt_m, oat_k=kelvin,
                   groundspeed_mps=values["groundspeed_kt"] * KT_TO_MPS,
                   track_deg=values["track_deg"] % 360.0, duration_s=values["duration_s"],
                   groundspeed_sd_mps=values["groundspeed_sd_kt"] * KT_TO_MPS,
                   source=name, lines=tuple(lines), temperature=temperature, tat_k=tat_k,
                   temp_recovery=temp_recovery)
    _check_speed_units(legs, values, lines, name)
    _check_track_unit(values["track_deg"], name)
    return legs


def write_legs(legs, path, comments=()):
    """Write `legs` as a leg CSV (ias_kt, oat_c; the optional columns where any leg has them)."""
    cols = list(LEG_COLUMNS)
    extra = {"duration_s": legs.duration_s,
             "groundspeed_sd_kt": legs.groundspeed_sd_mps / KT_TO_MPS}
    cols += [c for c, v in extra.items() if np.any(np.isfinite(v))]
    with atomic_open(path, "w", newline="", encoding="utf-8") as f:
        f.writelines(f"# {line}\n" for line in comments)
        w = csv.writer(f, lineterminator="\n")
        w.writerow(cols)
        for i in range(legs.n):
            row = [legs.point[i], f"{legs.ias_kt[i]:.2f}",
                   f"{legs.pressure_alt_m[i] / FT_TO_M:.0f}", f"{legs.oat_k[i] - 273.15:.2f}",
                   f"{legs.groundspeed_mps[i] / KT_TO_MPS:.3f}", f"{legs.track_deg[i]:.2f}"]
            row += ["" if not np.isfinite(extra[c][i]) else f"{extra[c][i]:.3f}"
                    for c in cols[len(LEG_COLUMNS):]]
            w.writerow(row)


def _not_text(path):
    """Why a file that is no UTF-8 is not read: UTF-16 named as such, else binary."""
    from .flight_checks import looks_utf16

    with open_binary(path) as f:
        head = f.read(4096)
    return ("UTF-16 text (save it as UTF-8: a CSV here is UTF-8 or ASCII)" if looks_utf16(head)
            else "not a text CSV (binary data)")


def _read_rows(path, name):
    """(header, data rows, file line of each row); comment and blank lines skipped."""
    with io.TextIOWrapper(open_binary(path), newline="", encoding="utf-8-sig") as f:
        try:
            text = f.read()
        except UnicodeDecodeError:
            raise FlightDataError(f"{name}: {_not_text(path)}") from None
    header, rows, lines = None, [], []
    for number, row in enumerate(csv.reader(text.splitlines()), start=1):
        if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
            continue
        if header is None:
            header = [c.strip() for c in row]
        else:
            rows.append(row)
            lines.append(number)
    if header is None:
        raise FlightDataError(f"{name}: no header line (columns {', '.join(LEG_COLUMNS)})")
    if not rows:
        raise FlightDataError(f"{name}: header only, no legs")
    return header, rows, lines


def _choose_columns(header, name):
    """The columns to use: each required one, or its alternative; all missing ones named."""
    use, missing = [], []
    for c in LEG_COLUMNS:
        alts = _ALTERNATIVES.get(c, ())
        found = next((a for a in (c, *alts) if a in header), None)
        if found:
            use.append(found)
        else:
            missing.append(f"{c} (or {' or '.join(alts)})" if alts else c)
    if missing:
        raise FlightDataError(f"{name}: missing column {', '.join(missing)}; a leg file has "
                              f"{', '.join(LEG_COLUMNS)}")
    return use


def _column(col, header, rows, lines, name, optional=False):
    """Column `col` as floats, each checked against its plausible range; NaN for an empty
    optional cell."""
    j = header.index(col)
    lo, hi, hint = _RANGES[col]
    out = np.empty(len(rows))
    for r, row in enumerate(rows):
        where = f"{name}: column {col}, row {r + 1} (line {lines[r]})"
        cell = row[j].strip() if j < len(row) else ""
        if optional and cell == "":
            out[r] = np.nan
            continue
        try:
            x = float(cell)
        except ValueError:
            raise FlightDataError(f"{where}: {cell!r} is not a number" if cell
                                  else f"{where}: empty") from None
        if not np.isfinite(x):
            raise FlightDataError(f"{where}: {cell} is not a finite number")
        if not lo <= x <= hi:
            raise FlightDataError(f"{where}: {x:g} is outside {lo:g} to {hi:g}"
                                  f"{hint or _unit_hint(col, x)}")
        if col in _POSITIVE and x == 0.0:
            raise FlightDataError(f"{where}: 0 is no accuracy (the legs would weigh "
                                  "infinitely); give the GPS's, or leave the cell empty")
        out[r] = x
    return out


def _unit_hint(col, x):
    if col == "oat_c" and 180.0 <= x <= 330.0:
        return " (looks like kelvin: give degC, or name the column oat_k)"
    if col == "oat_k" and -90.0 <= x <= 60.0:
        return " (looks like degC: give kelvin, or name the column oat_c)"
    if col == "tat_c" and 180.0 <= x <= 375.0:
        return " (looks like kelvin: give degC, or name the column tat_k)"
    if col == "tat_k" and -90.0 <= x <= 100.0:
        return " (looks like degC: give kelvin, or name the column tat_c)"
    return ""


def _check_track_unit(track, name):
    """Refuse tracks in radians: spread over more than 1 yet all within 0-2 pi, they are legs
    flown within 6.3 deg of one another in degrees, which no leg method can use."""
    if track.size >= 3 and np.ptp(track) >= 1.0 and track.min() >= 0.0 \
            and track.max() <= 2.0 * np.pi:
        raise FlightDataError(
            f"{name}: column track_deg: every track lies within {track.min():.3g}-"
            f"{track.max():.3g}, as radians would (x 57.2958 to degrees); legs within 6.3 "
            "degrees of one another cannot separate the wind")


def _check_speed_units(legs, values, lines, name):
    """Ground speed against an estimate of true airspeed (IAS, pressure altitude, OAT): with
    any wind a calibration flies in (< ~40 % of TAS) their ratio lies in 0.6-1.6; km/h gives
    ~1.85, m/s ~0.51 (judged on the median: all legs, not one)."""
    ps = airdata.static_pressure_pa(legs.pressure_alt_m)
    mach = airdata.mach_from_qc(legs.qci_pa, ps)
    tas = mach * airdata.speed_of_sound_mps(legs.oat_k)
    ratio = float(np.median(legs.groundspeed_mps / tas))
    if not 0.6 <= ratio <= 1.6:
        col = "qc_pa" if "qc_pa" in values else "ias_kt"
        guess = {"km/h": 1.852, "m/s": KT_TO_MPS}
        unit = min(guess, key=lambda u: abs(np.log(ratio / guess[u])))
        raise FlightDataError(
            f"{name}: column groundspeed_kt: median ground speed is {ratio:.2f} x the true "
            f"airspeed from {col}, pressure_alt_ft and the OAT (expected 0.6-1.6); are the "
            f"ground speeds in {unit}, or {col} in the wrong unit?")
