"""MAVLink telemetry log reader (``.tlog``, what Mission Planner and QGroundControl record): the
raw streams for `pitotcal.io.logs`.

A ``.tlog`` is the ground station's record of the telemetry link: every MAVLink message as it
arrived, each after an 8-byte time stamp (µs since 1970, the ground station's clock). pymavlink's
``mavutil.mavlink_connection`` reads it; each message's ``_timestamp`` is that arrival time,
which is the time base here (the messages' own ``time_boot_ms`` are not on one clock with
GPS_RAW_INT's ``time_usec``, GPS time on many receivers). Arrival times carry the link's
jitter (tens of ms on a radio): the GPS velocity is interpolated onto the pressure samples as
for the other logs, so a jitter that small moves the velocity by the acceleration times it.
The log's zero is the first message's arrival time.

Messages read (from the vehicle only: the system that sent the first autopilot HEARTBEAT;
a ground station's own messages in the file are skipped):

- ``SCALED_PRESSURE``: ``press_diff`` (hPa) is the first airspeed sensor's differential
  pressure (q_ci), ``press_abs`` (hPa) the static pressure, ``temperature`` (cdegC) the baro
  chip's temperature and ``temperature_press_diff`` (cdegC, MAVLink 2 extension) the airspeed
  sensor's: sensor temperatures, not the outside air (`pitotcal.io.logs` warns so). A log whose
  ``press_diff`` is absent or zero throughout cannot calibrate: refused, naming the field.
- ``SCALED_PRESSURE2``: a second airspeed sensor's ``press_diff`` where ArduPilot sends one
  (`LogStreams.other_sensors`).
- ``GPS_RAW_INT``: ``fix_type >= 3`` valid; ground velocity from ``vel`` (cm/s) and ``cog``
  (cdeg true), altitude ``alt`` (mm MSL). Only without it the EKF's ``GLOBAL_POSITION_INT``
  ``vx, vy`` (cm/s) are used, with a warning: a filtered velocity, not the receiver's.
- ``HEARTBEAT``: the armed flag of ``base_mode`` is the flight state (a tlog has no landed
  flag); ``autopilot`` says ArduPilot or PX4.
- ``PARAM_VALUE``: the airspeed parameters when the ground station fetched them
  (``ARSPD_RATIO``, ``ARSPD2_RATIO``, ``ASPD_SCALE_1``, ``ASPD_SCALE_2``, the minimum airspeed).
- ``WIND`` (ArduPilot): the autopilot's wind estimate, for comparison.
- ``STATUSTEXT``: the firmware version where the autopilot announced it.

``VFR_HUD.airspeed`` is not used: it is the autopilot's own airspeed, already calibrated with
the ratio under test (or a synthetic estimate without a sensor).
"""

import re
from pathlib import Path

import numpy as np

from pitotcal.core.errors import FlightDataError

from .streams import MAVLINK_READ_ERRORS, LogStreams, captured_output, skipped_bytes

__all__ = ["AIRSPEED_PARAMS", "read_tlog_streams"]

# The parameters a tlog's PARAM_VALUE messages are searched for
AIRSPEED_PARAMS = ("ARSPD_RATIO", "ARSPD2_RATIO", "ASPD_SCALE_1", "ASPD_SCALE_2", "ASPD_SCALE")
_MIN_AIRSPEED_PARAMS = ("ARSPD_FBW_MIN", "AIRSPEED_MIN", "FW_AIRSPD_MIN")
_ARMED = 128                 # MAV_MODE_FLAG_SAFETY_ARMED
_AUTOPILOT_PX4 = 12          # MAV_AUTOPILOT_PX4
_NOT_AUTOPILOT = (8,)        # MAV_AUTOPILOT_INVALID: ground stations, gimbals
_FIRMWARE = re.compile(r"^(Ardu\w+|Rover|PX4)\s*V?\d", re.IGNORECASE)
_UNKNOWN_U16 = 65535         # GPS_RAW_INT vel / cog not known
_MESSAGES = {"SCALED_PRESSURE": ("press_diff", "press_abs", "temperature",
                                 "temperature_press_diff"),
             "SCALED_PRESSURE2": ("press_diff",),
             "GPS_RAW_INT": ("fix_type", "vel", "cog", "alt"),
             "GLOBAL_POSITION_INT": ("vx", "vy", "vz", "alt"),
             "WIND": ("direction", "speed")}


