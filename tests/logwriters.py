"""Writers of small autopilot logs with known content, for the log-reader tests.

Neither pymavlink nor pyulog writes a log from scratch (pyulog's `write_ulog` only re-writes a
parsed file), so these write the formats directly: ArduPilot DataFlash text and binary (FMT
messages, then data) and PX4 ULog (header, flag bits, formats, info, parameters, subscriptions,
data). Each takes a `Flight` (tests/synthetic.py) and writes it the way an autopilot logs it:
pressure at the flight's own rate, GPS every `gps_every`-th sample, baro and wind slower.
"""

import struct

import numpy as np

from pitotcal.core.units import R_AIR_JKGK

PS_PA = 97000.0            # static pressure written to the logs
BOOT_S = 20.0              # boot time of the first message


def _temperature_k(flight):
    return PS_PA / (R_AIR_JKGK * flight.rho_kgm3)


def _gps_rows(flight, gps_every, invalid=None):
    """(index, status) of the GPS samples; `invalid` = (t0, t1) span logged with no fix."""
    idx = np.arange(0, flight.n, gps_every)
    status = np.full(idx.size, 6 if invalid is None else 3)
    if invalid is not None:
        t = flight.time_s[idx]
        status[(t >= invalid[0]) & (t <= invalid[1])] = 1
    return idx, status


# --- ArduPilot DataFlash ------------------------------------------------------------------

def _inside(t, span):
    return np.zeros(t.size, bool) if span is None else (t >= span[0]) & (t <= span[1])


