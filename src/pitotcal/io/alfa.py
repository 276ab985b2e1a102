"""The ALFA dataset's ArduPlane flights (CMU AirLab; MAVLink messages decoded to CSV) as a `Flight`.

`find_alfa_data(data_dir)` says which folder holds the CSVs (a given folder, else the
``PITOTCAL_ALFA_DATA`` environment variable, else ``./alfa-carbonz``) and, when none does, every
place it looked; `read_alfa_flight(folder)` builds the flight.

Choices (the study's summary repeats them):

- Clock: ``ros_time_s`` (``%time`` ns for the mavros topic) = Unix receive time, shifted so that
  t = 0 at the first pressure sample. The flight lives on the 10 Hz pressure samples; every
  other stream is sampled-and-held (latest sample at or before each pressure sample).
- Pressure: ``press_diff`` hPa → q_ci Pa (the logged value has its zero offset removed),
  ``press_abs`` hPa → p_s Pa.
- Temperature: the logged ``temperature`` is the pressure sensor chip's (53-60 °C), not the
  outside air, so it is not used. Default ``oat="autopilot"``: the density ArduPilot itself
  used, ρ = ρ0 / EAS2TAS² from AIRSPEED_AUTOCAL (≈ 32 °C at 973 hPa on that July afternoon),
  which also makes a comparison with its airspeed ratio like for like. ``oat="isa"``: ISA
  temperature at the pressure altitude; a number: that OAT in kelvin. A 10 K error moves ρ,
  and so k1, by ≈ 3 %.
- GPS velocity: mavros ``gps/vel`` (ENU: x = east, y = north); vertical speed from the
  autopilot's GLOBAL_POSITION_INT ``vz`` (cm/s, down) because the GPS topics carry none.
- Segment: before the engine failure (first row of failure_status_engines.csv) minus a margin.
"""

import csv
import os
import warnings
from pathlib import Path

import numpy as np

from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.core.flight import Flight
from pitotcal.core.units import (
    R_AIR_JKGK,
    RHO0_KGM3,
    density_kgm3,
    isa_altitude_m,
    isa_temperature_k,
)

from .resample import hold

__all__ = [
    "ALFA_DATA_ENV",
    "ALFA_DIR_NAME",
    "alfa_failure_time_s",
    "find_alfa_data",
    "read_alfa_csv",
    "read_alfa_flight",
]

ALFA_DIR_NAME = "alfa-carbonz"
ALFA_DATA_ENV = "PITOTCAL_ALFA_DATA"
MARKER_FILE = "scaled_pressure.csv"      # a folder holding this holds the flight
_PA_PER_HPA = 100.0


def find_alfa_data(data_dir=None):
    """The folder of the ALFA CSVs.

    Looks in `data_dir` when given (only there), else in ``$PITOTCAL_ALFA_DATA`` and then in
    ``./alfa-carbonz``; each place may be the folder itself or hold an ``alfa-carbonz`` folder.

    Raises
    ------
    FlightDataError
        No place holds the data; the one-line message lists every place looked at.
    """
    if data_dir is not None:
        places = [("data_dir", [Path(data_dir), Path(data_dir) / ALFA_DIR_NAME])]
    else:
        env = os.environ.get(ALFA_DATA_ENV)
        places = [(f"${ALFA_DATA_ENV}", [Path(env), Path(env) / ALFA_DIR_NAME])] if env else []
        places.append(("current folder", [Path.cwd() / ALFA_DIR_NAME]))
    for _, folders in places:
        for folder in folders:
            if (folder / MARKER_FILE).is_file():
                return folder
    looked = "; ".join(f"{', '.join(map(str, folders))} ({why})" for why, folders in places)
    if data_dir is None:
        unset = "" if os.environ.get(ALFA_DATA_ENV) else f"; {ALFA_DATA_ENV} is not set"
        looked += (f"{unset}; pass data_dir or set {ALFA_DATA_ENV} to the folder of the "
                   f"ALFA CSVs")
    raise FlightDataError(f"ALFA flight data ({MARKER_FILE}) not found: looked in {looked}",
                          param="data_dir")


