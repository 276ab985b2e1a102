"""Peer baselines (studies/peer_ardupilot.py, studies/peer_px4.py) recover a known scale and wind on seeded flights."""

import math

import numpy as np
import pytest
from pitotcal.studies.peers.baselines import (
    ardupilot_ratio_from_k1,
    delta_v_kt_from_k1,
    k1_from_ardupilot_ratio,
)
from pitotcal.studies.peers.ardupilot import ardupilot_autocal
from pitotcal.studies.peers.px4 import px4_wind_estimator
from synthetic import synthetic_flight

from pitotcal.core.errors import PitotcalError

K1 = 0.05


@pytest.fixture(scope="module")
def clean_flight():
    """600 s, six full turns, constant-model error k1 = 0.05, 5 m/s wind from 270 deg."""
    return synthetic_flight(seed=3, n=50 * 600, model="constant", k=(K1,), turns=6,
                            qc_noise_pa=0.3)


@pytest.fixture(scope="module")
def rough_flight():
    """The same with turbulence and 5 Hz noisy GPS."""
    return synthetic_flight(seed=4, n=50 * 600, model="constant", k=(K1,), turns=6,
                            turbulence_mps=0.5, gps_rate_hz=5.0, gps_noise_mps=0.05)


def test_ratio_k1_round_trip():
    assert k1_from_ardupilot_ratio(ardupilot_ratio_from_k1(0.14)) == pytest.approx(0.14)
    # a perfect sensor is ratio 2/rho0 = 1.633; ArduPilot's default 1.9936 means k1 = 0.18
    assert k1_from_ardupilot_ratio(2.0 / 1.225) == pytest.approx(0.0, abs=1e-12)
    assert k1_from_ardupilot_ratio(1.9936) == pytest.approx(0.181, abs=1e-3)
    assert delta_v_kt_from_k1(0.05, 85.0) == pytest.approx(85.0 * (0.95 ** -0.5 - 1.0))


