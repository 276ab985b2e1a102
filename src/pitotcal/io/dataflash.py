"""ArduPilot DataFlash reader (binary `.bin`, text `.log`): the raw streams for `pitotcal.io.logs`.

pymavlink's ``mavutil.mavlink_connection`` reads both forms. Messages read, with the field
names of older (3.x) and newer (4.x) firmware:

- ``ARSP`` (first sensor; instance ``I == 0`` where the field exists): ``DiffPress`` (Pa).
  Further sensors (``ARSP`` with ``I`` = 1, ...; older logs ``ASP2``) are kept apart for the
  joint fit of several sensors (`pitotcal.io.sensors`).
  A log with ``Airspeed`` but no ``DiffPress`` is converted with ArduPilot's own relation
  EAS = sqrt(ARSPD_RATIO · Δp), i.e. q_ci = EAS² / ARSPD_RATIO, with a warning.
- ``BARO`` (instance 0): ``Press`` (Pa) and ``Temp`` (°C).
- temperature: ``ARSP.Temp`` (the airspeed sensor's, usually nearer the outside air) when the
  sensor reports one (not identically 0), else ``BARO.Temp``. ArduPilot logs no outside air
  temperature: both are sensor temperatures, and the reader warns so.
- ``GPS`` (instance 0; not GPS2/GPSB): ``Status >= 3`` (3D fix) is valid; velocity from
  ``VelN/VelE`` where present, else ``Spd`` and ``GCrs`` (course over ground, deg true);
  ``VZ`` is the down velocity (NED, positive down). Altitude ``Alt`` (m MSL).
- the EKF wind estimate for comparison: ``XKF2`` (EKF3) or ``NKF2`` (EKF2), core ``C == 0``,
  else the old EKF's ``EKF2``; ``VWN, VWE`` are the air-mass velocity (the way it blows TO).
- the autopilot's flight state: ``STAT.isFlying`` and ``STAT.Armed`` (ArduPlane 3.5+).
- an outside air temperature sensor's ``TEMP.Temp`` (°C, lowest ``Instance``; TEMP_LOG = 1)
  and the throttle ``CTUN.ThO`` (%), where the log has them.
- parameters: ARSPD_RATIO, the minimum airspeed ARSPD_FBW_MIN (AIRSPEED_MIN from 4.5), and
  ARSPD_ENABLE / ARSPD_TYPE to explain a log without airspeed.

Times: ``TimeUS`` (µs since boot); old messages ``TimeMS`` (ms); old ``GPS`` messages keep the
GPS week time in ``TimeMS`` and the boot time in ``T`` (ms), which is used. The log's zero is
the time-stamp of the first data message in it.
"""

import re
from pathlib import Path

import numpy as np

from pitotcal.core.errors import FlightDataError

_HEADER_TYPES = {"FMT", "FMTU", "UNIT", "MULT", "PARM"}
# The minimum airspeed the autopilot flies, m/s (renamed in ArduPilot 4.5): the take-off and
# landing gate of `pitotcal.io.airborne`.
_MIN_AIRSPEED_PARAMS = ("ARSPD_FBW_MIN", "AIRSPEED_MIN")
_FIRMWARE = re.compile(r"^(Ardu\w+|Rover|APM:\w+|ArduPilot)\s+V?\d", re.IGNORECASE)


def _time_field(fields, msg_type):
    if "TimeUS" in fields:
        return "TimeUS", 1e-6
    if msg_type == "GPS" and "T" in fields:
        return "T", 1e-3          # old GPS: TimeMS is GPS time of week
    if "TimeMS" in fields:
        return "TimeMS", 1e-3
    return None, None


class _Collector:
    """Columns of the wanted fields of one message type, in log order."""

    def __init__(self, msg, wanted):
        fields = msg.get_fieldnames()
        self.time_name, self.time_scale = _time_field(fields, msg.get_type())
        self.names = [f for f in wanted if f in fields]
        self.rows = []

    def add(self, msg):
        self.rows.append([getattr(msg, self.time_name, np.nan) if self.time_name else np.nan]
                         + [getattr(msg, f, np.nan) for f in self.names])

    def columns(self):
        a = np.asarray(self.rows, dtype=float).reshape(-1, 1 + len(self.names))
        out = {name: a[:, i + 1] for i, name in enumerate(self.names)}
        out["t"] = a[:, 0] * (self.time_scale or np.nan)
        return out


