"""The plan CSV: `read_plan` and `write_plan` (docs/interfaces.md, plan CSV)."""

import csv
import json
import warnings
from pathlib import Path

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.core.plan import PLAN_COLUMNS, PLAN_RANGES, Plan
from .atomic import atomic_open
from .flight_checks import looks_utf16
from .jsonfile import json_ready

__all__ = ["read_plan", "write_plan"]


def write_plan(plan, path):
    """Write the plan CSV: `# key: json-value` lines with the settings, then the columns."""
    path = Path(path)
    with atomic_open(path, "w", newline="") as fh:
        for key, value in plan.settings.items():
            fh.write(f"# {key}: {json.dumps(json_ready(value), allow_nan=False)}\n")
        writer = csv.writer(fh)
        writer.writerow(PLAN_COLUMNS)
        data = np.column_stack([plan.column(c) for c in PLAN_COLUMNS])
        writer.writerows([[f"{v:.6g}" if i else f"{v:.3f}" for i, v in enumerate(row)]
                          for row in data])
    return path


def read_plan(path):
    """Read a plan CSV written by `write_plan` (or by hand with the same columns).

    Every problem is a `PitotcalError` naming the file, and for data the column and the row
    (data rows counted from 1 after the header; *line* is the file line): a bad or empty cell,
    NaN or inf, a short row, time not strictly increasing, an airspeed <= 0. A plan whose time
    span differs from the `duration_s` in its own settings (a truncated file) gives a warning.
    """
    path = Path(path)
    settings, header_row = {}, 0
    try:
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        if isinstance(exc, UnicodeDecodeError) and looks_utf16(path.read_bytes()[:4096]):
            raise PitotcalError(f"{path}: cannot read plan: UTF-16 text (save it as UTF-8: a "
                                "plan CSV is UTF-8 or ASCII)") from None
        raise PitotcalError(f"{path}: cannot read plan: {exc}") from None
    for header_row, line in enumerate(lines):
        if not line.startswith("#"):
            break
        key, _, value = line[1:].partition(":")
        try:
            settings[key.strip()] = json.loads(value)
        except json.JSONDecodeError:
            settings[key.strip()] = value.strip()
    header = [h.strip() for h in lines[header_row].split(",")] if lines[header_row:] else []
    missing = [c for c in PLAN_COLUMNS if c not in header]
    if missing:
        raise PitotcalError(f"{path}: not a plan CSV, missing column {missing[0]}")
    index = [header.index(c) for c in PLAN_COLUMNS]
    rows = []
    for line_no, line in enumerate(lines[header_row + 1:], start=header_row + 2):
        if not line.strip():
            continue
        cells = line.split(",")
        where = f"row {len(rows) + 1} (line {line_no})"
        if len(cells) < len(header):
            raise PitotcalError(f"{path}: {where}: {len(cells)} cells, the header has "
                                f"{len(header)}")
        values = []
        for name, i in zip(PLAN_COLUMNS, index):
            try:
                value = float(cells[i])
            except ValueError:
                raise PitotcalError(f"{path}: column {name}, {where}: not a number: "
                                    f"{cells[i].strip()!r}") from None
            if not np.isfinite(value):
                raise PitotcalError(f"{path}: column {name}, {where}: {value}")
            values.append(value)
        rows.append((values, where))
    if len(rows) < 2:
        raise PitotcalError(f"{path}: plan CSV has fewer than 2 rows")
    data = np.array([values for values, _ in rows])
    columns = {c: data[:, j] for j, c in enumerate(PLAN_COLUMNS)}
    bad = np.flatnonzero(np.diff(columns["time_s"]) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise PitotcalError(f"{path}: column time_s, {rows[i][1]}: {columns['time_s'][i]:g} s "
                            f"is not after the previous row's {columns['time_s'][i - 1]:g} s")
    for name in ("tas_mps", "cas_mps"):
        bad = np.flatnonzero(columns[name] <= 0)
        if bad.size:
            raise PitotcalError(f"{path}: column {name}, {rows[int(bad[0])][1]}: airspeed "
                                f"{columns[name][bad[0]]:g} m/s must be > 0")
    for name, (lo, hi) in PLAN_RANGES.items():
        bad = np.flatnonzero((columns[name] < lo) | (columns[name] > hi))
        if bad.size:
            raise PitotcalError(f"{path}: column {name}, {rows[int(bad[0])][1]}: "
                                f"{columns[name][bad[0]]:g} is outside {lo:g} to {hi:g} "
                                f"{name.rsplit('_', 1)[1]} (what a plan can hold)")
    span = columns["time_s"][-1] - columns["time_s"][0]
    duration = settings.get("duration_s")
    if isinstance(duration, (int, float)) and abs(span - duration) > max(1e-3 * duration, 0.01):
        warnings.warn(f"{path}: the plan spans {span:g} s but its settings say duration_s "
                      f"{duration:g} s: is the file truncated?", stacklevel=2)
    return Plan(**columns, settings=settings)
