"""Autopilot parameter files: the airspeed parameter a calibration recommends, and its source.

- ArduPilot: the Mission Planner parameter file, ``NAME,VALUE`` per line and ``#`` comments,
  which Mission Planner's "Load from file" and MAVProxy's ``param load`` both read (pymavlink's
  `mavparm.MAVParmDict.load` strips ``#`` comments and accepts ``,`` or blanks).
- PX4: the QGroundControl parameter file, ``#`` header lines then one tab-separated line per
  parameter: ``vehicle-id  component-id  name  value  type`` (type 9 = MAV_PARAM_TYPE_REAL32).

`read_flight_and_parameters` reads the flight with the autopilot's own current value of its
airspeed parameters (ArduPilot ``ARSPD_RATIO`` from the DataFlash ``PARM`` messages, PX4
``ASPD_SCALE_1`` from the ULog's initial parameters; `pitotcal.io.logs`), or, for a flight
CSV written by `pitotcal convert`, from its ``# autopilot_...`` comment lines.
"""

from pathlib import Path

from pitotcal.core.errors import PitotcalError
from .atomic import atomic_open

__all__ = ["QGC_REAL32", "read_flight_and_parameters", "read_qgc_params",
           "write_ardupilot_param_set", "write_ardupilot_params", "write_qgc_param_set",
           "write_qgc_params"]

QGC_REAL32 = 9          # MAV_PARAM_TYPE_REAL32
ARDUPILOT_RATIO = "ARSPD_RATIO"
PX4_SCALES = ("ASPD_SCALE_1", "ASPD_SCALE")


def read_flight_and_parameters(path, start_s=None, end_s=None, *, oat_k=None,
                               temp_recovery=1.0, rh_pct=None, oat_ground_k=None,
                               windows="all"):
    """(Flight, autopilot, {parameter: current value}) of a log or a converted flight CSV,
    the flight read as `read_flight` reads it (its air data made with `temp_recovery`, `rh_pct`).

    `autopilot` is "ArduPilot", "PX4", or None when nothing says which autopilot flew it.
    """
    from pitotcal.core.moist_air import check_air_options, with_static_air

    from . import is_log_file, read_flight, with_reading
    from .flight_checks import check_window
    from .read_once import log_suffix, read_once

    path = read_once(path)          # a stream once, whole: each reader below gets its bytes
    if is_log_file(path) or log_suffix(path):
        from .logs import load_log

        start_s, end_s = check_window(start_s, end_s)
        temp_recovery, rh_pct = check_air_options(temp_recovery, rh_pct)
        log = load_log(path, start_s, end_s, oat_k=oat_k, oat_ground_k=oat_ground_k,
                       windows=windows)
        params = dict(log.airspeed_scale)
        suffix = log_suffix(path) or Path(path).suffix.lower()
        # a telemetry log says which autopilot sent it (its format names it)
        autopilot = "PX4" if suffix == ".ulg" or "PX4" in log.log_format else "ArduPilot"
        flight = with_static_air(log.flight, temp_recovery=temp_recovery, rh_pct=rh_pct)
        reading = {"start_s": start_s, "end_s": end_s, "oat_k": oat_k,
                   "temp_recovery": temp_recovery, "rh_pct": rh_pct}
        if oat_ground_k is not None:
            reading["oat_ground_k"] = oat_ground_k
        return with_reading(flight, reading), \
            autopilot, params
    flight = read_flight(path, start_s, end_s, oat_k=oat_k, temp_recovery=temp_recovery,
                         rh_pct=rh_pct, oat_ground_k=oat_ground_k, windows=windows)
    params = {}
    for key, text in flight.meta.items():
        if key.startswith("autopilot_") and key[10:] in (ARDUPILOT_RATIO, *PX4_SCALES):
            try:
                params[key[10:]] = float(str(text).split()[0])
            except ValueError:
                continue
    autopilot = ("ArduPilot" if ARDUPILOT_RATIO in params
                 else "PX4" if any(p in params for p in PX4_SCALES) else None)
    return flight, autopilot, params


def write_ardupilot_params(path, name, value, comments=()):
    """Write one parameter as a Mission Planner / MAVProxy parameter file; returns the path.

    `comments` are written first, each as a ``#`` line; the value with 6 decimals (ArduPilot
    stores float32, ~7 significant digits).
    """
    lines = [f"# {c}" for c in comments] + [f"{name},{value:.6f}"]
    with atomic_open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path


def write_qgc_params(path, name, value, comments=(), vehicle_id=1, component_id=1):
    """Write one parameter as a QGroundControl parameter file (tab-separated); returns the path."""
    header = ["# Onboard parameters for Vehicle 1", "#", "# Stack: PX4 Pro",
              *(f"# {c}" for c in comments), "#",
              "# Vehicle-Id Component-Id Name Value Type"]
    row = f"{vehicle_id}\t{component_id}\t{name}\t{value:.6f}\t{QGC_REAL32}"
    with atomic_open(path, "w") as fh:
        fh.write("\n".join(header + [row]) + "\n")
    return path


def write_ardupilot_param_set(path, entries):
    """`write_ardupilot_params` of several parameters in one file: `entries` are
    (name, value, comments), each parameter's comments before its line. Returns the path."""
    lines = []
    for name, value, comments in entries:
        lines += [f"# {c}" for c in comments] + [f"{name},{value:.6f}"]
    with atomic_open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path


def write_qgc_param_set(path, entries, vehicle_id=1, component_id=1):
    """`write_qgc_params` of several parameters in one file: `entries` are (name, value,
    comments), the comments in the header. Returns the path."""
    header = ["# Onboard parameters for Vehicle 1", "#", "# Stack: PX4 Pro"]
    for _, _, comments in entries:
        header += [f"# {c}" for c in comments]
    rows = [f"{vehicle_id}\t{component_id}\t{name}\t{value:.6f}\t{QGC_REAL32}"
            for name, value, _ in entries]
    with atomic_open(path, "w") as fh:
        fh.write("\n".join(header + ["#", "# Vehicle-Id Component-Id Name Value Type"] + rows)
                 + "\n")
    return path


def read_qgc_params(path):
    """{name: value} of a QGroundControl parameter file.

    Raises
    ------
    PitotcalError
        A line that is neither a ``#`` comment nor five tab-separated fields.
    """
    out = {}
    for i, line in enumerate(Path(path).read_text().splitlines(), start=1):
        if not line.strip() or line.startswith("#"):
            continue
        fields = line.split("\t")
        if len(fields) != 5:
            raise PitotcalError(f"{path}: line {i}: expected 5 tab-separated fields, "
                                f"got {len(fields)}")
        out[fields[2]] = int(fields[3]) if fields[4] != str(QGC_REAL32) else float(fields[3])
    return out