def _scan(path):
    """({type: {field: array, "t": arrival s}}, params, heartbeat rows, firmware, bytes skipped)."""
    from pymavlink import mavutil

    name = Path(path).name
    rows = {k: [] for k in _MESSAGES}
    params, beats, firmware, vehicle, n_msgs = {}, [], None, None, 0
    try:
        with captured_output() as chatter:
            log = mavutil.mavlink_connection(str(path), notimestamps=False,
                                             dialect="ardupilotmega")
            while True:
                msg = log.recv_msg()
                if msg is None:
                    break
                kind = msg.get_type()
                if kind == "BAD_DATA":
                    continue
                n_msgs += 1
                if kind == "HEARTBEAT" and msg.autopilot not in _NOT_AUTOPILOT:
                    vehicle = msg.get_srcSystem() if vehicle is None else vehicle
                if vehicle is not None and msg.get_srcSystem() != vehicle:
                    continue
                t = float(getattr(msg, "_timestamp", np.nan))
                if kind == "HEARTBEAT" and msg.autopilot not in _NOT_AUTOPILOT:
                    beats.append((t, bool(msg.base_mode & _ARMED), int(msg.autopilot)))
                elif kind in rows:
                    rows[kind].append([t] + [float(getattr(msg, f, np.nan) or 0.0)
                                             for f in _MESSAGES[kind]])
                elif kind == "PARAM_VALUE":
                    params[str(msg.param_id).rstrip("\x00")] = float(msg.param_value)
                elif kind == "STATUSTEXT" and firmware is None and _FIRMWARE.match(msg.text or ""):
                    firmware = msg.text.strip()
            log.close()
    except MAVLINK_READ_ERRORS as exc:
        raise FlightDataError(f"{name}: not a readable MAVLink telemetry log ({exc}); "
                              "truncated or corrupt?") from None
    skipped = skipped_bytes(chatter.getvalue())
    if n_msgs == 0:
        raise FlightDataError(f"{name}: no MAVLink messages in the telemetry log; "
                              "truncated or corrupt file?")
    data = {}
    for kind, r in rows.items():
        a = np.asarray(r, float).reshape(-1, 1 + len(_MESSAGES[kind]))
        data[kind] = {"t": a[:, 0], **{f: a[:, i + 1] for i, f in enumerate(_MESSAGES[kind])}}
    return data, params, beats, firmware, skipped


def read_tlog_streams(path):
    """Read the streams of a MAVLink telemetry log (``.tlog``) into a `LogStreams`."""
    name = Path(path).name
    data, params, beats, firmware, skipped = _scan(path)
    all_t = [c["t"] for c in data.values() if c["t"].size] + [np.array([b[0] for b in beats])]
    t0 = min((float(np.nanmin(t)) for t in all_t if t.size), default=0.0)
    px4 = any(b[2] == _AUTOPILOT_PX4 for b in beats)
    s = LogStreams(log_format=f"MAVLink telemetry log ({'PX4' if px4 else 'ArduPilot'})")
    if skipped:
        s.warn(f"{name}: skipped {skipped} corrupt bytes in the telemetry log", stacklevel=4)
    s.autopilot = firmware or ("PX4" if px4 else "ArduPilot") + " (firmware version not in the log)"
    _read_pressure(data, t0, s, name)
    _read_gps(data, t0, s, name)
    if beats:
        s.airborne_t = np.array([b[0] for b in beats]) - t0
        s.airborne = np.array([b[1] for b in beats])
        s.airborne_source = "HEARTBEAT.base_mode armed flag"
    wind = data["WIND"]
    if wind["t"].size:
        # WIND.direction is where the wind blows FROM; the streams keep the air-mass velocity
        rad = np.radians(wind["direction"])
        s.wind_t, s.wind_source = wind["t"] - t0, "WIND.speed/direction (autopilot)"
        s.wind_n, s.wind_e = -wind["speed"] * np.cos(rad), -wind["speed"] * np.sin(rad)
    for key in AIRSPEED_PARAMS:
        if key in params:
            s.airspeed_scale[key] = params[key]
    for key in _MIN_AIRSPEED_PARAMS:
        if params.get(key, 0) > 0:
            s.min_airspeed_mps, s.min_airspeed_source = params[key], key
            break
    s.log_duration_s = max((float(np.nanmax(t)) - t0 for t in all_t if t.size), default=None)
    return s


