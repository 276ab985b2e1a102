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

from pitotcal.core.moist_air import check_air_options, with_static_air

from .flight_checks import QCI_MIN_FLYING_PA, check_window
from .read_once import is_stream, log_file, naming
from .streams import LOG_EXTENSIONS

__all__ = ["read_other_sensors", "sensor_count"]


def sensor_count(flight):
    """How many airspeed sensors the log of `flight` has (1 when its meta names no others)."""
    named = str(flight.meta.get("airspeed_sensors", "") or "")
    return len(named.split("; ")) if named else 1


def read_other_sensors(path, start_s=None, end_s=None, *, oat_k=None, temp_recovery=1.0,
                       rh_pct=None):
    """The flights of a log's airspeed sensors beyond the first, in instance order.

    Parameters
    ----------
    path : str or Path
        A log file (``.ulg``, ``.bin``, ``.log``, ``.tlog``); not a stream (read once, it is
        gone: an empty list then).
    start_s, end_s, oat_k, temp_recovery, rh_pct
        As `read_flight`.

    Returns
    -------
    list of Flight
        Each with its sensor's pressure source in ``meta["qc_source"]``; the reader's warnings
        about the log (given once, for the first sensor) kept in `Flight.warnings`, not issued
        again.
    """
    from .logs import _assemble, _check_options, _read_streams

    if is_stream(path):
        return []
    start_s, end_s = check_window(start_s, end_s)
    temp_recovery, rh_pct = check_air_options(temp_recovery, rh_pct)
    options = _check_options("linear", 0.0, 5.0, QCI_MIN_FLYING_PA, oat_k, None)
    with naming(path), log_file(path, LOG_EXTENSIONS) as file:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")       # said for the first sensor already
            streams = _read_streams(Path(file))
            flights = []
            for t, q, source in streams.other_sensors:
                one = dataclasses.replace(streams, pressure_t=t, qci_pa=q, pressure_source=source,
                                          other_sensors=[], conversions=list(streams.conversions))
                flight = _assemble(one, Path(file).name, start_s, end_s, options).flight
                flight = with_static_air(flight, temp_recovery=temp_recovery, rh_pct=rh_pct)
                flights.append(flight)
    from . import with_reading

    reading = {"start_s": start_s, "end_s": end_s, "oat_k": oat_k,
               "temp_recovery": temp_recovery, "rh_pct": rh_pct}
    return [with_reading(f, reading) for f in flights]