_WANTED = {
    "ARSP": ("I", "Airspeed", "DiffPress", "Temp", "Health", "H"),
    "ASP2": ("Airspeed", "DiffPress", "Temp"),
    "STAT": ("isFlying", "Armed"),
    "BARO": ("I", "Press", "Temp", "Health", "H"),
    "GPS": ("I", "Status", "Spd", "GCrs", "VZ", "VelN", "VelE", "VelD", "Alt"),
    "XKF2": ("C", "VWN", "VWE"),
    "NKF2": ("C", "VWN", "VWE"),
    "EKF2": ("VWN", "VWE"),
    "CTUN": ("ThO",),
    "TEMP": ("Instance", "I", "Temp"),
}


def _scan(path):
    """Read the wanted messages: ({type: columns}, params, firmware, log start, bytes skipped)."""
    from pymavlink import mavutil

    from .streams import MAVLINK_READ_ERRORS, captured_output, skipped_bytes

    name = Path(path).name
    collectors, firmware, n_data, t_first = {}, None, 0, np.inf
    # pymavlink prints "bad header" / "Skipped N bad bytes" lines: catch them, report once.
    try:
        with captured_output() as chatter:
            log = mavutil.mavlink_connection(str(path), dialect="ardupilotmega")
            if type(log).__name__ not in ("DFReader_binary", "DFReader_text"):
                raise FlightDataError(f"{name}: not an ArduPilot DataFlash log "
                                      f"(pymavlink reads it as {type(log).__name__})")
            while True:
                msg = log.recv_msg()
                if msg is None:
                    break
                mtype = msg.get_type()
                if mtype not in _HEADER_TYPES:
                    n_data += 1
                    if not np.isfinite(t_first):
                        # The log's zero: the first data message's own time-stamp (in file
                        # order, not the minimum: a stray tiny stamp must not shift it).
                        t = getattr(msg, "TimeUS", None)
                        if t:
                            t_first = t * 1e-6
                        elif mtype != "GPS" and getattr(msg, "TimeMS", None):
                            t_first = msg.TimeMS * 1e-3
                if mtype == "MSG" and firmware is None and _FIRMWARE.match(msg.Message or ""):
                    firmware = msg.Message.strip()
                elif mtype == "VER" and firmware is None and hasattr(msg, "FWS"):
                    firmware = str(msg.FWS).strip() or None
                elif mtype in _WANTED:
                    if mtype not in collectors:
                        collectors[mtype] = _Collector(msg, _WANTED[mtype])
                    collectors[mtype].add(msg)
            params = dict(getattr(log, "params", {}) or {})
            log.close()
    except FlightDataError:
        raise
    except MAVLINK_READ_ERRORS as exc:
        raise FlightDataError(f"{name}: not a readable DataFlash log ({exc}); "
                              "truncated or corrupt?") from None
    skipped = skipped_bytes(chatter.getvalue())
    if n_data == 0:
        raise FlightDataError(f"{name}: no data messages in the log; "
                              "truncated or corrupt file?")
    data = {k: c.columns() for k, c in collectors.items()}
    return data, params, firmware, (0.0 if not np.isfinite(t_first) else t_first), skipped


def _instance0(cols, key="I"):
    if key in cols and cols[key].size:
        first = np.nanmin(cols[key])
        keep = cols[key] == first
        return {k: v[keep] for k, v in cols.items()}
    return cols


def _no_airspeed_message(name, params):
    said = [f"{p}={params[p]:g}" for p in ("ARSPD_ENABLE", "ARSPD_TYPE", "ARSPD_USE")
            if p in params]
    return (f"{name}: no airspeed data (ARSP) in the log"
            + (f"; {', '.join(said[:1])}" if said else ""))


