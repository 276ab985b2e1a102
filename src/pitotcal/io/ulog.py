"""PX4 ULog (`.ulg`) reader: the raw streams of one log, for `pitotcal.io.logs`.

Topics read (pyulog), with the field names of older (v1.11-v1.12) and newer (v1.13+) PX4:

- pressure: ``differential_pressure`` (``differential_pressure_pa``, newer; else
  ``differential_pressure_raw_pa``; the filtered field only if nothing else, since the filter
  lags). When that topic is missing or logged below `MIN_PRESSURE_RATE_HZ` while ``airspeed``
  is faster, q_ci comes from ``airspeed.indicated_airspeed_m_s`` as ½ ρ0 IAS² (a warning says
  so; that IAS already holds PX4's tube and pitot corrections).
- static pressure: ``vehicle_air_data.baro_pressure_pa``; else ``sensor_baro.pressure`` (hPa in
  v1.11-v1.12, Pa later: told apart by its magnitude).
- temperature: the airspeed sensor's (``differential_pressure.temperature``, else
  ``airspeed.air_temperature_celsius``), else the baro's (``vehicle_air_data.baro_temp_celcius``
  / ``ambient_temperature``, ``sensor_baro.temperature``). PX4 logs no outside air temperature:
  these are sensor temperatures, and the reader warns so.
- GPS: ``vehicle_gps_position`` (or ``sensor_gps``): ``vel_n_m_s, vel_e_m_s, vel_d_m_s``, valid
  where ``fix_type >= 3`` and ``vel_ned_valid``; altitude ``alt`` (mm) or ``altitude_msl_m``.
- flight state: ``vehicle_land_detected.landed`` and ``vehicle_status.arming_state`` (flying =
  not landed and armed), and the minimum airspeed parameter FW_AIRSPD_MIN.
- the throttle, for the whole-flight windows (`pitotcal.io.windows`), where logged:
  ``vehicle_thrust_setpoint.xyz[0]`` (v1.14+), else ``actuator_controls_0.control[3]``.
- for comparison only: ``wind_estimate`` (or ``wind``) ``windspeed_north/east`` (the air-mass
  velocity, the way it blows TO) and ``tas_scale``; the parameter ASPD_SCALE (ASPD_SCALE_1).

Times are ``timestamp_sample`` where a topic has it, else ``timestamp`` (µs since boot); the
log's zero is the ULog header's start timestamp.
"""

from pathlib import Path

import numpy as np

from pitotcal.core.errors import FlightDataError
from pitotcal.core.units import RHO0_KGM3

from .resample import hold
from .timebase import clean

MIN_PRESSURE_RATE_HZ = 5.0      # below this a logged pressure topic cannot follow a turn
_PX4_NO_TEMPERATURE = -1000.0   # PX4's "sensor has no thermometer" value


def _topic(ulog, names, instance=None):
    """Data dict of the first of `names` present, instance 0 (or the lowest), else None."""
    for name in names:
        found = [d for d in ulog.data_list if d.name == name]
        if instance is not None:
            found = [d for d in found if d.multi_id == instance]
        if found:
            best = min(found, key=lambda d: d.multi_id)
            return name, best.data
    return None, None


def _times_s(data, t0_us):
    stamp = data["timestamp_sample"] if "timestamp_sample" in data else data["timestamp"]
    return (np.asarray(stamp, dtype=float) - t0_us) * 1e-6


def _first_field(data, names):
    for name in names:
        if name in data:
            return name, np.asarray(data[name], dtype=float)
    return None, None


def _rate_hz(t):
    return (t.size - 1) / (t[-1] - t[0]) if t.size > 1 and t[-1] > t[0] else 0.0


_TOPICS = ("differential_pressure", "airspeed", "vehicle_air_data", "sensor_baro",
           "vehicle_gps_position", "sensor_gps", "wind_estimate", "wind",
           "vehicle_land_detected", "vehicle_status", "vehicle_thrust_setpoint",
           "actuator_controls_0")
