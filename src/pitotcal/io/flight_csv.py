"""The flight CSV (docs/interfaces.md): `read_flight_csv` and `write_flight_csv`.

This module parses; `pitotcal.io.flight_checks` holds the checks of what it parsed (window,
unusable rows, time order, units).

Where a problem is
    Every problem is a `FlightDataError` with a one-line message naming the file, the column and
    the row, e.g. ``flight.csv: column qc_pa, row 1040 (line 1043): NaN``. *row* counts data rows
    from 1 (the first line after the header is row 1; blank lines are not rows); *line* is the
    line number in the file, what a person opens in an editor. Both are given because comment
    lines before the header make them differ.

What is rejected and what is dropped
    Rejected (the whole file is unusable; a flight-test engineer must look):

    - not a text CSV: empty file, binary file (a ULog or DataFlash log with a wrong extension is
      named as such), only comments, no header (the first line holds numbers), no commas,
      header only without data rows, fewer than `MIN_ROWS` usable rows;
    - a missing required column (all missing ones are named, with a near-miss spelling if one
      exists); density needs `rho_kgm3`, or both `ps_pa` and `oat_k`; a plan CSV (the
      columns of `pitotcal plan`) is named as a plan to fly or simulate first;
    - time not strictly increasing: a duplicated time or a step backwards (naming the row);
    - more than `MAX_BAD_FRACTION` (1 %) of the rows unusable (below), naming the first one:
      that is a bad column or a bad logger, not a glitch;
    - a unit that is wrong for the whole column, judged on medians so a few outliers cannot
      trigger it: `q_ci` in hPa / kPa / psi / inH2O, GPS speeds in knots / km/h / cm/s (both
      found by comparing q_ci with the GPS dynamic pressure 0.5 rho |V_g|^2, which agree
      within the wind's effect, a factor ~0.35-4, for a flying aircraft: knots make the ratio
      0.26, hPa 0.01), `ps_pa` in hPa or kPa, `oat_k` in degrees Celsius (< 150 K),
      `rho_kgm3` outside 0.15-1.6 kg/m^3 (g/m^3 is named), and an aircraft that is not
      flying (median q_ci < 20 Pa, about 11 kt, the low end of anything that flies).

    Dropped with ONE warning naming the count and the first one (a few glitches in 16,000
    samples should not stop anybody): rows where a used column is non-numeric, empty, missing
    (short row), NaN or infinite, where `qc_pa` <= 0, or where `rho_kgm3`, `ps_pa` or `oat_k`
    is <= 0, as long as they are at most 1 % of the rows (counted inside the time window).
    The count is kept in `Flight.n_dropped` and the warning in `Flight.warnings`. The
    informative column `alt_m` (never used in the fit) is exempt: an empty, non-numeric or NaN
    altitude is NaN in `Flight.alt_m` and the row is kept.

    Valid as they are: gaps in time, extra columns (ignored), blank lines, `#` comment lines
    before the header (``# key: value`` goes to `Flight.meta`), Windows line ends, a UTF-8 BOM.

The input file is opened read-only and never modified. Parsing is one C-level `np.loadtxt`
pass over the used columns (about 1 s per 10^6 rows here); only a file with non-numeric cells
takes a slower per-column Python pass to find and name them.
"""

import difflib
import io
import re
import warnings

import numpy as np

from pitotcal.core.errors import FlightDataError
from pitotcal.core.flight import Flight
from pitotcal.core.moist_air import check_air_options, with_static_air
from pitotcal.core.plan import PLAN_COLUMNS
from pitotcal.core.units import ISA_T0_K, density_kgm3

from .atomic import atomic_open
from .read_once import naming, open_binary, read_once
from .flight_checks import (
    check_plausible,
    check_ps_oat,
    check_rho,
    check_time,
    check_time_by_acceleration,
    check_time_units,
    check_units,
    check_vertical_speed,
    check_window,
    drop_bad_rows,
    looks_utf16,
    window_text,
)