def dataflash_records(flight, gps_every=2, firmware="ArduPlane V4.1.0 (test)", ratio=2.0,
                      old=False, gps_invalid=None, airspeed_only=False, flying=None,
                      min_airspeed=None, oat_sensor_c=None, throttle_pct=None,
                      second=None, second_ratio=2.0, second_as="ARSP"):
    """(formats, rows) of an ArduPilot log of `flight`: formats {name: (id, fmt, columns)}.

    `old`: ms time stamps (``TimeMS``), GPS velocity as VelN/VelE; `airspeed_only`: ARSP has
    Airspeed (EAS = sqrt(ratio * dp)) but no DiffPress, as some firmware logs it. `flying`:
    (t0, t1) of the flight's time_s when STAT (5 Hz) says isFlying and Armed (no STAT when
    None); `min_airspeed`: the ARSPD_FBW_MIN parameter, m/s. `oat_sensor_c`: a temperature
    sensor's TEMP messages (1 Hz, degC); `throttle_pct`: CTUN.ThO per sample (5 Hz), %.
    `second`: q_ci of a second airspeed sensor, Pa, logged as ARSP instance I = 1 (the first as
    I = 0; ARSPD2_RATIO `second_ratio`), or with `second_as` "ASP2" as older firmware logs it
    (ASP2, no I field).
    """
    t_us = np.round((flight.time_s - flight.time_s[0] + BOOT_S) * 1e6).astype(np.int64)
    time_col, tscale, tfmt = ("TimeMS", 1e-3, "I") if old else ("TimeUS", 1.0, "Q")

    def stamp(i):
        return int(round(t_us[i] * tscale))

    arsp_cols = ["Airspeed", "Temp"] if airspeed_only else ["Airspeed", "DiffPress", "Temp"]
    inst = [] if second is None or second_as == "ASP2" else ["I"]
    # Old (3.x) GPS messages keep the GPS week time in TimeMS and the boot time in T.
    gps_cols = (["Status", "Week", "VelN", "VelE", "VZ", "Alt", "T"] if old
                else ["Status", "GMS", "GWk", "Spd", "GCrs", "VZ", "Alt"])
    formats = {
        "PARM": (129, "QNf", "TimeUS,Name,Value"),
        "MSG": (134, tfmt + "Z", f"{time_col},Message"),
        "ARSP": (165, tfmt + "B" * len(inst) + "f" * len(arsp_cols),
                 ",".join([time_col] + inst + arsp_cols)),
        "BARO": (139, tfmt + "ff", f"{time_col},Press,Temp"),
        "GPS": (130, ("IBHffffI" if old else "QBIHffff"), ",".join([time_col] + gps_cols)),
        "NKF2": (65, tfmt + "Bff", f"{time_col},C,VWN,VWE"),
    }
    if second is not None and second_as == "ASP2":
        formats["ASP2"] = (166, tfmt + "fff", f"{time_col},Airspeed,DiffPress,Temp")
    if flying is not None:
        formats["STAT"] = (5, tfmt + "BB", f"{time_col},isFlying,Armed")
    if oat_sensor_c is not None:
        formats["TEMP"] = (6, tfmt + "Bf", f"{time_col},Instance,Temp")
    if throttle_pct is not None:
        formats["CTUN"] = (7, tfmt + "f", f"{time_col},ThO")
    rows = [(0, "PARM", [int(t_us[0]) - 1000, "ARSPD_RATIO", ratio]),
            (0, "PARM", [int(t_us[0]) - 1000, "ARSPD_TYPE", 1.0]),
            (0, "MSG", [stamp(0), firmware])]
    if min_airspeed is not None:
        rows.append((0, "PARM", [int(t_us[0]) - 1000, "ARSPD_FBW_MIN", float(min_airspeed)]))
    if second is not None:
        rows.append((0, "PARM", [int(t_us[0]) - 1000, "ARSPD2_RATIO", second_ratio]))
    in_flight = _inside(flight.time_s, flying)
    temp_c = _temperature_k(flight) - 273.15
    eas = np.sqrt(ratio * flight.qci_pa)
    for i in range(flight.n):
        vals = [eas[i], temp_c[i]] if airspeed_only else [eas[i], flight.qci_pa[i], temp_c[i]]
        rows.append((t_us[i], "ARSP", [stamp(i)] + [0] * len(inst) + vals))
        if second is not None:
            rows.append((t_us[i], second_as, [stamp(i)] + [1] * len(inst) + [
                np.sqrt(second_ratio * second[i]), second[i], temp_c[i]]))
        if i % 5 == 0:
            rows.append((t_us[i], "BARO", [stamp(i), PS_PA, temp_c[i]]))
        if i % 10 == 0:
            rows.append((t_us[i], "NKF2", [stamp(i), 0, -1.0, 0.5]))
        if flying is not None and i % 2 == 0:
            rows.append((t_us[i], "STAT", [stamp(i), int(in_flight[i]), int(in_flight[i])]))
        if oat_sensor_c is not None and i % 10 == 0:
            rows.append((t_us[i], "TEMP", [stamp(i), 0, float(oat_sensor_c)]))
        if throttle_pct is not None and i % 2 == 0:
            rows.append((t_us[i], "CTUN", [stamp(i), float(throttle_pct[i])]))
    idx, status = _gps_rows(flight, gps_every, gps_invalid)
    vd = flight.gps_vd_mps if flight.gps_vd_mps is not None else np.zeros(flight.n)
    for i, st in zip(idx, status):
        vn, ve = flight.gps_vn_mps[i], flight.gps_ve_mps[i]
        gps_ms = 300_000_000 + int(t_us[i] // 1000)
        if old:
            vals = [gps_ms, int(st), 2088, vn, ve, vd[i], 100.0, stamp(i)]
        else:
            vals = [stamp(i), int(st), gps_ms, 2088, np.hypot(vn, ve),
                    np.degrees(np.arctan2(ve, vn)) % 360, vd[i], 100.0]
        rows.append((t_us[i], "GPS", vals))
    rows.sort(key=lambda r: r[0])
    return formats, [(name, vals) for _, name, vals in rows]


def write_dataflash_text(path, flight, **kw):
    formats, rows = dataflash_records(flight, **kw)
    lines = ["FMT, 128, 89, FMT, BBnNZ, Type,Length,Name,Format,Columns"]
    for name, (mid, fmt, cols) in formats.items():
        length = 3 + struct.calcsize("<" + _struct(fmt))
        lines.append(f"FMT, {mid}, {length}, {name}, {fmt}, {cols}")
    for name, vals in rows:
        lines.append(", ".join([name] + [f"{v:.9g}" if isinstance(v, float) else str(v)
                                         for v in vals]))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


_STRUCT = {"Q": "Q", "I": "I", "H": "H", "B": "B", "f": "f", "N": "16s", "Z": "64s", "n": "4s"}


def _struct(fmt):
    return "".join(_STRUCT[c] for c in fmt)


def write_dataflash_bin(path, flight, **kw):
    formats, rows = dataflash_records(flight, **kw)
    out = bytearray()
    head = b"\xa3\x95"

    def fmt_msg(mid, name, fmt, cols):
        length = 3 + struct.calcsize("<" + _struct(fmt))
        return head + bytes([128]) + struct.pack("<BB4s16s64s", mid, length, name.encode(),
                                                 fmt.encode(), cols.encode())

    out += fmt_msg(128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")
    for name, (mid, fmt, cols) in formats.items():
        out += fmt_msg(mid, name, fmt, cols)
    for name, vals in rows:
        mid, fmt, _ = formats[name]
        packed = [v.encode() if isinstance(v, str) else (int(v) if c in "QIHB" else float(v))
                  for v, c in zip(vals, fmt)]
        out += head + bytes([mid]) + struct.pack("<" + _struct(fmt), *packed)
    with open(path, "wb") as f:
        f.write(bytes(out))
    return path


# --- PX4 ULog -----------------------------------------------------------------------------

_ULOG_TYPES = {"uint64_t": "Q", "float": "f", "uint8_t": "B", "int32_t": "i", "bool": "B"}


def _msg(kind, payload):
    return struct.pack("<HB", len(payload), ord(kind)) + payload


def write_ulog(path, flight, gps_every=2, newer=True, gps_invalid=None,
               firmware_release=0x010E0000 | 0xFF, flying=None, min_airspeed=None,
               second=None):
    """A PX4 ULog of `flight`: newer (v1.13+) or older (v1.11) topic and field names.

    `flying`: (t0, t1) of the flight's time_s when vehicle_land_detected says not landed
    (armed from the first sample; no such topics when None); `min_airspeed`: FW_AIRSPD_MIN.
    `second`: q_ci of a second airspeed sensor, Pa: differential_pressure instance 1.
    """
    t_us = np.round((flight.time_s - flight.time_s[0] + BOOT_S) * 1e6).astype(np.int64)
    temp_c = _temperature_k(flight) - 273.15
    dp_field = "differential_pressure_pa" if newer else "differential_pressure_raw_pa"
    topics = {
        "differential_pressure": [("uint64_t", "timestamp"), ("float", dp_field),
                                  ("float", "temperature")],
        "vehicle_gps_position": [("uint64_t", "timestamp"), ("float", "vel_n_m_s"),
                                 ("float", "vel_e_m_s"), ("float", "vel_d_m_s"),
                                 ("uint8_t", "fix_type"), ("bool", "vel_ned_valid"),
                                 ("int32_t", "alt")],
        "wind_estimate": [("uint64_t", "timestamp"), ("float", "windspeed_north"),
                          ("float", "windspeed_east"), ("float", "tas_scale")],
    }
    if flying is not None:
        topics["vehicle_land_detected"] = [("uint64_t", "timestamp"), ("bool", "landed")]
        topics["vehicle_status"] = [("uint64_t", "timestamp"), ("uint8_t", "arming_state")]
    if newer:
        topics["vehicle_air_data"] = [("uint64_t", "timestamp"), ("float", "baro_pressure_pa"),
                                      ("float", "ambient_temperature")]
    else:
        topics["sensor_baro"] = [("uint64_t", "timestamp"), ("float", "pressure"),
                                 ("float", "temperature")]
    out = bytearray(b"ULog\x01\x12\x35" + bytes([1]) + struct.pack("<Q", int(t_us[0]) - 100000))
    out += _msg("B", bytes(16) + struct.pack("<3Q", 0, 0, 0))
    for name, fields in topics.items():
        out += _msg("F", f"{name}:{''.join(f'{t} {n};' for t, n in fields)}".encode())

    def info(key_type, key, value):
        k = f"{key_type} {key}".encode()
        return bytes([len(k)]) + k + value

    out += _msg("I", info("char[3]", "sys_name", b"PX4"))
    out += _msg("I", info("uint32_t", "ver_sw_release", struct.pack("<I", firmware_release)))
    out += _msg("P", info("float", "ASPD_SCALE", struct.pack("<f", 1.0)))
    if min_airspeed is not None:
        out += _msg("P", info("float", "FW_AIRSPD_MIN", struct.pack("<f", min_airspeed)))
    ids = {}
    for i, name in enumerate(topics):
        ids[name] = i
        out += _msg("A", struct.pack("<BH", 0, i) + name.encode())
    if second is not None:           # the same topic, multi_id 1
        ids["differential_pressure#1"] = len(topics)
        out += _msg("A", struct.pack("<BH", 1, len(topics)) + b"differential_pressure")

    def data(name, values):
        fmt = "<" + "".join(_ULOG_TYPES[t] for t, _ in topics[name.split("#")[0]])
        return _msg("D", struct.pack("<H", ids[name]) + struct.pack(fmt, *values))

    idx_gps, status = _gps_rows(flight, gps_every, gps_invalid)
    gps_at = dict(zip(idx_gps, status))
    in_flight = _inside(flight.time_s, flying)
    vd = flight.gps_vd_mps if flight.gps_vd_mps is not None else np.zeros(flight.n)
    for i in range(flight.n):
        t = int(t_us[i])
        out += data("differential_pressure", [t, flight.qci_pa[i], temp_c[i]])
        if second is not None:
            out += data("differential_pressure#1", [t, second[i], temp_c[i]])
        if i % 5 == 0:
            baro = "vehicle_air_data" if newer else "sensor_baro"
            ps = PS_PA if newer else PS_PA / 100.0          # v1.11 logged hPa here
            out += data(baro, [t, ps, temp_c[i]])
        if i in gps_at:
            fix = 3 if gps_at[i] >= 3 else 0
            out += data("vehicle_gps_position", [t, flight.gps_vn_mps[i], flight.gps_ve_mps[i],
                                                 vd[i], fix, int(fix >= 3), 100000])
        if i % 10 == 0:
            out += data("wind_estimate", [t, -1.0, 0.5, 1.02])
        if flying is not None and i % 10 == 0:
            out += data("vehicle_land_detected", [t, int(not in_flight[i])])
            out += data("vehicle_status", [t, 2])
    with open(path, "wb") as f:
        f.write(bytes(out))
    return path


# --- MAVLink telemetry log ----------------------------------------------------------------

TLOG_T0_S = 1.7e9            # the ground station's clock (s since 1970) at the first message


def write_tlog(path, flight, gps_every=2, *, press_diff=True, gps_raw=True, second=None,
               params=None, armed=None, autopilot=3):
    """A MAVLink telemetry log of `flight` as a ground station records it: each message after
    its 8-byte big-endian arrival time (µs since 1970), encoded by pymavlink.

    SCALED_PRESSURE per sample (`press_diff` False: zero, as a vehicle without an airspeed
    sensor sends it), GPS_RAW_INT every `gps_every`-th sample (`gps_raw` False: only
    GLOBAL_POSITION_INT), a HEARTBEAT a second (armed inside `armed` = (t0, t1), always when
    None), PARAM_VALUE of `params` and a ground station's own heartbeat; `second`: q_ci of a
    second sensor (SCALED_PRESSURE2), Pa.
    """
    from pymavlink.dialects.v20 import ardupilotmega as mavlink

    mav = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    t = flight.time_s - flight.time_s[0]
    temp_c = _temperature_k(flight) - 273.15
    out = bytearray()

    def put(t_s, link, msg):
        out.extend(struct.pack(">Q", int(round((TLOG_T0_S + t_s) * 1e6))) + msg.pack(link))

    for i, (name, value) in enumerate((params or {}).items()):
        put(0.0, mav, mav.param_value_encode(name.encode(), float(value), 9, len(params), i))
    vd = flight.gps_vd_mps if flight.gps_vd_mps is not None else np.zeros(flight.n)
    alt = flight.alt_m if flight.alt_m is not None else np.full(flight.n, 100.0)
    rate = 1.0 / max(float(np.median(np.diff(t))), 1e-3)
    for i in range(flight.n):
        ms = int(round(t[i] * 1000.0))
        if i % max(int(round(rate)), 1) == 0:
            on = armed is None or armed[0] <= flight.time_s[i] <= armed[1]
            put(t[i], mav, mav.heartbeat_encode(1, autopilot, 128 if on else 0, 0, 4, 3))
            put(t[i], gcs, gcs.heartbeat_encode(6, 8, 0, 0, 0, 3))
        dp = flight.qci_pa[i] / 100.0 if press_diff else 0.0
        put(t[i], mav, mav.scaled_pressure_encode(ms, PS_PA / 100.0, dp,
                                                  int(round(temp_c[i] * 100)), 0))
        if second is not None:
            put(t[i], mav, mav.scaled_pressure2_encode(ms, PS_PA / 100.0, second[i] / 100.0,
                                                       int(round(temp_c[i] * 100)), 0))
        if i % gps_every == 0:
            vn, ve = flight.gps_vn_mps[i], flight.gps_ve_mps[i]
            if gps_raw:
                cog = int(round(np.degrees(np.arctan2(ve, vn)) % 360.0 * 100)) % 36000
                put(t[i], mav, mav.gps_raw_int_encode(
                    ms * 1000, 3, 0, 0, int(round(alt[i] * 1000)), 100, 100,
                    int(round(np.hypot(vn, ve) * 100)), cog, 10))
            put(t[i], mav, mav.global_position_int_encode(
                ms, 0, 0, int(round(alt[i] * 1000)), 0, int(round(vn * 100)),
                int(round(ve * 100)), int(round(vd[i] * 100)), 0))
    with open(path, "wb") as f:
        f.write(bytes(out))
    return path