_PX4_ARMED = 2                  # vehicle_status.arming_state ARMED (v1.11 to v1.15)


def read_ulog_streams(path):
    """Read the streams of a PX4 ULog file into a `LogStreams` (times in s since log start)."""
    from .streams import LogStreams

    name = Path(path).name
    ulog = _open(path, name)
    s = LogStreams(log_format="PX4 ULog")
    t0 = ulog.start_timestamp
    info = ulog.msg_info_dict
    try:
        version = ulog.get_version_info_str() or ""
    except (TypeError, ValueError):     # a mangled ver_sw_release in the header: no version
        version = ""
    s.autopilot = f"{info.get('sys_name', 'PX4')} {version}".strip()
    if info.get("ver_sw_branch"):
        s.autopilot += f" ({info['ver_sw_branch']})"
    if getattr(ulog, "file_corruption", False):
        s.warn(f"{name}: pyulog found corrupt data in the log; it skipped it", stacklevel=3)
    if ulog.last_timestamp > t0:
        s.log_duration_s = (ulog.last_timestamp - t0) * 1e-6
    if not ulog.data_list:
        raise FlightDataError(f"{name}: no logged data after the ULog header; truncated or "
                              "corrupt file?")
    try:
        _read_pressure(ulog, t0, s, name)
        _read_static_and_temperature(ulog, t0, s)
        _read_gps(ulog, t0, s)
        _read_flight_state(ulog, t0, s)
        _read_autopilot_estimates(ulog, t0, s)
        _read_throttle(ulog, t0, s)
    except KeyError as exc:     # a mangled format definition: a topic without its fields
        raise FlightDataError(f"{name}: a logged topic lacks the field {exc}; corrupt format "
                              "definitions in the ULog header?") from None
    return s


def _open(path, name):
    """The parsed `pyulog.ULog` of the topics read, or a `FlightDataError`."""
    from pyulog import ULog

    from .streams import captured_output

    # pyulog prints its own complaints about corrupt bytes; keep them off our terminal.
    try:
        with captured_output():
            return ULog(str(path), list(_TOPICS))
    except Exception as exc:  # noqa: BLE001 - pyulog raises bare Exception, struct and index errors
        raise FlightDataError(f"{name}: not a readable ULog file ({exc}); "
                              "truncated or corrupt?") from None


def _read_pressure(ulog, t0, s, name):
    """q_ci: the differential pressure itself when it is logged fast enough, else from IAS."""
    _, dp = _topic(ulog, ["differential_pressure"])
    _, asp = _topic(ulog, ["airspeed"])
    dp_t = _times_s(dp, t0) if dp is not None else np.empty(0)
    asp_t = _times_s(asp, t0) if asp is not None else np.empty(0)
    field, dp_pa = (_first_field(dp, ["differential_pressure_pa", "differential_pressure_raw_pa",
                                      "differential_pressure_filtered_pa"])
                    if dp is not None else (None, None))
    slow = dp_pa is not None and _rate_hz(dp_t) < MIN_PRESSURE_RATE_HZ
    if dp_pa is not None and not (slow and _rate_hz(asp_t) > _rate_hz(dp_t)):
        s.pressure_t, s.qci_pa = dp_t, dp_pa
        s.pressure_source = f"differential_pressure.{field} (Pa)"
    elif asp is not None and "indicated_airspeed_m_s" in asp:
        ias = np.asarray(asp["indicated_airspeed_m_s"], dtype=float)
        s.pressure_t = asp_t
        s.qci_pa = 0.5 * RHO0_KGM3 * np.sign(ias) * ias ** 2
        why = (f"differential_pressure is logged at only {_rate_hz(dp_t):.1f} Hz"
               if dp_pa is not None else "the log has no differential_pressure topic")
        s.pressure_source = "airspeed.indicated_airspeed_m_s converted: q_ci = 0.5 rho0 IAS^2"
        s.conversions.append(f"{why}; q_ci from airspeed.indicated_airspeed_m_s as "
                             "0.5*rho0*IAS^2 (IAS already holds PX4's tube corrections)")
    else:
        raise FlightDataError(f"{name}: no airspeed data (differential_pressure or airspeed "
                              "topic) in the log")
    if s.pressure_source.startswith("differential_pressure"):
        _read_other_sensors(ulog, t0, s)