__all__ = ["PLAN_NOT_FLIGHT", "csv_kind", "read_flight_csv", "write_flight_csv"]

PLAN_NOT_FLIGHT = ("this is a plan (the columns of pitotcal plan), not a flight: fly or simulate "
                   "it first (pitotcal simulate PLAN.csv -o FLIGHT.csv)")


def write_flight_csv(flight, path, comments=None):
    """Write `flight` as a flight CSV (docs/interfaces.md §1): `# key: value` lines, header, rows;
    the columns WRITTEN_COLUMNS, then those of WRITTEN_IF_PRESENT the flight has."""
    optional = [name for name in WRITTEN_IF_PRESENT if getattr(flight, name) is not None]
    columns = [*WRITTEN_COLUMNS, *optional]
    data = [flight.time_s, flight.qci_pa, flight.gps_vn_mps, flight.gps_ve_mps, flight.rho_kgm3,
            *(getattr(flight, name) for name in optional)]
    meta = {**flight.meta, **(comments or {})}
    header = "".join(f"# {key}: {value}\n" for key, value in meta.items()) + ",".join(columns)
    with atomic_open(path, "w") as fh:          # whole or not at all: never a spliced file
        np.savetxt(fh, np.column_stack(data), delimiter=",", header=header, comments="",
                   fmt=["%.4f"] + ["%.9g"] * (len(columns) - 1))
    return path


# --- reading and validation -------------------------------------------------------------

REQUIRED_COLUMNS = ("time_s", "qc_pa", "gps_vn_mps", "gps_ve_mps")
OPTIONAL_COLUMNS = ("gps_vd_mps", "alt_m", "ps_ref_pa")
# Static pressure (the static source's reading) and temperature: density when rho_kgm3 is
# absent, and the compressible calibration's air data whenever both are present.
STATIC_COLUMNS = ("ps_pa", "oat_k")
# total air temperature and humidity, converted by core.moist_air
TEMPERATURE_COLUMNS = ("tat_k", "rh_pct")
# The columns `write_flight_csv` writes, in order (the optional ones: Flight fields it has)
WRITTEN_COLUMNS = (*REQUIRED_COLUMNS, "rho_kgm3")
WRITTEN_IF_PRESENT = ("gps_vd_mps", "alt_m", *STATIC_COLUMNS, "ps_ref_pa", *TEMPERATURE_COLUMNS)
MIN_ROWS = 10


