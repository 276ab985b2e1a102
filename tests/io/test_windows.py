"""Whole-flight logs: the calibration windows chosen from the log (pitotcal.io.windows) and the
outside air temperature's source (pitotcal.io.oat), on simulated DataFlash logs with truth."""

import numpy as np
import pytest
from wholeflight import K, OAT_K, calibration as _calibration, straight as _straight
from wholeflight import write_log as _log

from pitotcal.estimation import identify
from pitotcal.io import read_flight
from pitotcal.io.logs import load_log


def test_the_windows_are_the_calibration_part_and_the_fit_matches_the_truth(tmp_path):
    """Taxi, a 25-deg take-off climb, 300 s of turns and a speed sweep, a 30-deg dive, taxi:
    the window is the calibration part (less the pads at its ends), the climb and the dive
    are cut and said so, and k1, k2 match the truth within 3 sigma."""
    path, spans = _log(tmp_path, [("ground", _straight(20, 3.0, 0.0)),
                                  ("climb", _straight(40, 35.0, 25.0)),
                                  ("cal", _calibration(300, seed=3)),
                                  ("dive", _straight(30, 45.0, -30.0)),
                                  ("ground", _straight(20, 3.0, 0.0))])
    flog = load_log(path, oat_k=OAT_K, windows="auto")
    flight = flog.flight
    (c0, c1), = spans["cal"]
    assert len(flight.reading["windows"]) == 1 and flight.segment is None
    w = flight.reading["windows"][0]
    assert c0 <= w["start_s"] < c0 + 5.0 and c1 - 5.0 < w["end_s"] <= c1
    assert flight.time_s.min() >= c0 and flight.time_s.max() <= c1
    cut = flight.reading["cut_s"]
    assert cut["climb or dive (flight-path angle > 15 deg)"] == pytest.approx(70.0, abs=6.0)
    assert "autopilot not flying (STAT.isFlying/Armed)" in cut
    result = identify(flight, model="inverse", air="incompressible")
    for name, truth in zip(("k1", "k2"), K):
        assert abs(result.value(name) - truth) < 3 * result.std[result.param_names.index(name)]
    # without auto windows the climb and the dive are fitted too
    assert load_log(path, oat_k=OAT_K).flight.time_s.min() < c0 - 30


def test_two_windows_share_the_calibration_and_are_segments(tmp_path):
    """Two calibration parts with a dive and a climb between them: two windows, Flight.segment
    0 and 1, and the estimator runs on them without a gap warning."""
    path, spans = _log(tmp_path, [("ground", _straight(20, 3.0, 0.0)),
                                  ("climb", _straight(30, 35.0, 25.0)),
                                  ("cal", _calibration(200, seed=4)),
                                  ("dive", _straight(40, 40.0, -25.0)),
                                  ("climb", _straight(40, 35.0, 25.0)),
                                  ("cal", _calibration(200, seed=5)),
                                  ("ground", _straight(20, 3.0, 0.0))])
    flight = read_flight(path, oat_k=OAT_K, windows="auto")
    windows = flight.reading["windows"]
    assert len(windows) == 2
    for w, (c0, c1) in zip(windows, spans["cal"]):
        assert c0 <= w["start_s"] < c0 + 5.0 and c1 - 5.0 < w["end_s"] <= c1
        assert w["track_spread_deg"] > 180.0
    assert set(np.unique(flight.segment)) == {0, 1}
    assert np.all(np.diff(flight.segment) >= 0)
    result = identify(flight, model="constant", air="incompressible")
    assert result.converged and not any("time gaps" in w for w in result.warnings)
    record = result.to_dict()
    assert [w["n_samples"] for w in record["windows"]] == [w["n_samples"] for w in windows]
    assert "windows" not in record["reading"] and record["cut_s"]


def test_oat_from_the_ground_temperature_and_the_lapse(tmp_path):
    """--oat-ground-c: T = T_ground - 6.5 K/km above the take-off point (the static pressure
    is constant in the test logs: the whole flight is at the take-off height)."""
    path, _ = _log(tmp_path, [("ground", _straight(20, 3.0, 0.0)),
                              ("cal", _calibration(120, seed=6)),
                              ("ground", _straight(20, 3.0, 0.0))])
    flight = read_flight(path, oat_ground_k=290.0)
    assert np.allclose(flight.oat_k, 290.0)
    assert "standard lapse" in flight.reading["oat_source"]
    from pitotcal.estimation.identification.sensor_inputs import detected_oat_source
    assert detected_oat_source(flight)[0] == "ground-lapse"