def read_dataflash_streams(path):
    """Read the streams of an ArduPilot DataFlash `.bin` / `.log` into a `LogStreams`."""
    from .streams import LogStreams

    name = Path(path).name
    data, params, firmware, t0, skipped = _scan(path)
    fmt = "binary" if Path(path).suffix.lower() == ".bin" else "text"
    s = LogStreams(log_format=f"ArduPilot DataFlash {fmt}")
    if skipped:
        s.warn(f"{name}: skipped {skipped} corrupt bytes in the log", stacklevel=4)
    s.autopilot = firmware or "ArduPilot (firmware version not logged)"
    try:
        arsp = _read_pressure(data, params, t0, s, name)
        _read_other_sensors(data, t0, s)
        _read_static_and_temperature(data, arsp, t0, s)
        _read_gps(data, t0, s)
        _read_flight_state(data, params, t0, s)
        _read_oat_and_throttle(data, t0, s)
    except KeyError as exc:     # a mangled FMT record: a message without its columns
        raise FlightDataError(f"{name}: a logged message lacks the column {exc}; corrupt "
                              "format (FMT) records?") from None
    for wtype in ("XKF2", "NKF2", "EKF2"):
        wind = data.get(wtype)
        if wind is not None and wind["t"].size and "VWN" in wind and "VWE" in wind:
            wind = _instance0(wind, "C")
            s.wind_t, s.wind_n, s.wind_e = wind["t"] - t0, wind["VWN"], wind["VWE"]
            s.wind_source = f"{wtype}.VWN/VWE (EKF)"
            break
    s.log_duration_s = max((c["t"][-1] - t0 for c in data.values() if c["t"].size),
                           default=None)
    return s


def _read_pressure(data, params, t0, s, name):
    """q_ci from ARSP (DiffPress, else Airspeed through ARSPD_RATIO); returns the ARSP columns."""
    arsp = data.get("ARSP")
    if arsp is None or arsp["t"].size == 0:
        raise FlightDataError(_no_airspeed_message(name, params))
    arsp = _instance0(arsp)
    s.pressure_t = arsp["t"] - t0
    ratio = params.get("ARSPD_RATIO")
    if ratio is not None:
        s.airspeed_scale["ARSPD_RATIO"] = float(ratio)
    if params.get("ARSPD2_RATIO") is not None:      # the second sensor's
        s.airspeed_scale["ARSPD2_RATIO"] = float(params["ARSPD2_RATIO"])
    if "DiffPress" in arsp:
        s.qci_pa = arsp["DiffPress"]
        s.pressure_source = "ARSP.DiffPress (Pa)"
    elif "Airspeed" in arsp:
        if not ratio or ratio <= 0:
            raise FlightDataError(f"{name}: ARSP has Airspeed but no DiffPress, and no "
                                  "ARSPD_RATIO parameter to convert it")
        eas = arsp["Airspeed"]
        s.qci_pa = eas * np.abs(eas) / ratio
        s.pressure_source = f"ARSP.Airspeed converted: q_ci = EAS^2 / ARSPD_RATIO ({ratio:g})"
        s.conversions.append("the log has airspeed but no differential pressure: q_ci = "
                             f"ARSP.Airspeed^2 / ARSPD_RATIO ({ratio:g}), ArduPilot's "
                             "EAS = sqrt(ratio*dp)")
    else:
        raise FlightDataError(f"{name}: ARSP has neither DiffPress nor Airspeed")
    return arsp


def _read_other_sensors(data, t0, s):
    """The airspeed sensors beyond the first: ARSP instances I > 0, or an older log's ASP2,
    each with a differential pressure (`LogStreams.other_sensors`)."""
    arsp = data.get("ARSP")
    if arsp is not None and "I" in arsp and "DiffPress" in arsp:
        for inst in np.unique(arsp["I"][np.isfinite(arsp["I"])])[1:]:
            rows = arsp["I"] == inst
            s.other_sensors.append((arsp["t"][rows] - t0, arsp["DiffPress"][rows],
                                    f"ARSP[{inst:g}].DiffPress (Pa)"))
    asp2 = data.get("ASP2")
    if not s.other_sensors and asp2 is not None and asp2["t"].size and "DiffPress" in asp2:
        s.other_sensors.append((asp2["t"] - t0, asp2["DiffPress"], "ASP2.DiffPress (Pa)"))