def read_flight_csv(path, start_s=None, end_s=None, *, temp_recovery=1.0, rh_pct=None):
    """Read and validate a flight CSV (docs/interfaces.md §1); see `read_flight` and the module notes.

    Parameters
    ----------
    path : str or path-like
    start_s, end_s, temp_recovery, rh_pct : float, optional
        Time window, s; the air data's options (`read_flight`).

    Returns
    -------
    Flight
        SI arrays; `meta` from the ``# key: value`` lines; `n_dropped` rows dropped with a
        warning; `source` is `path` as given.
    """
    (start_s, end_s), air = check_window(start_s, end_s), check_air_options(temp_recovery, rh_pct)
    path = read_once(path)          # "-", a FIFO or a pipe: read whole once, parsed from memory
    name = str(path)
    _reject_binary(path, name)
    header_line, columns, meta = _read_header(path, name)
    use = _used_columns(name, columns)
    table = _parse_body(path, name, header_line, columns, use)
    if table.data.shape[0] == 0:
        raise FlightDataError(f"{name}: header only, no data rows after line {header_line}")

    col = {c: j for j, c in enumerate(use)}
    data, rows = _window(name, table, col["time_s"], start_s, end_s)
    data, rows, n_dropped, warning = drop_bad_rows(name, table, data, rows, use)
    time_s = data[:, col["time_s"]]
    check_time(name, table, time_s, rows)
    if time_s.size < MIN_ROWS:
        raise FlightDataError(f"{name}: only {time_s.size} usable data rows, at least {MIN_ROWS} "
                              "needed")

    qci = data[:, col["qc_pa"]]
    vn, ve = data[:, col["gps_vn_mps"]], data[:, col["gps_ve_mps"]]
    alt = data[:, col["alt_m"]] if "alt_m" in col else None
    if "ps_pa" in col and "oat_k" in col:
        check_ps_oat(name, data[:, col["ps_pa"]], data[:, col["oat_k"]], alt=alt,
                     rho=data[:, col["rho_kgm3"]] if "rho_kgm3" in col else None)
    if "rho_kgm3" in col:
        rho = data[:, col["rho_kgm3"]]
        check_rho(name, rho)
    else:
        temperature = data[:, col["oat_k" if "oat_k" in col else "tat_k"]]
        if "oat_k" not in col:              # total temperature: with_static_air converts it
            check_ps_oat(name, data[:, col["ps_pa"]], temperature, alt=alt)
        rho = density_kgm3(data[:, col["ps_pa"]], temperature)
    check_units(name, qci, vn, ve, rho)
    # no implausible cell left, the units of time and of the vertical speed
    check_plausible(name, table, data, rows, use)
    clock = check_time_units(name, time_s)
    if "gps_vd_mps" in col:
        check_vertical_speed(name, data[:, col["gps_vd_mps"]], vn, ve, time_s,
                             data[:, col["alt_m"]] if "alt_m" in col else None)
    check_time_by_acceleration(name, time_s, vn, ve)     # level flight: no climb to tell
    if "ps_ref_pa" in col:
        check_ps_oat(name, data[:, col["ps_ref_pa"]], np.full(1, ISA_T0_K), column="ps_ref_pa",
                     alt=alt)
    optional = {c: (np.ascontiguousarray(data[:, col[c]]) if c in col else None)
                for c in (*OPTIONAL_COLUMNS, *STATIC_COLUMNS, *TEMPERATURE_COLUMNS)}
    flight = Flight(time_s=np.ascontiguousarray(time_s), qci_pa=np.ascontiguousarray(qci),
                    gps_vn_mps=np.ascontiguousarray(vn), gps_ve_mps=np.ascontiguousarray(ve),
                    rho_kgm3=np.ascontiguousarray(rho, dtype=float), source=name, meta=meta,
                    n_dropped=n_dropped, warnings=tuple(w for w in (warning, clock) if w),
                    **optional)
    return with_static_air(flight, temp_recovery=air[0], rh_pct=air[1])


def csv_kind(path):
    """"flight" or "plan" for a text CSV whose header has those columns, else None.

    Looks only at the header (after any ``#`` lines); never raises for a file it can open.
    """
    with naming(path):
        return _csv_kind(read_once(path))


def _csv_kind(path):
    name = str(path)
    try:
        _reject_binary(path, name)
        _, columns, _ = _read_header(path, name)
    except FlightDataError:
        return None
    present = set(columns)
    if present.issuperset(REQUIRED_COLUMNS):
        return "flight"
    return "plan" if present.issuperset(PLAN_COLUMNS) else None


class _Table:
    """The parsed body: `data` (rows x used columns) plus what is needed to name a row."""

    def __init__(self, path, header_line, data, bad=None, lines=None):
        self.path = path
        self.header_line = header_line
        self.data = data
        self.bad = bad or {}          # parsed row index -> (column, problem) for unparsable cells
        self._lines = lines           # parsed row index -> file line; None: computed on demand

    def where(self, r):
        """'row R (line L)' of parsed row index `r` (0-based)."""
        if self._lines is None:
            self._lines = _data_line_numbers(self.path, self.header_line)
        line = self._lines[r] if r < len(self._lines) else self.header_line + 1 + r
        return f"row {r + 1} (line {line})"


