"""`Plan`: a planned calibration maneuver and its CSV (INTERFACES §4)."""

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from estimation.errors import PitotcalError

__all__ = ["Plan", "PLAN_COLUMNS", "read_plan", "write_plan"]

PLAN_COLUMNS = ("time_s", "north_m", "east_m", "alt_m", "heading_deg", "bank_deg",
                "tas_mps", "cas_mps", "qc_pa")


@dataclass(frozen=True)
class Plan:
    """A maneuver on a time grid, SI, positions relative to the test-area centre.

    Attributes
    ----------
    time_s, north_m, east_m, alt_m, heading_deg, bank_deg, tas_mps, cas_mps, qc_pa : ndarray (N,)
        The columns of the plan CSV; `qc_pa` is the target impact pressure, `heading_deg` is
        the unwrapped air-relative heading.
    settings : dict
        The request: profile, cas_min_kt, cas_max_kt, radius_m, altitude_m, duration_s,
        bank_max_deg, wind_speed_mps, wind_from_deg, ... (written as `#` comment lines).
    success, message, iterations :
        The solver's outcome (scipy naming).
    """

    time_s: np.ndarray
    north_m: np.ndarray
    east_m: np.ndarray
    alt_m: np.ndarray
    heading_deg: np.ndarray
    bank_deg: np.ndarray
    tas_mps: np.ndarray
    cas_mps: np.ndarray
    qc_pa: np.ndarray
    settings: dict = field(default_factory=dict)
    success: bool = True
    message: str = ""
    iterations: int = 0

    @property
    def n(self):
        return int(self.time_s.size)

    def column(self, name):
        return getattr(self, name)


def write_plan(plan, path):
    """Write the plan CSV: `# key: json-value` lines with the settings, then the columns."""
    path = Path(path)
    with path.open("w", newline="") as fh:
        for key, value in plan.settings.items():
            fh.write(f"# {key}: {json.dumps(value)}\n")
        writer = csv.writer(fh)
        writer.writerow(PLAN_COLUMNS)
        data = np.column_stack([plan.column(c) for c in PLAN_COLUMNS])
        writer.writerows([[f"{v:.6g}" if i else f"{v:.3f}" for i, v in enumerate(row)]
                          for row in data])
    return path


def read_plan(path):
    """Read a plan CSV written by `write_plan` (or by hand with the same columns)."""
    path = Path(path)
    settings, header_row = {}, 0
    try:
        lines = path.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
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
    try:
        data = np.loadtxt(lines[header_row + 1:], delimiter=",", ndmin=2)
    except ValueError as exc:
        raise PitotcalError(f"{path}: plan CSV has a bad cell: {exc}") from None
    if data.shape[0] < 2:
        raise PitotcalError(f"{path}: plan CSV has fewer than 2 rows")
    columns = {c: data[:, header.index(c)] for c in PLAN_COLUMNS}
    return Plan(**columns, settings=settings)