def read_alfa_csv(path):
    """One ALFA CSV as {column: float ndarray}; the Unix receive time as `time_unix_s`.

    Files with ``ros_time_s`` use it; the rostopic dumps use ``%time`` (ns). Cells that are not
    numbers become NaN.
    """
    path = Path(path)
    if not path.is_file():
        raise FlightDataError(f"{path}: file not found")
    with open(path, newline="") as fh:
        reader = csv.reader(fh)
        try:
            header = next(reader)
        except StopIteration:
            raise FlightDataError(f"{path}: empty file") from None
        rows = [row for row in reader if row]
    if not rows:
        raise FlightDataError(f"{path}: no data rows")
    out = {name: np.array([_number(row, j) for row in rows]) for j, name in enumerate(header)}
    if "ros_time_s" in out:
        out["time_unix_s"] = out["ros_time_s"]
    elif "%time" in out:
        out["time_unix_s"] = out["%time"] * 1e-9
    else:
        raise FlightDataError(f"{path}: no time column (ros_time_s or %time)")
    return out


def _number(row, j):
    try:
        return float(row[j])
    except (ValueError, IndexError):
        return np.nan


def _read(folder, name, *columns):
    """`read_alfa_csv` of folder/name, with `columns` required."""
    path = Path(folder) / name
    table = read_alfa_csv(path)
    for c in columns:
        if c not in table:
            raise FlightDataError(f"{path}: column {c} missing")
    return table


def _held(table, column, t_dst, scale=1.0):
    """A stream's column sampled-and-held at `t_dst` (its rows sorted by time first)."""
    order = np.argsort(table["time_unix_s"], kind="stable")
    return hold(table["time_unix_s"][order], table[column][order] * scale, t_dst)


def alfa_failure_time_s(data_dir):
    """Unix time of the engine failure: first row of failure_status_engines.csv."""
    return float(_read(data_dir, "failure_status_engines.csv")["time_unix_s"][0])


def read_alfa_flight(data_dir, *, oat="autopilot", powered_only=True, margin_s=1.0,
                     vertical=True):
    """Build a `Flight` from the ALFA CSVs.

    Parameters
    ----------
    data_dir : path
        The folder of the CSVs (``alfa-carbonz``; `find_alfa_data` finds it).
    oat : "autopilot", "isa" or float
        Source of the air density (module docstring): the autopilot's EAS2TAS, ISA at the
        pressure altitude, or an outside air temperature in kelvin.
    powered_only : bool
        Keep only t < engine failure − `margin_s`.
    vertical : bool
        Add the autopilot's vertical speed as `gps_vd_mps`.

    Returns
    -------
    Flight
        time_s from the first pressure sample; `meta` holds `t0_unix_s`, `failure_time_s`,
        the density choice and the autopilot's ratio.
    """
    d = Path(data_dir)
    oat = _check_oat(oat)
    if margin_s < 0:
        raise PitotcalError(f"margin_s must be >= 0, got {margin_s!r}", param="margin_s")
    if not d.is_dir():
        raise FlightDataError(f"{d}: ALFA data directory not found")
    t_unix, qci, ps = _pressure(d)
    t0 = float(t_unix[0])
    vel = _read(d, "mavros_gps_vel.csv", "field.twist.linear.x", "field.twist.linear.y")
    vn, ok = _held(vel, "field.twist.linear.y", t_unix)
    ve, _ = _held(vel, "field.twist.linear.x", t_unix)
    ok &= np.isfinite(qci) & np.isfinite(ps) & np.isfinite(vn) & np.isfinite(ve)
    meta = {"aircraft": "Carbon-Z T-28 (ALFA carbonZ_2018-07-18-15-53-31)",
            "t0_unix_s": f"{t0:.3f}"}
    rho = _density(d, oat, t_unix, ps, meta)
    notes = []
    vd = _vertical_speed(d, t_unix, notes) if vertical else None
    if vd is not None:
        ok &= np.isfinite(vd)
    ok &= _powered(d, t_unix, t0, powered_only, margin_s, meta)
    if np.count_nonzero(ok) < 10:
        raise FlightDataError(f"{d / 'scaled_pressure.csv'}: fewer than 10 usable samples")
    # the static pressure and the temperature the density implies, for the compressible fit
    oat_k = ps / (R_AIR_JKGK * rho)
    return Flight(time_s=t_unix[ok] - t0, qci_pa=qci[ok], gps_vn_mps=vn[ok], gps_ve_mps=ve[ok],
                  rho_kgm3=rho[ok], gps_vd_mps=None if vd is None else vd[ok],
                  ps_pa=ps[ok], oat_k=oat_k[ok],
                  alt_m=None, source=str(d), meta=meta, n_dropped=int(np.count_nonzero(~ok)),
                  warnings=tuple(notes))


