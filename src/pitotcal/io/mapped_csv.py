"""A flight-test engineer's own CSV export, read through a column mapping (docs/interfaces.md §1b).

A small TOML file says which column of the export is which quantity and in what unit::

    time              = { column = "time_s",          unit = "s" }
    gps_vn            = { column = "north_vel_fps",   unit = "ft/s" }
    gps_ve            = { column = "east_vel_fps",    unit = "ft/s" }
    gps_vd            = { column = "down_vel_fps",    unit = "ft/s" }
    total_pressure    = { column = "total_pres_psi",  unit = "psi" }
    static_pressure   = { column = "static_pres_psi", unit = "psi" }
    total_temperature = { column = "total_temp_K",    unit = "K" }
    gps_height        = { column = "height_ft",       unit = "ft" }

`read_mapped_csv` converts the mapped columns to SI (the unit tables of `pitotcal.core.units`),
forms the impact pressure q_ci = p_t − p_s from a total pressure, and hands the result to the
flight-CSV reader, so every check of a flight CSV (units, time order, bad rows) applies; a
message about a flight column also names the export's column it came from. The attitude keys
(`roll`, `pitch`, `true_heading`, `sideslip`; rad or deg) are not flight columns: `read_attitude`
reads them for the self-survey's vector airspeed.

Every sample the pitot relations take is read, through Mach 1: above it the Rayleigh (normal
shock) relation of `pitotcal.core.airdata` holds, so `MACH_IC_MAX` is the relations' own
`MACH_MAX`. A caller may still leave out the samples whose measured pressures give a Mach
number above `mach_ic_max` (one warning; `Flight.meta["excluded_supersonic"]` counts them).
"""

import dataclasses
import difflib
import io
import re
import tomllib
import warnings

import numpy as np

from pitotcal.core.airdata import MACH_MAX, qc_from_mach_pa
from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.core.units import (M_PER_UNIT, MPS_PER_UNIT, PA_PER_UNIT, RAD_PER_UNIT,
                                 S_PER_UNIT, TEMPERATURE_UNITS)

from .flight_csv import read_flight_csv
from .read_once import InputBytes, open_binary, read_once

__all__ = ["ATTITUDE_KEYS", "MACH_IC_MAX", "MAPPING_KEYS", "SUPERSONIC_NOTE", "mapped_attitude",
           "read_attitude",
           "read_column_map", "read_mapped_csv"]

# mapping key -> (flight CSV column, unit table, what it is)
MAPPING_KEYS = {
    "time": ("time_s", S_PER_UNIT, "time"),
    "gps_vn": ("gps_vn_mps", MPS_PER_UNIT, "GPS velocity north"),
    "gps_ve": ("gps_ve_mps", MPS_PER_UNIT, "GPS velocity east"),
    "gps_vd": ("gps_vd_mps", MPS_PER_UNIT, "GPS velocity down"),
    "total_pressure": ("pt_pa", PA_PER_UNIT, "pitot total pressure"),
    "impact_pressure": ("qc_pa", PA_PER_UNIT, "impact pressure p_t - p_s"),
    "static_pressure": ("ps_pa", PA_PER_UNIT, "static-port pressure"),
    "reference_static_pressure": ("ps_ref_pa", PA_PER_UNIT, "reference static pressure"),
    "total_temperature": ("tat_k", TEMPERATURE_UNITS, "total-temperature probe"),
    "static_temperature": ("oat_k", TEMPERATURE_UNITS, "outside (static) air temperature"),
    "gps_height": ("alt_m", M_PER_UNIT, "GPS geometric height"),
    "roll": ("roll_rad", RAD_PER_UNIT, "roll angle"),
    "pitch": ("pitch_rad", RAD_PER_UNIT, "pitch angle"),
    "true_heading": ("heading_rad", RAD_PER_UNIT, "true heading"),
    "sideslip": ("sideslip_rad", RAD_PER_UNIT, "sideslip vane angle"),
}
# not flight CSV columns: read by `read_attitude` for the self-survey's vector airspeed
ATTITUDE_KEYS = ("roll", "pitch", "true_heading", "sideslip")
_REQUIRED = ("time", "gps_vn", "gps_ve", "static_pressure")
_ONE_OF = (("total_pressure", "impact_pressure"), ("total_temperature", "static_temperature"))
MACH_IC_MAX = MACH_MAX
SUPERSONIC_NOTE = "left out: above M_ic {:g} (`mach_ic_max`)"