def _read_static_and_temperature(data, arsp, t0, s):
    """BARO static pressure; the airspeed sensor's temperature if it reports one, else BARO's."""
    baro = data.get("BARO")
    if baro is not None and "Press" in baro and baro["t"].size:
        baro = _instance0(baro)
        s.static_t, s.ps_pa, s.static_source = baro["t"] - t0, baro["Press"], "BARO.Press"
    if "Temp" in arsp and np.any(arsp["Temp"] != 0):
        s.temp_t, s.temp_k = s.pressure_t, arsp["Temp"] + 273.15
        s.temp_source = "ARSP.Temp (airspeed sensor)"
    elif baro is not None and "Temp" in baro and baro["t"].size:
        s.temp_t, s.temp_k = baro["t"] - t0, baro["Temp"] + 273.15
        s.temp_source = "BARO.Temp (baro sensor)"


def _read_gps(data, t0, s):
    """GPS velocity (VelN/VelE, else Spd and GCrs), VZ, validity (Status >= 3), altitude."""
    gps = data.get("GPS")
    if gps is None or not gps["t"].size:
        return
    gps = _instance0(gps)
    s.gps_t = gps["t"] - t0
    if "VelN" in gps and "VelE" in gps:
        s.gps_vn, s.gps_ve = gps["VelN"], gps["VelE"]
        s.gps_source = "GPS.VelN/VelE"
    else:
        crs = np.radians(gps["GCrs"])
        s.gps_vn, s.gps_ve = gps["Spd"] * np.cos(crs), gps["Spd"] * np.sin(crs)
        s.gps_source = "GPS.Spd/GCrs"
    s.gps_vd = gps.get("VelD", gps.get("VZ"))
    s.gps_source += "/VZ" if "VZ" in gps and "VelD" not in gps else ""
    s.gps_source += " (Status>=3)"
    s.gps_ok = gps["Status"] >= 3 if "Status" in gps else np.ones(s.gps_t.size, bool)
    s.gps_alt_m = gps.get("Alt")


def _read_oat_and_throttle(data, t0, s):
    """A temperature sensor's ``TEMP.Temp`` (degC; the lowest instance) as the outside air
    temperature, and ``CTUN.ThO`` (percent) as the throttle, where the log has them."""
    temp = data.get("TEMP")
    if temp is not None and temp["t"].size and "Temp" in temp:
        temp = _instance0(temp, "Instance" if "Instance" in temp else "I")
        ok = np.isfinite(temp["Temp"])
        if ok.sum() >= 2:
            s.oat_t, s.oat_k = temp["t"][ok] - t0, temp["Temp"][ok] + 273.15
            s.oat_source = "TEMP.Temp (temperature sensor)"
    ctun = data.get("CTUN")
    if ctun is not None and ctun["t"].size and "ThO" in ctun:
        s.throttle_t, s.throttle, s.throttle_source = ctun["t"] - t0, ctun["ThO"], "CTUN.ThO"


def _read_flight_state(data, params, t0, s):
    """The autopilot's flying state (STAT.isFlying and Armed) and minimum airspeed parameter."""
    stat = data.get("STAT")
    if stat is not None and stat["t"].size and "isFlying" in stat:
        flying = stat["isFlying"] != 0
        if "Armed" in stat:
            flying &= stat["Armed"] != 0
        s.airborne_t, s.airborne = stat["t"] - t0, flying
        s.airborne_source = "STAT.isFlying/Armed" if "Armed" in stat else "STAT.isFlying"
    for pname in _MIN_AIRSPEED_PARAMS:
        if params.get(pname, 0) > 0:
            s.min_airspeed_mps, s.min_airspeed_source = float(params[pname]), pname
            break