def _read_pressure(data, t0, s, name):
    """q_ci, static pressure and the sensor temperatures of SCALED_PRESSURE (and a second
    sensor's q_ci of SCALED_PRESSURE2); refused when no differential pressure is sent."""
    sp = data["SCALED_PRESSURE"]
    if not sp["t"].size:
        raise FlightDataError(f"{name}: no SCALED_PRESSURE messages in the telemetry log: no "
                              "differential pressure to calibrate (stream them: ArduPilot "
                              "SRn_EXTRA3, PX4 the SCALED_PRESSURE stream)")
    if not np.any(np.isfinite(sp["press_diff"]) & (sp["press_diff"] != 0)):
        raise FlightDataError(f"{name}: SCALED_PRESSURE.press_diff is zero in all "
                              f"{sp['t'].size} messages: no airspeed sensor's differential "
                              "pressure to calibrate")
    t = sp["t"] - t0
    s.pressure_t, s.qci_pa = t, sp["press_diff"] * 100.0
    s.pressure_source = "SCALED_PRESSURE.press_diff (hPa)"
    if np.any(sp["press_abs"] > 0):
        s.static_t, s.ps_pa, s.static_source = t, sp["press_abs"] * 100.0, \
            "SCALED_PRESSURE.press_abs (hPa)"
    diff_k, chip_k = _kelvin(sp["temperature_press_diff"]), _kelvin(sp["temperature"])
    if np.isfinite(diff_k).any():
        s.temp_t, s.temp_k = t, diff_k
        s.temp_source = "SCALED_PRESSURE.temperature_press_diff (airspeed sensor)"
    elif np.isfinite(chip_k).any():
        s.temp_t, s.temp_k = t, chip_k
        s.temp_source = "SCALED_PRESSURE.temperature (baro chip)"
    sp2 = data["SCALED_PRESSURE2"]
    if sp2["t"].size and np.any(sp2["press_diff"] != 0):
        s.other_sensors.append((sp2["t"] - t0, sp2["press_diff"] * 100.0,
                                "SCALED_PRESSURE2.press_diff (hPa)"))


def _kelvin(cdeg_c):
    """A cdegC temperature field in K; NaN where it says "not available" (0 or 1 cdegC in
    current MAVLink, -1 / INT16_MAX in older senders) or lies outside -80..+80 degC."""
    c = np.asarray(cdeg_c, float)
    ok = (np.abs(c) > 1.0) & (np.abs(c) <= 8000.0)
    return np.where(ok, c / 100.0 + 273.15, np.nan)


def _read_gps(data, t0, s, name):
    """Ground velocity: GPS_RAW_INT vel/cog (the receiver's), else GLOBAL_POSITION_INT (EKF)."""
    gps = data["GPS_RAW_INT"]
    known = (gps["vel"] != _UNKNOWN_U16) & (gps["cog"] != _UNKNOWN_U16)
    if gps["t"].size and known.any():
        crs = np.radians(gps["cog"] / 100.0)
        spd = gps["vel"] / 100.0
        s.gps_t = gps["t"] - t0
        s.gps_vn, s.gps_ve = spd * np.cos(crs), spd * np.sin(crs)
        s.gps_ok = (gps["fix_type"] >= 3) & known
        s.gps_alt_m = gps["alt"] / 1000.0
        s.gps_source = "GPS_RAW_INT.vel/cog (fix_type>=3)"
        return
    pos = data["GLOBAL_POSITION_INT"]
    if not pos["t"].size:
        return
    s.gps_t = pos["t"] - t0
    s.gps_vn, s.gps_ve = pos["vx"] / 100.0, pos["vy"] / 100.0
    s.gps_ok = np.ones(s.gps_t.size, bool)
    s.gps_alt_m = pos["alt"] / 1000.0
    s.gps_source = "GLOBAL_POSITION_INT.vx/vy (EKF velocity)"
    s.conversions.append("no GPS_RAW_INT ground velocity in the telemetry log: the EKF's "
                         "GLOBAL_POSITION_INT.vx/vy is used, a filtered velocity that may "
                         "lag the receiver's in turns")