def read_column_map(path):
    """The validated column mapping of TOML file `path`: {key: (column, unit)}.

    Raises
    ------
    PitotcalError
        One line naming the file and the key: not TOML, an unknown key (with the nearest known
        one), a value that is not ``{ column = "...", unit = "..." }``, a unit the key's
        quantity does not have (the known ones listed), a required key missing, or two keys
        that say the same thing (total and impact pressure, total and static temperature).
    """
    doc = _load(path)

    def refuse(key, problem):
        raise PitotcalError(f"`columns` {path}: key {key}: {problem}", param="columns")

    mapping = {}
    for key, value in doc.items():
        if key not in MAPPING_KEYS:
            near = difflib.get_close_matches(key, MAPPING_KEYS, n=1, cutoff=0.6)
            refuse(key, "unknown" + (f" (did you mean {near[0]}?)" if near else "") +
                   f"; known keys: {', '.join(MAPPING_KEYS)}")
        if not isinstance(value, dict) or not isinstance(value.get("column"), str) \
                or not value["column"].strip():
            refuse(key, 'expected { column = "NAME", unit = "UNIT" }')
        extra = sorted(set(value) - {"column", "unit"})
        if extra:
            refuse(key, f"unknown field {extra[0]} (fields: column, unit)")
        units = MAPPING_KEYS[key][1]
        unit = value.get("unit")
        if unit not in units:
            said = "no unit" if unit is None else f"unit {unit!r} is not known"
            refuse(key, f"{said}; {MAPPING_KEYS[key][2]} units: {', '.join(units)}")
        mapping[key] = (value["column"].strip(), unit)
    for key in _REQUIRED:
        if key not in mapping:
            refuse(key, f"missing ({MAPPING_KEYS[key][2]} is required)")
    for pair in _ONE_OF:
        present = [k for k in pair if k in mapping]
        if not present:
            refuse(pair[0], f"missing: map {pair[0]} or {pair[1]}")
        if len(present) == 2:
            refuse(pair[1], f"both {pair[0]} and {pair[1]} are mapped; map one")
    return mapping


def _load(path):
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except tomllib.TOMLDecodeError as exc:
        raise PitotcalError(f"`columns` {path}: not valid TOML ({exc})", param="columns") \
            from None
    except UnicodeDecodeError:
        raise PitotcalError(f"`columns` {path}: not valid TOML (binary content)",
                            param="columns") from None
    except RecursionError:
        raise PitotcalError(f"`columns` {path}: not valid TOML (nested too deeply)",
                            param="columns") from None
    except OSError as exc:
        raise PitotcalError(f"`columns` {path}: cannot read it ({exc.strerror})",
                            param="columns") from None


def read_mapped_csv(path, columns, start_s=None, end_s=None, *, temp_recovery=1.0,
                    rh_pct=None, mach_ic_max=MACH_IC_MAX):
    """Read a CSV export through the column mapping `columns` (a TOML path or the dict of
    `read_column_map`); see the module notes.

    Parameters
    ----------
    path : str or path-like
        The export: a comma-separated text file with one header row (``#`` lines before it
        are allowed, as in a flight CSV); columns not mapped are ignored.
    columns : str, path-like or dict
        The mapping.
    start_s, end_s, temp_recovery, rh_pct
        As in `pitotcal.io.read_flight` (the window is in the mapped time, s).
    mach_ic_max : float
        Samples whose measured pressures give a Mach number above this are left out (module
        notes); the default keeps every sample the pitot relations take (Mach 0 to 3).

    Returns
    -------
    Flight
        As `read_flight_csv` makes it; `meta` also holds ``columns`` (the mapping's file),
        ``alt_source`` ("gps_height" when mapped) and ``excluded_supersonic`` (a count).

    Raises
    ------
    PitotcalError
        A bad mapping (`read_column_map`), or a mapped column the export does not have.
    FlightDataError
        Unusable data, as for a flight CSV; the message names the export's column.
    """
    try:
        mach_ic_max = float(mach_ic_max)
    except (TypeError, ValueError):
        mach_ic_max = float("nan")     # refused below, by name
    if not 0.0 < mach_ic_max <= MACH_IC_MAX:
        raise PitotcalError(f"`mach_ic_max` {mach_ic_max!r} must be in (0, {MACH_IC_MAX:g}]",
                            param="mach_ic_max")
    mapping, label, name, data, header_line = _mapped_data(path, columns)
    mapping = {k: v for k, v in mapping.items() if k not in ATTITUDE_KEYS}
    flight_columns, table = _to_si(mapping, data)
    kept, n_super, note = _subsonic(table, flight_columns, mach_ic_max)
    table = table[kept]
    text = _flight_csv_text(flight_columns, table)
    where = {MAPPING_KEYS[k][0]: c for k, (c, _) in mapping.items()}
    where["qc_pa"] = where.get("qc_pa") or f"{where['pt_pa']} - {where['ps_pa']}"
    try:
        flight = read_flight_csv(InputBytes(name, text), start_s, end_s,
                                 temp_recovery=temp_recovery, rh_pct=rh_pct)
    except FlightDataError as exc:
        message = _export_rows(str(exc), np.flatnonzero(kept), header_line)
        raise FlightDataError(f"{message} [{_named(message, where)} via {label}]") from None
    meta = {**flight.meta, "columns": str(label), "excluded_supersonic": n_super}
    if "gps_height" in mapping:
        meta["alt_source"] = "gps_height"
    return dataclasses.replace(flight, meta=meta,
                               warnings=(*((note,) if note else ()), *flight.warnings))


