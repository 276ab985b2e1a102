"""Whole-flight logs: the calibration windows chosen from the log (pitotcal.io.windows) and the
outside air temperature's source (pitotcal.io.oat), on simulated DataFlash logs with truth."""

import numpy as np
import pytest
from logwriters import PS_PA, write_dataflash_bin
from synthetic import synthetic_flight, wind_vector

from pitotcal.core.flight import Flight
from pitotcal.core.models import get_model, qci_from_qc_pa
from pitotcal.core.units import R_AIR_JKGK
from pitotcal.estimation import identify
from pitotcal.io import read_flight
from pitotcal.io.logs import load_log

RATE_HZ, RHO, K = 10.0, 1.196, (0.02, -15.0)
WIND = wind_vector(5.0, 270.0)


def _straight(duration_s, tas_mps, path_deg, heading_deg=90.0):
    """(qci, vn, ve, vd) of straight flight at this true airspeed and flight-path angle."""
    n = int(duration_s * RATE_HZ)
    vd = np.full(n, -tas_mps * np.sin(np.radians(path_deg)))
    vh = tas_mps * np.cos(np.radians(path_deg))
    vn = np.full(n, vh * np.cos(np.radians(heading_deg)) + WIND[0])
    ve = np.full(n, vh * np.sin(np.radians(heading_deg)) + WIND[1])
    qci = qci_from_qc_pa(get_model("inverse"), K, np.full(n, 0.5 * RHO * tas_mps ** 2))
    return qci, vn, ve, vd


def _calibration(duration_s, seed):
    f, _ = synthetic_flight(seed=seed, n=int(duration_s * RATE_HZ), rate_hz=RATE_HZ, k=K,
                            cas_kt=(60.0, 90.0), turns=duration_s / 100.0, rho_kgm3=RHO)
    return f.qci_pa, f.gps_vn_mps, f.gps_ve_mps, np.zeros(f.n)


def _whole_flight(parts):
    """A Flight of the parts [(name, (qci, vn, ve, vd))] one after another, and each part's
    (start, end) time, s."""
    cols = [np.concatenate([p[1][i] for p in parts]) for i in range(4)]
    t = np.arange(cols[0].size) / RATE_HZ
    spans, i = {}, 0
    for name, p in parts:
        spans.setdefault(name, []).append((t[i], t[i + p[0].size - 1]))
        i += p[0].size
    flight = Flight(time_s=t, qci_pa=cols[0], gps_vn_mps=cols[1], gps_ve_mps=cols[2],
                    rho_kgm3=np.full(t.size, RHO), gps_vd_mps=cols[3])
    return flight, spans


def _log(tmp_path, parts):
    flight, spans = _whole_flight(parts)
    ground = spans["ground"]
    path = write_dataflash_bin(tmp_path / "whole.bin", flight, flying=(ground[0][1], ground[1][0]),
                               min_airspeed=15.0)
    return path, spans


OAT_K = PS_PA / (R_AIR_JKGK * RHO)        # the temperature the test logs carry


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