def test_a_logged_oat_sensor_is_the_temperature_and_a_flag_wins_over_it(tmp_path):
    """ArduPilot TEMP (a temperature sensor): the density's temperature, no chip warning; with
    oat_k given the flag wins and the sensor's reading is noted."""
    import warnings

    path, _ = _log(tmp_path, [("ground", _straight(20, 3.0, 0.0)),
                              ("cal", _calibration(120, seed=7)),
                              ("ground", _straight(20, 3.0, 0.0))], oat_sensor_c=3.5)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        flight = read_flight(path)
    assert np.allclose(flight.oat_k, 276.65)
    assert flight.reading["oat_source"] == ("TEMP.Temp (temperature sensor): a logged outside "
                                            "air temperature")
    assert not any("not OAT" in str(w.message) for w in caught)
    with pytest.warns(UserWarning, match=r"TEMP\.Temp \(temperature sensor\) \(mean 3\.5 degC\) "
                                         r"not used: `oat_k` given"):
        given = read_flight(path, oat_k=290.0)
    assert np.allclose(given.oat_k, 290.0)


def test_full_throttle_is_cut_where_the_log_has_the_throttle(tmp_path):
    """A 10-deg climb (steady by its angle) at full throttle (CTUN.ThO 100 %) is cut for the
    throttle; at 70 % it is kept."""
    parts = [("ground", _straight(20, 3.0, 0.0)), ("climb", _straight(40, 35.0, 10.0)),
             ("cal", _calibration(200, seed=8)), ("ground", _straight(20, 3.0, 0.0))]
    from wholeflight import whole_flight
    flight, spans = whole_flight(parts)
    (c0, c1), = spans["climb"]
    thr = np.where((flight.time_s >= c0) & (flight.time_s <= c1), 100.0, 70.0)
    path, _ = _log(tmp_path, parts, throttle_pct=thr)
    read = read_flight(path, oat_k=OAT_K, windows="auto")
    assert read.reading["cut_s"]["full throttle (CTUN.ThO >= 95 %)"] == pytest.approx(40, abs=3)
    assert read.time_s.min() > c1
    path, _ = _log(tmp_path, parts, throttle_pct=np.full(flight.n, 70.0))
    assert read_flight(path, oat_k=OAT_K, windows="auto").time_s.min() < c1


def test_the_ground_lapse_follows_the_height_above_the_take_off_point():
    """T = T_ground - 6.5 K/km above the take-off point, the height from the static pressure."""
    from pitotcal.core.units import isa_pressure_pa
    from pitotcal.io.oat import oat_on_times, takeoff_height_m
    from pitotcal.io.streams import LogStreams

    t = np.arange(0.0, 100.0, 0.5)
    h = np.where(t < 20.0, 300.0, 1300.0)          # on the ground at 300 m, then 1 km up
    s = LogStreams(static_t=t, ps_pa=isa_pressure_pa(h), airborne_t=np.array([0.0, 20.0]),
                   airborne=np.array([False, True]))
    assert takeoff_height_m(s) == pytest.approx(300.0, abs=0.5)
    temp, source = oat_on_times(s, t, np.full(t.size, 500.0), isa_pressure_pa(h), h,
                                oat_ground_k=288.15)
    assert temp[t >= 20.0] == pytest.approx(288.15 - 6.5, abs=0.01)
    assert temp[t < 20.0] == pytest.approx(288.15, abs=0.01)
    assert "standard lapse from the ground" in source and "(300 m)" in source


def test_no_window_long_enough_alone_keeps_all_steady_flight_with_a_warning(tmp_path):
    """Two 45-s calibration parts 40 s apart (a dive between): neither is a window alone
    (60 s), so all steady flight is one window, and a warning says so."""
    path, spans = _log(tmp_path, [("ground", _straight(20, 3.0, 0.0)),
                                  ("cal", _calibration(45, seed=10)),
                                  ("dive", _straight(40, 45.0, -30.0)),
                                  ("cal", _calibration(45, seed=11)),
                                  ("ground", _straight(20, 3.0, 0.0))])
    with pytest.warns(UserWarning, match="no steady window alone is long enough and turns "
                                         "enough: .*all steady flight is fitted as one window"):
        flight = read_flight(path, oat_k=OAT_K, windows="auto")
    (w,) = flight.reading["windows"]
    assert w["reason"].startswith("all steady flight as one window")
    assert flight.segment is None
    (a0, a1), (b0, b1) = spans["cal"]
    assert w["start_s"] < a0 + 5 and w["end_s"] > b1 - 5
    assert not np.any((flight.time_s > a1 + 1) & (flight.time_s < b0 - 1))   # the dive: cut
