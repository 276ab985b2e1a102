"""Log readers (estimation.logs, .ulog, .dataflash): logs written here with known content, the
shared real/SITL logs (skipped, naming PITOTCAL_SHARED_DATA and the file, when absent), and
every error case."""

import logging
import shutil
import warnings

import numpy as np
import pytest
from logwriters import write_dataflash_bin, write_dataflash_text, write_ulog
from pitotcal.estimation import identify
from synthetic import synthetic_flight, with_ground_rolls

from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.core.units import RHO0_KGM3, incompressible_cas_mps
from pitotcal.io.airborne import gate_ends
from pitotcal.io.logs import load_log, read_log
from pitotcal.io.timebase import onto as _onto

WRITERS = {
    "dataflash-text": (write_dataflash_text, ".log", {}, "ArduPlane V4.1.0"),
    "dataflash-bin": (write_dataflash_bin, ".bin", {}, "ArduPlane V4.1.0"),
    "dataflash-text-old": (write_dataflash_text, ".log", {"old": True}, "ArduPlane"),
    "dataflash-bin-old": (write_dataflash_bin, ".bin", {"old": True}, "ArduPlane"),
    "ulog-newer": (write_ulog, ".ulg", {"newer": True}, "PX4 v1.14.0"),
    "ulog-older": (write_ulog, ".ulg", {"newer": False}, "PX4"),
}


@pytest.fixture(scope="module")
def truth_flight():
    """300 s at 10 Hz, 3 turns, 5 m/s wind from 270, climbing and descending a little."""
    return synthetic_flight(seed=1, n=3000, rate_hz=10.0, model="inverse", k=(0.02, -15.0),
                            vertical=True)


def _write(kind, tmp_path, flight, **extra):
    writer, suffix, kw, _ = WRITERS[kind]
    return writer(tmp_path / f"flight{suffix}", flight, **{**kw, **extra})


@pytest.mark.parametrize("kind", list(WRITERS))
def test_reader_recovers_written_flight_and_calibration(kind, tmp_path, truth_flight):
    flight, truth = truth_flight
    path = _write(kind, tmp_path, flight)
    with pytest.warns(UserWarning, match="sensor temperature, not OAT") as record:
        flog = load_log(path)
    got = flog.flight
    assert got.warnings == tuple(str(w.message) for w in record) and len(got.warnings) == 1
    assert WRITERS[kind][3] in flog.autopilot
    # Pressure samples are kept as logged: same values at the same times since log start
    # (the ULog header's start is 0.1 s before the first message).
    offset = 0.1 if kind.startswith("ulog") else 0.0
    np.testing.assert_allclose(got.qci_pa, np.interp(got.time_s - offset, flight.time_s,
                                                     flight.qci_pa), atol=1e-3)
    np.testing.assert_allclose(got.rho_kgm3, flight.rho_kgm3[0], rtol=1e-6)
    # GPS at 5 Hz interpolated onto 10 Hz: a turning velocity vector's chord error is tiny.
    np.testing.assert_allclose(got.gps_vn_mps, np.interp(got.time_s - offset, flight.time_s,
                                                         flight.gps_vn_mps), atol=0.01)
    assert got.gps_vd_mps is not None and got.n >= flight.n - 2
    result = identify(got, "inverse", air="incompressible")   # the truth is q_c = rho V^2 / 2
    p = truth["parameters"]
    assert result.value("k1") == pytest.approx(p["k1"], abs=2e-3)
    assert result.value("k2") == pytest.approx(p["k2"], abs=1.5)
    assert result.value("wind_speed_mps") == pytest.approx(p["wind_speed_mps"], abs=0.05)
    assert result.value("wind_from_deg") == pytest.approx(p["wind_from_deg"], abs=1.0)