def _read_other_sensors(ulog, t0, s):
    """The differential_pressure instances beyond the first (multi_id 1, 2...): further
    airspeed sensors (`LogStreams.other_sensors`)."""
    found = sorted((d for d in ulog.data_list if d.name == "differential_pressure"),
                   key=lambda d: d.multi_id)
    for d in found[1:]:
        field, dp_pa = _first_field(d.data, ["differential_pressure_pa",
                                             "differential_pressure_raw_pa",
                                             "differential_pressure_filtered_pa"])
        if dp_pa is not None:
            s.other_sensors.append((_times_s(d.data, t0), np.asarray(dp_pa, float),
                                    f"differential_pressure[{d.multi_id}].{field} (Pa)"))


def _read_static_and_temperature(ulog, t0, s):
    """Static pressure, and the sensor temperature used for density (airspeed sensor first)."""
    _, air = _topic(ulog, ["vehicle_air_data"])
    _, baro = _topic(ulog, ["sensor_baro"])
    baro_temp = None
    if air is not None and "baro_pressure_pa" in air:
        s.static_t, s.ps_pa = _times_s(air, t0), np.asarray(air["baro_pressure_pa"], float)
        s.static_source = "vehicle_air_data.baro_pressure_pa"
        tfield, tc = _first_field(air, ["ambient_temperature", "baro_temp_celcius"])
        if tc is not None:
            baro_temp = (s.static_t, tc, f"vehicle_air_data.{tfield}")
    elif baro is not None and "pressure" in baro:
        s.static_t, ps = _times_s(baro, t0), np.asarray(baro["pressure"], float)
        hpa = np.nanmedian(ps) < 2000.0         # PX4 v1.11-v1.12 logged millibar here
        s.ps_pa = ps * 100.0 if hpa else ps
        s.static_source = "sensor_baro.pressure" + (" (hPa, x100)" if hpa else "")
        if "temperature" in baro:
            baro_temp = (s.static_t, np.asarray(baro["temperature"], float),
                         "sensor_baro.temperature")
    candidates = []
    for topic, field, label in (("differential_pressure", "temperature", "airspeed sensor"),
                                ("airspeed", "air_temperature_celsius", "airspeed sensor")):
        _, data = _topic(ulog, [topic])
        if data is not None and field in data:
            candidates.append((_times_s(data, t0), np.asarray(data[field], float),
                               f"{topic}.{field} ({label})"))
    if baro_temp is not None:
        candidates.append((*baro_temp[:2], baro_temp[2] + " (baro sensor)"))
    for t, tc, label in candidates:
        ok = np.isfinite(tc) & (tc > _PX4_NO_TEMPERATURE + 1.0)
        if ok.sum() >= 2:
            s.temp_t, s.temp_k, s.temp_source = t[ok], tc[ok] + 273.15, label
            break


def _read_gps(ulog, t0, s):
    """GPS velocity, its validity (3D fix and valid NED velocity) and altitude."""
    gname, gps = _topic(ulog, ["vehicle_gps_position", "sensor_gps"])
    if gps is None or "vel_n_m_s" not in gps:
        return
    s.gps_t = _times_s(gps, t0)
    s.gps_vn = np.asarray(gps["vel_n_m_s"], float)
    s.gps_ve = np.asarray(gps["vel_e_m_s"], float)
    s.gps_vd = np.asarray(gps["vel_d_m_s"], float) if "vel_d_m_s" in gps else None
    ok = np.ones(s.gps_t.size, bool)
    if "fix_type" in gps:
        ok &= np.asarray(gps["fix_type"]) >= 3
    if "vel_ned_valid" in gps:
        ok &= np.asarray(gps["vel_ned_valid"]) != 0
    s.gps_ok = ok
    if "altitude_msl_m" in gps:
        s.gps_alt_m = np.asarray(gps["altitude_msl_m"], float)
    elif "alt" in gps:
        s.gps_alt_m = np.asarray(gps["alt"], float) * 1e-3
    s.gps_source = f"{gname}.vel_n/e/d_m_s (fix_type>=3, vel_ned_valid)"


