"""MAVLink telemetry logs (`pitotcal.io.tlog`): tlogs written here from simulated flights with
pymavlink's encoder, read and calibrated against the truth, and the ones that cannot calibrate
refused in one line."""

import numpy as np
import pytest
from logwriters import write_tlog
from synthetic import synthetic_flight

from pitotcal.core.errors import FlightDataError
from pitotcal.estimation import identify
from pitotcal.io.logs import load_log
from pitotcal.io.param_files import read_flight_and_parameters


@pytest.fixture(scope="module")
def truth_flight():
    """300 s at 10 Hz, 3 turns, 5 m/s wind from 270, in 0.3 m/s turbulence."""
    return synthetic_flight(seed=3, n=3000, rate_hz=10.0, k=(0.02, -15.0), turbulence_mps=0.3)


def test_tlog_calibrates_within_its_bounds(tmp_path, truth_flight):
    flight, truth = truth_flight
    path = write_tlog(tmp_path / "flight.tlog", flight, params={"ARSPD_RATIO": 1.9936})
    with pytest.warns(UserWarning, match="baro chip.*not OAT"):
        log = load_log(path)
    got = log.flight
    assert log.log_format == "MAVLink telemetry log (ArduPilot)"
    assert log.airspeed_scale == {"ARSPD_RATIO": pytest.approx(1.9936)}
    assert got.meta["qc_source"].startswith("SCALED_PRESSURE.press_diff")
    assert got.meta["gps_source"].startswith("GPS_RAW_INT.vel/cog")
    assert got.meta["flight_state_source"] == "HEARTBEAT.base_mode armed flag"
    # float32 hPa: q_ci as sent, to 1e-5 of its value
    np.testing.assert_allclose(got.qci_pa, np.interp(got.time_s, flight.time_s, flight.qci_pa),
                               rtol=1e-5)
    result = identify(got, air="incompressible")
    for name in ("k1", "k2", "wind_speed_mps"):
        assert abs(result.value(name) - truth["parameters"][name]) < 2.5 * result.stddev(name)


def test_tlog_without_gps_raw_uses_the_ekf_velocity_and_says_so(tmp_path, truth_flight):
    flight, _ = truth_flight
    path = write_tlog(tmp_path / "ekf.tlog", flight, gps_raw=False)
    with pytest.warns(UserWarning, match="GLOBAL_POSITION_INT.vx/vy is used"):
        got = load_log(path).flight
    assert "EKF velocity" in got.meta["gps_source"]


def test_tlog_armed_flag_is_the_flight_state(tmp_path, truth_flight):
    flight, _ = truth_flight
    path = write_tlog(tmp_path / "armed.tlog", flight, armed=(50.0, 250.0))
    with pytest.warns(UserWarning):
        got = load_log(path).flight
    assert got.time_s[0] >= 49.0 and got.time_s[-1] <= 251.0


def test_px4_tlog_gives_the_px4_parameter(tmp_path, truth_flight):
    flight, _ = truth_flight
    path = write_tlog(tmp_path / "px4.tlog", flight, autopilot=12,
                      params={"ASPD_SCALE_1": 1.0})
    with pytest.warns(UserWarning):
        _, autopilot, params = read_flight_and_parameters(path)
    assert autopilot == "PX4" and params == {"ASPD_SCALE_1": 1.0}


@pytest.mark.parametrize("make, match", [
    (lambda d, f: write_tlog(d / "nodp.tlog", f, press_diff=False),
     r"nodp\.tlog: SCALED_PRESSURE\.press_diff is zero in all 3000 messages"),
    (lambda d, f: _cut(write_tlog(d / "a.tlog", f), d / "short.tlog", 3000),
     r"short\.tlog: too little usable airborne data"),
    (lambda d, f: _garbled(d / "noise.tlog"),
     r"noise\.tlog: (not a readable MAVLink telemetry log|no MAVLink messages)"),
])
def test_tlogs_that_cannot_calibrate_are_refused_in_one_line(make, match, tmp_path,
                                                              truth_flight):
    path = make(tmp_path, truth_flight[0])
    with pytest.raises(FlightDataError, match=match) as err:
        load_log(path)
    assert "\n" not in str(err.value)


def _cut(src, dst, n_bytes):
    dst.write_bytes(src.read_bytes()[:n_bytes])
    return dst


def _garbled(path):
    path.write_bytes(np.random.default_rng(5).integers(0, 256, 500, dtype=np.uint8).tobytes())
    return path


def test_second_sensors_are_read_each_on_its_own_and_a_dead_one_is_left_out(tmp_path,
                                                                           truth_flight):
    """ARSP instance 1 (an older log's ASP2), a PX4 differential_pressure instance 1 and
    SCALED_PRESSURE2 each become their own flight; a dead second sensor is left out with a
    warning."""
    from logwriters import write_dataflash_bin, write_ulog

    from pitotcal.io import read_flight
    from pitotcal.io.sensors import read_other_sensors, sensor_count

    flight, _ = truth_flight
    second = flight.qci_pa * 1.05
    cases = ((write_dataflash_bin, "two.bin", {}), (write_ulog, "two.ulg", {}),
             (write_tlog, "two.tlog", {}), (write_dataflash_bin, "asp2.bin", {"second_as": "ASP2"}))
    for writer, name, kw in cases:
        path = writer(tmp_path / name, flight, second=second, **kw)
        with pytest.warns(UserWarning):
            first = read_flight(path)
        (other,) = read_other_sensors(path)
        assert sensor_count(first) == 2 and other.meta["qc_source"] != first.meta["qc_source"]
        np.testing.assert_allclose(other.qci_pa, 1.05 * first.qci_pa, rtol=2e-5)
    dead = write_tlog(tmp_path / "dead.tlog", flight, second=np.full(flight.n, 1e-3))
    with pytest.warns(UserWarning, match=r"airspeed sensor 2 \(SCALED_PRESSURE2.press_diff "
                                         r"\(hPa\)\) not calibrated: .*too little usable"):
        assert read_other_sensors(dead) == []