def _reject_binary(path, name):
    with open_binary(path) as f:
        head = f.read(65536)
    if not head.strip():
        raise FlightDataError(f"{name}: empty file, not a flight CSV")
    if b"\0" in head:
        kind = "binary file"
        if head.startswith(b"ULog"):
            kind = "PX4 ULog file (name it .ulg to read it as a log)"
        elif head[:2] == b"\xa3\x95":
            kind = "ArduPilot DataFlash log (name it .bin to read it as a log)"
        elif looks_utf16(head):
            kind = "UTF-16 text (save it as UTF-8: a flight CSV is UTF-8 or ASCII)"
        raise FlightDataError(f"{name}: {kind}, not a flight CSV")


def _text(path):
    # utf-8-sig drops a BOM; undecodable bytes become U+FFFD and then fail as non-numeric
    # cells or unknown column names, with a row to point at, rather than a decode error.
    return io.TextIOWrapper(open_binary(path), encoding="utf-8-sig", errors="replace",
                            newline=None)


def _read_header(path, name):
    """(header line number, column names, meta) from the lines before the data."""
    meta = {}
    with _text(path) as f:
        for line_no, line in enumerate(f, start=1):
            text = line.strip()
            if not text:
                continue
            if text.startswith("#"):
                key, sep, value = text[1:].partition(":")
                if sep and key.strip():
                    meta[key.strip()] = value.strip()
                continue
            break
        else:
            raise FlightDataError(f"{name}: only comment lines, no header row and no data")
    columns = [c.strip().strip('"').strip("'").strip() for c in text.split(",")]
    if len(columns) == 1:
        for sep, label in ((";", "semicolons"), ("\t", "tabs")):
            if sep in text:
                raise FlightDataError(f"{name}: line {line_no}: fields are separated by {label}; "
                                      "a flight CSV uses commas")
        raise FlightDataError(f"{name}: line {line_no}: not a CSV header (no commas); expected "
                              f"columns {', '.join(REQUIRED_COLUMNS)}, ...")
    if all(_is_number(c) for c in columns if c):
        raise FlightDataError(f"{name}: line {line_no}: no header row (the first line holds "
                              f"numbers); expected column names {', '.join(REQUIRED_COLUMNS)}, ...")
    if not set(columns) & set(REQUIRED_COLUMNS) and not all(map(_NAME.match, columns)):
        raise FlightDataError(f"{name}: line {line_no}: not a CSV header; expected columns "
                              f"{', '.join(REQUIRED_COLUMNS)}, ...")
    return line_no, columns, meta


_NAME = re.compile(r"^[A-Za-z_][\w .()/%\[\]-]*$")


def _is_number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


def _used_columns(name, columns):
    """Names of the columns read, in order: required, density, optional present."""
    present = set(columns)
    missing = [c for c in REQUIRED_COLUMNS if c not in present]
    if missing and present.issuperset(PLAN_COLUMNS):
        raise FlightDataError(f"{name}: {PLAN_NOT_FLIGHT}")
    if missing:
        hints = []
        for c in missing:
            close = difflib.get_close_matches(c, columns, n=1, cutoff=0.6)
            close = close or [x for x in columns if x.lower() == c.lower()]
            if close:
                hints.append(f"{c} (found {close[0]!r})")
            else:
                hints.append(c)
        raise FlightDataError(f"{name}: missing column{'s' if len(missing) > 1 else ''} "
                              f"{', '.join(hints)}; required: {', '.join(REQUIRED_COLUMNS)} "
                              "and density (rho_kgm3, or both ps_pa and oat_k)")
    static = ["ps_pa", "oat_k"] if {"ps_pa", "oat_k"} <= present else []
    if "rho_kgm3" in present:
        density = ["rho_kgm3"] + static
    elif static:
        density = static
    elif "ps_pa" in present and "tat_k" in present:      # total temperature
        density = ["ps_pa", "tat_k"]
    else:
        found = [c for c in ("ps_pa", "oat_k") if c in present]
        also = f" (found only {found[0]})" if found else ""
        raise FlightDataError(f"{name}: missing column for density: needs rho_kgm3, or both "
                              f"ps_pa and oat_k{also}")
    use = list(REQUIRED_COLUMNS) + density + [c for c in OPTIONAL_COLUMNS if c in present]
    if present & set(TEMPERATURE_COLUMNS):      # and what converting them needs
        use += [c for c in ("ps_pa", *TEMPERATURE_COLUMNS) if c in present and c not in use]
    for c in use:
        if columns.count(c) > 1:
            raise FlightDataError(f"{name}: column {c} appears {columns.count(c)} times in the "
                                  "header")
    return use