def _check_oat(oat):
    if isinstance(oat, str) and oat in ("autopilot", "isa"):
        return oat
    try:
        oat = float(oat)
    except (TypeError, ValueError):
        raise PitotcalError(f"oat must be 'autopilot', 'isa' or a temperature in K, "
                            f"got {oat!r}", param="oat") from None
    if not 150.0 < oat < 350.0:
        raise PitotcalError(f"oat must be a temperature in K (150-350), got {oat:g}",
                            param="oat")
    return oat


def _pressure(d):
    """Pressure samples on a strictly increasing clock: (t_unix_s, qci_pa, ps_pa)."""
    sp = _read(d, "scaled_pressure.csv", "press_diff", "press_abs")
    t_unix = sp["time_unix_s"]
    order = np.argsort(t_unix, kind="stable")
    t_unix = t_unix[order]
    keep = np.concatenate([[True], np.diff(t_unix) > 0])
    return (t_unix[keep], sp["press_diff"][order][keep] * _PA_PER_HPA,
            sp["press_abs"][order][keep] * _PA_PER_HPA)


def _density(d, oat, t_unix, ps, meta):
    """Air density at the pressure samples for the `oat` choice; notes it in `meta`."""
    cal_path = d / "airspeed_autocal.csv"
    cal = read_alfa_csv(cal_path) if cal_path.is_file() else None
    if cal is not None and "ratio" in cal:
        meta["autopilot_ratio"] = f"{float(np.median(cal['ratio'])):.5g}"
    if oat == "autopilot":
        if cal is None:
            raise FlightDataError(f"{cal_path}: needed for oat='autopilot' (EAS2TAS)")
        if "EAS2TAS" not in cal:
            raise FlightDataError(f"{cal_path}: column EAS2TAS missing")
        meta["density"] = "rho0/EAS2TAS^2 (the autopilot's own density)"
        return RHO0_KGM3 / np.interp(t_unix, cal["time_unix_s"], cal["EAS2TAS"]) ** 2
    if oat == "isa":
        # pressure altitude from the measured static pressure, then ISA temperature there
        temp = isa_temperature_k(isa_altitude_m(ps))
        meta["density"] = "ps / (R * T_ISA(pressure altitude))"
    else:
        temp = np.full(t_unix.size, oat)
        meta["density"] = f"ps / (R * {oat:g} K)"
    return density_kgm3(ps, temp)


def _vertical_speed(d, t_unix, notes):
    """The autopilot's vertical speed (down, m/s) at the pressure samples, or None."""
    gp_path = d / "global_position_int.csv"
    if not gp_path.is_file():
        notes.append(f"{gp_path} not found: flight without vertical speed")
        warnings.warn(notes[-1], stacklevel=3)
        return None
    vd, _ = _held(_read(d, "global_position_int.csv", "vz"), "vz", t_unix, scale=0.01)
    return vd


def _powered(d, t_unix, t0, powered_only, margin_s, meta):
    """Mask of the samples before the engine failure (all when not `powered_only`)."""
    fail_path = d / "failure_status_engines.csv"
    if not fail_path.is_file():
        if powered_only:
            raise FlightDataError(f"{fail_path}: needed to cut the powered segment")
        return np.ones(t_unix.size, dtype=bool)
    t_fail = alfa_failure_time_s(d) - t0
    meta["failure_time_s"] = f"{t_fail:.3f}"
    if not powered_only:
        return np.ones(t_unix.size, dtype=bool)
    return (t_unix - t0) < t_fail - margin_s