@pytest.mark.parametrize("filt, k1_tol, wind_tol", [
    (ardupilot_autocal, 0.005, 0.3),
    (px4_wind_estimator, 0.01, 0.3),
])
def test_baseline_converges_on_clean_flight(clean_flight, filt, k1_tol, wind_tol):
    flight, truth = clean_flight
    tr = filt(flight)
    end = tr.at(flight.time_s[-1])
    assert end["k1"] == pytest.approx(K1, abs=k1_tol)
    assert end["wind_n_mps"] == pytest.approx(truth["wind_n_mps"], abs=wind_tol)
    assert end["wind_e_mps"] == pytest.approx(truth["wind_e_mps"], abs=wind_tol)
    # stated uncertainty shrinks from the start and covers the truth at the end
    assert tr.k1_std[-1] < tr.k1_std[len(tr.k1_std) // 20] or filt is ardupilot_autocal
    assert abs(end["k1"] - K1) <= end["k1_2sigma"]


@pytest.mark.parametrize("filt", [ardupilot_autocal, px4_wind_estimator])
def test_baseline_in_turbulence(rough_flight, filt):
    flight, truth = rough_flight
    tr = filt(flight)
    end = tr.at(flight.time_s[-1], vi_kt=85.0)
    assert end["k1"] == pytest.approx(K1, abs=0.015)
    assert end["wind_speed_mps"] == pytest.approx(truth["parameters"]["wind_speed_mps"], abs=0.6)
    assert end["dv_2sigma_kt"] > 0
    assert tr.n_resets == 0


def test_ardupilot_is_slow_by_design(clean_flight):
    """P0 = 1e-6 and Q = 5e-7/s on z: after 60 s the ratio has barely left its start."""
    flight, _ = clean_flight
    tr = ardupilot_autocal(flight)
    assert tr.at(60.0)["k1"] < 0.5 * K1
    assert tr.time_s[1] - tr.time_s[0] == pytest.approx(1.0)


def test_px4_validation_needs_all_course_bins():
    """Straight flight never fills the 12 course bins: the validated scale stays at its start."""
    flight, _ = synthetic_flight(seed=5, n=50 * 120, model="constant", k=(K1,), turns=0.5)
    tr = px4_wind_estimator(flight)
    assert np.all(tr.k1_validated == 0.0)


@pytest.mark.parametrize("call, match", [
    (lambda f: ardupilot_autocal("x"), "flight must be a pitotcal.Flight, got str"),
    (lambda f: ardupilot_autocal(f, rate_hz=0), "rate_hz 0 must be > 0"),
    (lambda f: ardupilot_autocal(f, initial_ratio=-1), "initial_ratio -1 must be > 0"),
    (lambda f: px4_wind_estimator(f, tas_noise_mps=float("nan")), "tas_noise_mps nan must be"),
    (lambda f: px4_wind_estimator(f, gate_sd=-3), "gate_sd -3 must be > 0"),
    (lambda f: ardupilot_autocal(f).at(-5.0), "no filter update before"),
])
def test_errors(clean_flight, call, match):
    with pytest.raises(PitotcalError, match=match):
        call(clean_flight[0])


def test_compare_peers_one_run(tmp_path):
    """One short simulated flight per truth case through the whole comparison (the quick grid:
    T = 30 and 240 s): files, keys, pitotcal refusal, headline."""
    from pitotcal.studies.catalog import run_study
    s = run_study("peers", runs=1, seed=0, quick=True, out_dir=tmp_path)
    for name in ("peers.csv", "peers.json", "peers.png"):
        assert (tmp_path / name).is_file()
    by = s["by_method"]
    assert set(by) == {"pitotcal", "ardupilot", "px4"}
    # after 30 s the track has not turned enough: pitotcal refuses, the filters answer anyway
    assert by["pitotcal"]["30"]["estimates"] == 0
    assert by["px4"]["30"]["estimates"] == 1
    # after the full 240 s plan pitotcal's ΔV is within 0.5 kt and inside its stated 2-sigma
    e = by["pitotcal"]["240"]
    assert e["dv_rms_err_kt"] < 0.5 and e["dv_coverage"] == 1.0
    assert len(s["claims"]) == 4
    assert s["headline"].startswith("first flight time with error and stated 2σ within wind "
                                    "±0.5 m/s: pitotcal ")


def test_compare_peers_inverse_truth_case(tmp_path):
    """The second truth case (the paper's inverse+ model): pitotcal fits `inverse`, the peers
    their single scale; both cases in one table, one summary, two figures."""
    from pitotcal.studies.catalog import run_study
    from pitotcal.studies.engine.runner import read_table

    from pitotcal.core.scenario import TRUE_K

    inverse_k = TRUE_K["inverse"]
    s = run_study("peers", runs=1, seed=3, quick=True, out_dir=tmp_path, workers=0)
    for name in ("peers.csv", "peers.json", "peers.png", "peers-inverse.png"):
        assert (tmp_path / name).is_file()
    inv = s["inverse_truth"]
    assert inv["truth_model"] == inv["fit_model"] == "inverse"
    assert inv["truth_k"] == list(inverse_k)
    assert s["truth_model"] == "constant" and s["n_runs"] == 2 and s["n_failed"] == 0
    rows = read_table(tmp_path / "peers.csv")
    assert {r["truth_model"] for r in rows} == {"constant", "inverse"}
    # the truth ΔV of each case is that case's own model at 85 kt
    ref = {r["truth_model"]: r["dv_true_kt"] for r in rows}
    from pitotcal.core.models import delta_v_kt, get_model
    assert math.isclose(ref["inverse"], float(delta_v_kt(get_model("inverse"), inverse_k, 85.0)))
    assert math.isclose(ref["constant"], float(delta_v_kt(get_model("constant"), (0.05,), 85.0)))
    e = inv["by_method"]["pitotcal"]["240"]
    assert e["estimates"] == 1 and e["dv_range_rms_err_kt"] < 0.5 and e["dv_range_coverage"] == 1.0
    # a single scale cannot follow k2/q_ci: its ΔV error over the range is larger than at
    # the reference speed, where a one-scale fit crosses the curve
    for peer in ("ardupilot", "px4"):
        p = inv["by_method"][peer]["240"]
        assert p["dv_range_rms_err_kt"] > p["dv_rms_err_kt"]
    assert len(inv["claims"]) == 4 and len(inv["claims_dv_range"]) == 2


def test_range_score_uses_every_grid_point():
    import numpy as np
    from pitotcal.studies.peers.study import _range_score
    out = _range_score([1.0, 2.0, 3.0], [0.5, 0.5, 0.1], np.array([1.0, 2.2, 3.3]))
    assert math.isclose(out["dv_range_err_max_kt"], 0.3)
    assert out["dv_range_2sigma_max_kt"] == 0.5 and out["dv_range_covered"] is False
