"""Every airspeed sensor of a log as its own `Flight`, for the joint fit of several sensors.

ArduPilot logs a second sensor as ``ARSP`` instance 1 (older firmware: ``ASP2``), PX4 as a
second ``differential_pressure`` instance, a telemetry log as ``SCALED_PRESSURE2``
(`LogStreams.other_sensors`). Each sensor's flight is read the way `read_flight` reads the
first one: its own pressure samples as the time base (never interpolated), the same GPS, static
pressure, temperature, cuts and air-data options. The first sensor's flight names the others in
``Flight.meta["airspeed_sensors"]``; `sensor_count` reads that.
"""

import dataclasses
import warnings
from pathlib import Path

from pitotcal.core.errors import FlightDataError
from pitotcal.core.moist_air import check_air_options, with_static_air

from .flight_checks import QCI_MIN_FLYING_PA, check_window
from .read_once import is_stream, log_file, naming
from .streams import LOG_EXTENSIONS

__all__ = ["in_windows", "other_sensor_flights", "read_other_sensors", "sensor_count"]


def sensor_count(flight):
    """How many airspeed sensors the log of `flight` has (1 when its meta names no others)."""
    named = str(flight.meta.get("airspeed_sensors", "") or "")
    return len(named.split("; ")) if named else 1


def other_sensor_flights(path, flight, *, csv_columns=None, single_only=None):
    """`read_other_sensors` of the log `flight` was read from, read as `flight` was (its
    `Flight.reading`), when its meta names more than one sensor; [] for one sensor, a stream
    or a CSV (a `csv_columns` export, or `convert`'s, which holds the first sensor), and with
    a warning when options that apply to one sensor's fit only are given (`single_only`:
    {option name: value}, None or 0 when not given)."""
    from . import is_log_file

    n = sensor_count(flight)
    # a CSV (`convert`'s keeps the log's airspeed_sensors line) has the first sensor only
    if n < 2 or csv_columns is not None or not is_log_file(path):
        return []
    given = [name for name, value in (single_only or {}).items() if value]
    if given:
        warnings.warn(f"{Path(str(path)).name}: the log has {n} airspeed sensors; "
                      f"{', '.join(given)} applies to one sensor's fit: the first sensor "
                      "alone is calibrated", stacklevel=2)
        return []
    reading = dict(getattr(flight, "reading", None) or {})
    others = read_other_sensors(path, reading.get("start_s"), reading.get("end_s"),
                                oat_k=reading.get("oat_k"),
                                temp_recovery=reading.get("temp_recovery", 1.0),
                                rh_pct=reading.get("rh_pct"),
                                oat_ground_k=reading.get("oat_ground_k"))
    return [in_windows(other, reading.get("windows"), first=flight) for other in others]


def in_windows(flight, windows, first=None):
    """`flight`'s samples inside the first sensor's calibration `windows` (`Flight.reading`
    ``windows``: start_s, end_s), each window its `Flight.segment`; `flight` when None.

    With `first` (the first sensor's flight), also only the samples within one of its sample
    steps of a sample it kept: what the steady-flight cuts took out inside a window (a steep
    turn, a full-throttle climb: the aircraft's state, not the sensor's) goes for every sensor.
    """
    if not windows:
        return flight
    import numpy as np

    segment = np.full(flight.n, -1)
    for i, w in enumerate(windows):
        segment[(flight.time_s >= w["start_s"]) & (flight.time_s <= w["end_s"])] = i
    if first is not None and first.n > 1:
        kept_t = np.asarray(first.time_s, float)
        step = float(np.median(np.diff(kept_t)))
        at = np.clip(np.searchsorted(kept_t, flight.time_s), 1, kept_t.size - 1)
        gap = np.minimum(np.abs(flight.time_s - kept_t[at - 1]), np.abs(kept_t[at] - flight.time_s))
        segment[gap > step] = -1
    inside = dataclasses.replace(flight, segment=segment if len(windows) > 1 else None)
    return inside.select(segment >= 0)


def read_other_sensors(path, start_s=None, end_s=None, *, oat_k=None, temp_recovery=1.0,
                       rh_pct=None, oat_ground_k=None):
    """The flights of a log's airspeed sensors beyond the first, in instance order.

    Parameters
    ----------
    path : str or Path
        A log file (``.ulg``, ``.bin``, ``.log``, ``.tlog``); not a stream (read once, it is
        gone: an empty list then).
    start_s, end_s, oat_k, temp_recovery, rh_pct, oat_ground_k
        As `read_flight` (every usable sample: `other_sensor_flights` keeps the first
        sensor's windows).

    Returns
    -------
    list of Flight
        Each with its sensor's pressure source in ``meta["qc_source"]``; the reader's warnings
        about the log (given once, for the first sensor) kept in `Flight.warnings`, not issued
        again. A sensor whose data cannot calibrate (too little usable data: a dead or
        disconnected sensor) is left out with a warning naming it and why.
    """
    from .logs import _assemble, _check_options, _read_streams

    if is_stream(path):
        return []
    start_s, end_s = check_window(start_s, end_s)
    temp_recovery, rh_pct = check_air_options(temp_recovery, rh_pct)
    options = _check_options("linear", 0.0, 5.0, QCI_MIN_FLYING_PA, oat_k, None,
                             oat_ground_k)
    with naming(path), log_file(path, LOG_EXTENSIONS) as file:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")       # said for the first sensor already
            streams = _read_streams(Path(file))
            flights, unusable = [], []
            for i, (t, q, source) in enumerate(streams.other_sensors, start=2):
                one = dataclasses.replace(streams, pressure_t=t, qci_pa=q, pressure_source=source,
                                          other_sensors=[], conversions=list(streams.conversions))
                try:
                    flight = _assemble(one, Path(file).name, start_s, end_s, options).flight
                except FlightDataError as exc:      # a dead second sensor: the first stands
                    unusable.append(f"airspeed sensor {i} ({source}) not calibrated: {exc}")
                    continue
                flights.append(with_static_air(flight, temp_recovery=temp_recovery,
                                               rh_pct=rh_pct))
    for text in unusable:
        warnings.warn(text, stacklevel=2)
    from . import with_reading

    reading = {"start_s": start_s, "end_s": end_s, "oat_k": oat_k,
               "temp_recovery": temp_recovery, "rh_pct": rh_pct}
    if oat_ground_k is not None:
        reading["oat_ground_k"] = oat_ground_k
    return [with_reading(f, reading) for f in flights]