def read_attitude(path, columns):
    """The attitude of a CSV export through its column mapping, for `self_survey(attitude=)`.

    Returns
    -------
    dict of ndarray
        `time_s` and `roll_rad`, `pitch_rad`, `heading_rad`, with `sideslip_rad` when mapped,
        every row of the export (NaN where a cell is not a number).

    Raises
    ------
    PitotcalError
        A bad mapping, or one without roll, pitch and true_heading (each named).
    """
    mapping, label, _, data, _ = _mapped_data(path, columns)
    missing = [k for k in ATTITUDE_KEYS[:3] if k not in mapping]
    if missing:
        raise PitotcalError(f"`columns` {label}: key {missing[0]}: missing (the attitude needs "
                            "roll, pitch and true_heading)", param="columns")
    out = {"time_s": data["time"] * S_PER_UNIT[mapping["time"][1]]}
    for key in ATTITUDE_KEYS:
        if key in mapping:
            out[MAPPING_KEYS[key][0]] = data[key] * RAD_PER_UNIT[mapping[key][1]]
    return out


def mapped_attitude(path, columns):
    """`read_attitude` when the mapping `columns` names roll, pitch and true_heading, else
    None: the attitude wherever an export has it."""
    mapping = columns if isinstance(columns, dict) else read_column_map(columns)
    if not all(k in mapping for k in ATTITUDE_KEYS[:3]):
        return None
    return read_attitude(path, mapping)


def _mapped_data(path, columns):
    """(mapping, its label, the export's name, {key: raw column}, the header's line number)."""
    mapping = columns if isinstance(columns, dict) else read_column_map(columns)
    label = columns if not isinstance(columns, dict) else "the column mapping"
    source = read_once(path)
    name = str(source)
    header, skip = _header(source, name)
    index = {}
    for key, (column, _) in mapping.items():
        if column not in header:
            near = difflib.get_close_matches(column, header, n=1, cutoff=0.6)
            raise PitotcalError(f"`columns` {label}: key {key}: {name} has no column {column!r}"
                                + (f" (found {near[0]!r})" if near else ""), param="columns")
        index[key] = header.index(column)
    return mapping, label, name, _parse(source, name, skip, index), skip


def _header(source, name):
    """(column names, lines before the data) of the export."""
    with io.TextIOWrapper(open_binary(source), encoding="utf-8-sig", errors="replace") as f:
        for skip, line in enumerate(f, start=1):
            text = line.strip()
            if text and not text.startswith("#"):
                return [c.strip().strip('"').strip() for c in text.split(",")], skip
    raise FlightDataError(f"{name}: no header row")


def _parse(source, name, skip, index):
    """Rows x mapped keys (in `index` order), NaN where a cell is not a number."""
    keys = list(index)
    with io.TextIOWrapper(open_binary(source), encoding="utf-8-sig", errors="replace") as f:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            data = np.genfromtxt(f, delimiter=",", skip_header=skip,
                                 usecols=[index[k] for k in keys],
                                 dtype=float, invalid_raise=False, comments="#")
    data = np.atleast_2d(data).reshape(-1, len(keys))
    if data.shape[0] == 0:
        raise FlightDataError(f"{name}: header only, no data rows")
    return {k: data[:, j] for j, k in enumerate(keys)}


def _to_si(mapping, data):
    """(flight CSV column names, rows x columns) in SI; q_ci from a total pressure."""
    si = {}
    for key, (_, unit) in mapping.items():
        column, units, _ = MAPPING_KEYS[key]
        if units is TEMPERATURE_UNITS:
            scale, offset = units[unit]
            si[column] = scale * data[key] + offset
        else:
            si[column] = units[unit] * data[key]
    if "pt_pa" in si:
        si["qc_pa"] = si.pop("pt_pa") - si["ps_pa"]
    names = list(si)
    return names, np.column_stack([si[c] for c in names])


def _subsonic(table, names, mach_ic_max):
    """Which rows are at or below `mach_ic_max` by q_ci/p_s (or not a number there), the count
    left out and the warning saying so."""
    ratio = table[:, names.index("qc_pa")] / table[:, names.index("ps_pa")]
    above = ratio > float(qc_from_mach_pa(mach_ic_max, 1.0))
    n = int(np.count_nonzero(above))
    note = f"{n} samples {SUPERSONIC_NOTE.format(mach_ic_max)}" if n else None
    if note:
        warnings.warn(note, stacklevel=3)
    return ~above, n, note


def _flight_csv_text(names, table):
    buf = io.StringIO()
    np.savetxt(buf, table, delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    return buf.getvalue().encode()


def _export_rows(message, kept, header_line):
    """`message` with each 'row R (line L)' of the converted table as the export's own row and
    line (rows left out above M_ic counted; the line assumes no blank lines among the data)."""
    def export(match):
        row = int(kept[int(match.group(1)) - 1]) + 1 if int(match.group(1)) <= kept.size \
            else int(match.group(1))
        return f"row {row} (line {header_line + row})"
    return re.sub(r"row (\d+) \(line \d+\)", export, message)


def _named(message, where):
    """'qc_pa is total_pres_psi - static_pres_psi' for the flight column in `message`."""
    said = [f"{c} is {src}" for c, src in where.items() if f"column {c}" in message]
    return "; ".join(said) or ", ".join(f"{c} is {src}" for c, src in where.items())