def _read_flight_state(ulog, t0, s):
    """Flying = not landed and armed, on the union of both topics' times; FW_AIRSPD_MIN."""
    parts = []
    _, land = _topic(ulog, ["vehicle_land_detected"])
    if land is not None and "landed" in land:
        parts.append((_times_s(land, t0), np.asarray(land["landed"]) == 0,
                      "vehicle_land_detected.landed"))
    _, status = _topic(ulog, ["vehicle_status"])
    if status is not None and "arming_state" in status:
        parts.append((_times_s(status, t0), np.asarray(status["arming_state"]) == _PX4_ARMED,
                      "vehicle_status.arming_state"))
    if parts:
        t = np.unique(np.concatenate([tp for tp, _, _ in parts]))
        flying = np.ones(t.size, bool)
        for tp, state, _ in parts:
            ts, st = clean(tp, state.astype(float))
            held, valid = hold(ts, st, t)
            flying &= np.where(valid, held, st[0]) > 0.5
        s.airborne_t, s.airborne = t, flying
        s.airborne_source = " and ".join(label for _, _, label in parts)
    minimum = ulog.initial_parameters.get("FW_AIRSPD_MIN", 0.0)
    if minimum > 0:
        s.min_airspeed_mps, s.min_airspeed_source = float(minimum), "FW_AIRSPD_MIN"


def _read_throttle(ulog, t0, s):
    """The throttle, 0-1, for the whole-flight windows: the fixed-wing forward thrust set-point
    (``vehicle_thrust_setpoint.xyz[0]``, v1.14+), else ``actuator_controls_0.control[3]``."""
    for topic, field in (("vehicle_thrust_setpoint", "xyz[0]"),
                         ("actuator_controls_0", "control[3]")):
        _, data = _topic(ulog, [topic])
        if data is not None and field in data and np.size(data[field]) >= 2:
            s.throttle_t = _times_s(data, t0)
            s.throttle = np.asarray(data[field], float)
            s.throttle_source = f"{topic}.{field}"
            return


def _read_autopilot_estimates(ulog, t0, s):
    """The autopilot's own wind estimate and airspeed scale, for comparison only."""
    wname, wind = _topic(ulog, ["wind_estimate", "wind"])
    if wind is not None and "windspeed_north" in wind:
        s.wind_t = _times_s(wind, t0)
        s.wind_n = np.asarray(wind["windspeed_north"], float)
        s.wind_e = np.asarray(wind["windspeed_east"], float)
        s.wind_source = f"{wname}.windspeed_north/east"
        sfield, scale = _first_field(wind, ["tas_scale", "tas_scale_validated", "tas_scale_raw"])
        if scale is not None and np.any(scale > 0):
            s.airspeed_scale[f"{wname}.{sfield} (last)"] = float(scale[scale > 0][-1])
    # the scale, and the airspeed sensor model PX4 compensates its IAS with before scaling
    for pname in ("ASPD_SCALE", "ASPD_SCALE_1", "ASPD_SCALE_2", "SENS_EN_SDP3X",
                  "CAL_AIR_CMODEL", "CAL_AIR_TUBELEN", "CAL_AIR_TUBED_MM"):
        if pname in ulog.initial_parameters:
            s.airspeed_scale[pname] = float(ulog.initial_parameters[pname])