def _parse_body(path, name, header_line, columns, use):
    """Parse the used columns; fast C path, or a slower pass that names unparsable cells."""
    index = [columns.index(c) for c in use]
    with _text(path) as f:
        for _ in range(header_line):
            f.readline()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")      # "input contained no data": we say it better
                data = np.loadtxt(f, delimiter=",", usecols=index, ndmin=2, comments=None,
                                  dtype=float)
            return _Table(path, header_line, data.reshape(-1, len(use)))
        except ValueError:
            pass
    return _parse_slow(path, header_line, columns, use, index)


def _parse_slow(path, header_line, columns, use, index):
    """Blocks of rows through np.loadtxt; only a block that fails is parsed cell by cell."""
    with _text(path) as f:
        lines = f.read().splitlines()[header_line:]
    # blank lines are skipped as np.loadtxt does; a '#' line inside the data is a bad row
    line_no = [header_line + 1 + k for k, line in enumerate(lines) if line.strip()]
    lines = [lines[k - header_line - 1] for k in line_no]
    data = np.full((len(lines), len(use)), np.nan)
    bad = {}
    for lo in range(0, len(lines), _BLOCK_ROWS):
        block = lines[lo:lo + _BLOCK_ROWS]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                data[lo:lo + len(block)] = np.loadtxt(block, delimiter=",", usecols=index,
                                                      ndmin=2, comments=None, dtype=float)
        except ValueError:
            _parse_cells(block, lo, len(columns), use, index, data, bad)
    return _Table(path, header_line, data, bad, np.array(line_no))


_BLOCK_ROWS = 10000


def _parse_cells(block, lo, width, use, index, data, bad):
    """Cell-by-cell parse of rows lo.. (a block with a bad cell); first problem per row."""
    for k, line in enumerate(block):
        fields = line.split(",")
        r = lo + k
        for j, (c, i) in enumerate(zip(use, index)):
            if i >= len(fields):
                bad.setdefault(r, (c, f"short row ({len(fields)} fields, header has {width})"))
                continue
            cell = fields[i].strip()
            try:
                data[r, j] = float(cell)
            except ValueError:
                problem = f"non-numeric value {cell[:20]!r}" if cell else "empty cell"
                bad.setdefault(r, (c, problem))


def _data_line_numbers(path, header_line):
    """File line number of each data row (blank lines are not rows)."""
    with _text(path) as f:
        lines = f.read().splitlines()[header_line:]
    return np.array([header_line + 1 + k for k, line in enumerate(lines) if line.strip()])


def _window(name, table, jt, start_s, end_s):
    """Rows (and their parsed indices) from the first to the last inside the time window."""
    data = table.data
    rows = np.arange(data.shape[0])
    if start_s is None and end_s is None:
        return data, rows
    t = data[:, jt]
    lo = -np.inf if start_s is None else start_s
    hi = np.inf if end_s is None else end_s
    inside = np.flatnonzero(np.isfinite(t) & (t >= lo) & (t <= hi))
    if inside.size == 0:
        finite = t[np.isfinite(t)]
        span = f"{finite.min():g} to {finite.max():g} s" if finite.size else "no valid times"
        raise FlightDataError(f"{name}: column time_s: no rows in the window "
                              f"{window_text(start_s, end_s)} (the file spans {span})")
    # the positional range keeps NaN-time rows between in-window rows, so they are counted
    sl = slice(inside[0], inside[-1] + 1)
    return data[sl], rows[sl]