@pytest.mark.parametrize("kind", ["dataflash-bin", "ulog-older"])
def test_gps_fix_lost_span_is_cut_and_logged(kind, tmp_path, truth_flight, caplog):
    flight, _ = truth_flight
    path = _write(kind, tmp_path, flight, gps_invalid=(100.0, 120.0))
    with caplog.at_level(logging.INFO, logger="pitotcal.io.logs"), \
            pytest.warns(UserWarning):
        flog = load_log(path)
    t = flog.flight.time_s
    assert not np.any((t > 100.0) & (t < 120.0))
    assert np.any(t < 100.0) and np.any(t > 120.5)
    assert flog.excluded["no valid GPS fix"] >= 200
    assert "no valid GPS fix" in caplog.text and "no valid GPS fix" in flog.flight.meta["excluded"]


def test_corrupt_bytes_skipped_are_warned_and_recorded(tmp_path, truth_flight):
    path = _write("dataflash-bin", tmp_path, truth_flight[0])
    data = bytearray(path.read_bytes())
    data[len(data) // 2:len(data) // 2] = b"\x00\x11" * 50
    path.write_bytes(bytes(data))
    with pytest.warns(UserWarning, match=r"flight\.bin: skipped 100 corrupt bytes in the log"):
        flight = read_log(path, oat_k=288.0)
    assert flight.warnings == ("flight.bin: skipped 100 corrupt bytes in the log",)


def _damaged(data, seed, n):
    """`n` seeded damaged copies of `data`: 1-200 bytes changed at random, every fourth cut
    at a random length (the sequence the fuzzing that found the readers' escapes used)."""
    import random

    rng = random.Random(seed)
    for trial in range(n):
        b = bytearray(data)
        for _ in range(rng.choice([1, 3, 10, 50, 200])):
            b[rng.randrange(len(b))] = rng.randrange(256)
        yield bytes(b[:rng.randrange(len(b))] if trial % 4 == 0 else b)


def test_mangled_binary_logs_are_refused_in_one_line(tmp_path):
    """A DataFlash binary whose format record names a type pymavlink does not know (it raises a
    bare Exception, "Unsupported format char"), and seeded random damage (bytes changed, the
    file cut): each copy reads or is refused with a FlightDataError naming the file, never a
    traceback; inputs unchanged. The damaged copies read here are those of the seeded
    sequence that once escaped (an empty stream after cleaning, a static stream of NaN, a
    message without a column its FMT record named)."""
    from pitotcal.core.errors import FlightDataError

    flight, _ = synthetic_flight(seed=1, n=1500, rate_hz=10.0)
    data = write_dataflash_bin(tmp_path / "base.bin", flight).read_bytes()
    fmt = data.index(b"\xa3\x95\x80", 3)     # the second FMT record (the first is FMT's own)
    bad = bytearray(data)
    bad[fmt + 9:fmt + 11] = b"Qy"                # its format string: 'y' is no DataFlash type
    copies = {"badfmt.bin": bytes(bad)}
    for trial, b in enumerate(_damaged(data, seed=7, n=172)):
        if trial in (7, 42, 48, 69, 101, 113, 171):
            copies[f"m{trial}.bin"] = b
    for name, content in copies.items():
        path = tmp_path / name
        path.write_bytes(content)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                read_log(path, oat_k=288.0)
            except FlightDataError as exc:
                assert str(exc).startswith(f"{name}: "), exc
            else:
                assert name != "badfmt.bin"
        assert path.read_bytes() == content


def test_mangled_ulog_version_is_no_version(tmp_path):
    """A seeded damaged ULog whose header's ver_sw_release no longer parses as a number
    (pyulog raised TypeError on it): the log reads, with no firmware version, and the
    calibration refuses what the damage left (a one-line error, never a traceback)."""
    from pitotcal.core.errors import PitotcalError
    from pitotcal.estimation import identify

    flight, _ = synthetic_flight(seed=1, n=1500, rate_hz=10.0)
    data = write_ulog(tmp_path / "base.ulg", flight).read_bytes()
    path = tmp_path / "m72.ulg"
    path.write_bytes(list(_damaged(data, seed=11, n=73))[72])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            identify(read_log(path, oat_k=288.0))
        except PitotcalError as exc:
            assert str(exc).startswith("m72.ulg: "), exc


def test_clean_of_a_stream_with_no_finite_sample_is_empty():
    from pitotcal.io.timebase import clean

    t, x = clean(np.array([np.nan, 1.0]), np.array([2.0, np.nan]))
    assert t.size == 0 and x.size == 0


def test_ulog_topic_without_its_timestamp_is_refused_in_one_line(tmp_path, truth_flight):
    """A ULog whose format definition of differential_pressure lost its timestamp field (a
    mangled header): refused naming the file and the field, never a KeyError traceback."""
    from pitotcal.core.errors import FlightDataError

    data = _write("ulog-newer", tmp_path, truth_flight[0]).read_bytes()
    at = data.index(b"timestamp", data.index(b"differential_pressure:"))
    path = tmp_path / "badfield.ulg"
    path.write_bytes(data[:at] + b"timestxmp" + data[at + 9:])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(FlightDataError, match=r"^badfield\.ulg: a logged topic lacks the "
                                                  r"field 'timestamp'"):
            read_log(path, oat_k=288.0)


def test_airspeed_without_pressure_uses_ratio(tmp_path, truth_flight):
    flight, _ = truth_flight
    path = _write("dataflash-text-old", tmp_path, flight, airspeed_only=True)
    with pytest.warns(UserWarning, match=r"airspeed but no differential pressure.*ARSPD_RATIO"):
        flog = load_log(path)
    np.testing.assert_allclose(flog.flight.qci_pa, np.interp(flog.flight.time_s, flight.time_s,
                                                             flight.qci_pa), rtol=1e-6)
    assert "EAS^2 / ARSPD_RATIO" in flog.flight.meta["qc_source"]


def test_window_and_oat_and_autopilot_estimates(tmp_path, truth_flight):
    flight, _ = truth_flight
    path = _write("dataflash-bin", tmp_path, flight)
    flog = load_log(path, start_s=50.0, end_s=150.0, oat_k=250.0)
    t = flog.flight.time_s
    assert t[0] >= 50.0 and t[-1] <= 150.0 and t.size == pytest.approx(1000, abs=2)
    np.testing.assert_allclose(flog.flight.rho_kgm3, 97000.0 / (287.05287 * 250.0))
    assert flog.airspeed_scale == {"ARSPD_RATIO": 2.0}
    wind = flog.autopilot_wind
    assert wind.source.startswith("NKF2") and np.all((wind.time_s >= 50) & (wind.time_s <= 150))
    assert wind.from_deg[0] == pytest.approx(np.degrees(np.arctan2(-0.5, 1.0)) % 360)
    assert "from 333 deg" in flog.flight.meta["autopilot_wind"]
    ulog = load_log(_write("ulog-newer", tmp_path, flight), oat_k=250.0)
    assert ulog.airspeed_scale["ASPD_SCALE"] == 1.0
    assert ulog.airspeed_scale["wind_estimate.tas_scale (last)"] == pytest.approx(1.02)


@pytest.fixture(scope="module")
def rolling_flight():
    """60 s of flight (36-51 m/s) between 10 s standing + 10 s take-off roll and the mirror."""
    flight, _ = synthetic_flight(seed=4, n=600, rate_hz=10.0, model="inverse", k=(0.02, -15.0))
    return with_ground_rolls(flight)


GATE_MPS = 30.0
STATE_SOURCE = {"dataflash-bin": "STAT.isFlying/Armed", "dataflash-text": "STAT.isFlying/Armed",
                "ulog-newer": "vehicle_land_detected.landed and vehicle_status.arming_state"}
PARAM = {"dataflash-bin": "ARSPD_FBW_MIN", "dataflash-text": "ARSPD_FBW_MIN",
         "ulog-newer": "FW_AIRSPD_MIN"}


@pytest.mark.parametrize("kind", list(STATE_SOURCE))
def test_ground_and_rolls_are_cut_on_the_autopilot_state_and_gate(kind, tmp_path,
                                                                  rolling_flight, caplog):
    """The autopilot says flying from 3 s into the take-off roll to 3 s before the landing
    roll ends (as ArduPlane does); its minimum airspeed parameter gates both rolls."""
    flight, roll_start, roll_end = rolling_flight
    flying = (roll_start + 3.0, roll_end - 3.0)
    path = _write(kind, tmp_path, flight, flying=flying, min_airspeed=GATE_MPS)
    with caplog.at_level(logging.INFO, logger="pitotcal.io.logs"), pytest.warns(UserWarning):
        flog = load_log(path)
    got = flog.flight
    offset = 0.1 if kind.startswith("ulog") else 0.0       # the ULog header starts 0.1 s early
    t = flight.time_s
    fast = t[np.flatnonzero(incompressible_cas_mps(flight.qci_pa) >= GATE_MPS)[[0, -1]]]
    np.testing.assert_allclose(got.time_s[[0, -1]], fast + offset, atol=0.11)
    assert incompressible_cas_mps(got.qci_pa[[0, -1]]).min() >= GATE_MPS
    state = f"autopilot not flying ({STATE_SOURCE[kind]})"
    gate = f"take-off or landing: IAS < 30 m/s ({PARAM[kind]})"
    assert list(flog.excluded)[:2] == [state, gate]
    assert flog.excluded[state] == pytest.approx(2 * 130, abs=12)  # 10 s standing + 3 s each
    rolls = (t >= flying[0]) & (t <= flying[1]) & ((t < fast[0]) | (t > fast[1]))
    assert flog.excluded[gate] == pytest.approx(rolls.sum(), abs=3)
    assert f"cut {flog.excluded[gate]} of {flight.n} samples for {gate}" in caplog.text
    assert got.meta["flight_state_source"] == STATE_SOURCE[kind]
    assert got.meta["min_airspeed_mps"] == f"30 ({PARAM[kind]}): take-off and landing gate"
    assert got.meta["excluded"].startswith(f"{state}: {flog.excluded[state]} samples (0.")
    # the gate is computed over the whole log: a window does not move it; 0 turns it off
    inside = load_log(path, start_s=got.time_s[0] - 5.0, oat_k=288.0).flight
    np.testing.assert_array_equal(inside.time_s, got.time_s)
    ungated = load_log(path, min_airspeed_mps=0.0, oat_k=288.0)
    assert gate not in ungated.excluded and ungated.flight.n > got.n + 80


@pytest.mark.parametrize("airborne, fast, cut", [
    ("0111111110", "0001101100", "0110000010"),    # ends cut, the slow dip in between kept
    ("1111011111", "0110000110", "1001011001"),    # two flying spans, each gated
    ("0111100000", "0000000000", "0111100000"),    # never fast: the whole span is cut
    ("0000000000", "1111111111", "0000000000"),    # never flying: nothing to gate
])
def test_gate_cuts_only_the_ends_of_each_flying_span(airborne, fast, cut):
    def bits(text):
        return np.array([c == "1" for c in text])

    got = gate_ends(bits(airborne), bits(fast))
    assert "".join("1" if b else "0" for b in got) == cut


def test_hold_never_uses_future_data_and_linear_never_bridges_gaps():
    ts = np.array([0.0, 0.2, 0.4, 2.0, 2.2])
    v = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    t = np.array([-0.1, 0.0, 0.1, 0.3, 1.05, 2.1, 2.5])
    held, ok = _onto(t, ts, v, 0.6, hold=True)
    np.testing.assert_array_equal(ok, [False, True, True, True, False, True, True])
    np.testing.assert_array_equal(held[ok], [0.0, 0.0, 1.0, 3.0, 4.0])
    lin, ok = _onto(t, ts, v, 0.6, hold=False)
    np.testing.assert_array_equal(ok, [False, True, True, True, False, True, False])
    np.testing.assert_allclose(lin[ok], [0.0, 0.5, 1.5, 3.5])


def _truncated(src, tmp_path, n_bytes, name):
    out = tmp_path / name
    out.write_bytes(src.read_bytes()[:n_bytes])
    return out


ERRORS = [  # (what, make(tmp_path, flight) -> path, message regex)
    ("unknown extension", lambda d, f: write_dataflash_text(d / "x.txt", f),
     r"x\.txt: unknown log extension '\.txt'"),
    ("telemetry log of no messages",
     lambda d, f: (d / "x.tlog").write_bytes(b"0" * 64) and d / "x.tlog",
     r"x\.tlog: no MAVLink messages in the telemetry log; truncated or corrupt"),
    ("missing file", lambda d, f: d / "none.bin", r"none\.bin: no such file"),
    ("empty file", lambda d, f: _truncated(write_dataflash_bin(d / "a.bin", f), d, 0, "e.bin"),
     r"e\.bin: empty file"),
    ("bin truncated to its formats",
     lambda d, f: _truncated(write_dataflash_bin(d / "a.bin", f), d, 700, "t.bin"),
     r"t\.bin: no data messages in the log; truncated or corrupt"),
    ("text truncated to its formats",
     lambda d, f: _truncated(write_dataflash_text(d / "a.log", f), d, 400, "t.log"),
     r"t\.log: no data messages in the log; truncated or corrupt"),
    ("ulog truncated in its header",
     lambda d, f: _truncated(write_ulog(d / "a.ulg", f), d, 10, "t.ulg"),
     r"t\.ulg: not a readable ULog file .*truncated or corrupt"),
    ("ulog truncated before data",
     lambda d, f: _truncated(write_ulog(d / "a.ulg", f), d, 300, "t.ulg"),
     r"t\.ulg: no logged data after the ULog header"),
    ("random bytes", lambda d, f: (d / "r.bin").write_bytes(
        np.random.default_rng(0).bytes(5000)) and d / "r.bin",
     r"r\.bin: no data messages in the log"),
    ("text that is not DataFlash", lambda d, f: (d / "n.log").write_text("hello\n") and d / "n.log",
     r"n\.log: not an ArduPilot DataFlash log"),
    ("window outside the log", lambda d, f: (write_dataflash_bin(d / "a.bin", f), "window"),
     (r"a\.bin: no airspeed samples in the window start_s=1000, end_s=2000; the log's "
      r"airspeed spans 0\.0-299\.9 s")),
    ("flight too short", lambda d, f: (write_dataflash_bin(d / "a.bin", f), "short"),
     r"a\.bin: too little usable airborne data \(\d+ samples over 5\.\d s"),
]


@pytest.mark.parametrize("what,make,match", ERRORS, ids=[e[0] for e in ERRORS])
def test_error_cases(what, make, match, tmp_path, truth_flight):
    path = make(tmp_path, truth_flight[0])
    window = {}
    if isinstance(path, tuple):
        path, kind = path
        window = {"window": dict(start_s=1000.0, end_s=2000.0),
                  "short": dict(start_s=10.0, end_s=15.5)}[kind]
    with pytest.raises(FlightDataError, match=match), pytest.warns(UserWarning) \
            if "short" in what else _nothing():
        read_log(path, **window)


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


@pytest.mark.parametrize("kwargs,match", [
    (dict(gps_resample="cubic"), "gps_resample 'cubic' is not one of linear, hold"),
    (dict(min_qci_pa=-1.0), "min_qci_pa -1 must be >= 0"),
    (dict(gps_latency_s=float("inf")), "gps_latency_s inf must be a finite number"),
    (dict(oat_k=15.0),
     r"oat_k 15 must be >= 150 and <= 350 \(an outside air temperature in kelvin\)"),
    (dict(start_s=20.0, end_s=10.0), r"start_s 20 must be before end_s 10"),
])
def test_argument_errors(kwargs, match, tmp_path):
    with pytest.raises(PitotcalError, match=match) as info:
        load_log(tmp_path / "x.bin", **kwargs)
    assert info.value.param in kwargs             # the CLI shows the flag of this parameter


# --- the shared logs ----------------------------------------------------------------------

def test_sitl_dataflash_calibrates_end_to_end(shared_file):
    """ArduPlane SITL, calm air, ARSPD_RATIO 1.9936: wind < 1 m/s; with the simulator's air
    temperature (ISA, 15 degC at its field) the constant model gives back the ratio through
    0.5 rho0 ratio = 1/(1 - k1)."""
    path = shared_file("ardupilot/arduplane_sitl.log")
    flog = load_log(path, oat_k=288.15)
    assert flog.autopilot.startswith("ArduPlane V4.1.0dev")
    assert flog.airspeed_scale["ARSPD_RATIO"] == pytest.approx(1.9936)
    assert flog.flight.n > 2000 and flog.flight.meta["qc_source"] == "ARSP.DiffPress (Pa)"
    # STAT cuts the ground, ARSPD_FBW_MIN (10 m/s) the take-off roll and the landing; the
    # slowest sample left is the slow leg at ~10 m/s (156-162 s), not the 11 kt roll
    assert flog.excluded == {"autopilot not flying (STAT.isFlying/Armed)": 268,
                             "take-off or landing: IAS < 10 m/s (ARSPD_FBW_MIN)": 224}
    t = flog.flight.time_s
    assert t[0] == pytest.approx(15.5, abs=0.05) and t[-1] == pytest.approx(220.2, abs=0.05)
    assert 9.8 < incompressible_cas_mps(flog.flight.qci_pa).min() < 10.0
    result = identify(flog.flight, "constant")
    assert result.success and result.value("wind_speed_mps") < 1.0
    ratio = 2.0 / (RHO0_KGM3 * (1.0 - result.value("k1")))
    assert ratio == pytest.approx(1.9936, rel=5e-3)
    # With the baro chip's temperature (~34 degC, not OAT) the density is ~6 % low and k1
    # absorbs it: the reader warns about exactly this.
    with pytest.warns(UserWarning, match="BARO.Temp .*not OAT"):
        warm = read_log(path)
    assert np.mean(warm.rho_kgm3) < 0.95 * np.mean(flog.flight.rho_kgm3)


@pytest.mark.parametrize("relpath,match", [
    ("ardupilot/arduplane_no_airspeed.bin",
     r"arduplane_no_airspeed\.bin: no airspeed data \(ARSP\) in the log; ARSPD_ENABLE=0$"),
    ("px4-ulog/sample_log_small.ulg",
     r"sample_log_small\.ulg: too little usable airborne data \(on the ground throughout\?\)"),
])
def test_shared_logs_that_cannot_calibrate(relpath, match, shared_file):
    with pytest.raises(FlightDataError, match=match):
        with pytest.warns(UserWarning) if relpath.endswith(".ulg") else _nothing():
            read_log(shared_file(relpath))


@pytest.mark.parametrize("relpath,n_bytes,match", [
    ("ardupilot/arduplane_sitl.log", 3000, r"no data messages in the log; truncated or corrupt"),
    ("ardupilot/arduplane_no_airspeed.bin", 4000, r"no data messages in the log"),
    ("px4-ulog/sample_log_small.ulg", 5000, r"no logged data after the ULog header"),
])
def test_truncated_copies_of_shared_logs(relpath, n_bytes, match, shared_file, tmp_path):
    src = shared_file(relpath)
    copy = tmp_path / src.name
    shutil.copyfile(src, copy)
    with open(copy, "r+b") as f:
        f.truncate(n_bytes)
    with pytest.raises(FlightDataError, match=match):
        read_log(copy)


def test_ulog_reader_on_real_px4_log(shared_file):
    """The real PX4 v1.11 log: slow differential_pressure falls back on the airspeed topic."""
    with pytest.warns(UserWarning, match="differential_pressure is logged at only 1.0 Hz"):
        with pytest.raises(FlightDataError):
            read_log(shared_file("px4-ulog/sample_log_small.ulg"))
