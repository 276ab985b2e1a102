"""Real ArduPlane flight (ALFA Carbon-Z): the comparison with the autopilot."""

import json

import pytest
from pitotcal.studies.catalog import run_study

_CACHE = {}


@pytest.fixture
def alfa_summary(shared_file, tmp_path_factory):
    """The study run once per module (it takes ~2 s), skipped without the shared data."""
    if "run" not in _CACHE:
        out = tmp_path_factory.mktemp("real-alfa")
        _CACHE["run"] = (run_study("real-alfa", out_dir=out,
                                   data_dir=shared_file("alfa-carbonz")), out)
    return _CACHE["run"]


def test_summary_keys_and_files(alfa_summary):
    s, out = alfa_summary
    for key in ("segment_s", "pitotcal", "autopilot", "peers", "comparison", "failure_time_s"):
        assert key in s
    assert set(s["pitotcal"]) == {"constant", "inverse"}
    assert set(s["peers"]) == {"ardupilot", "px4"}
    for name in ("real-alfa.csv", "real-alfa.json", "real-alfa.png", "real-alfa_tracks.csv"):
        assert (out / name).is_file()
    on_disk = json.loads((out / "real-alfa.json").read_text())
    assert on_disk["study"] == "real-alfa" and on_disk["n_runs"] == 1
    # the table: one row per method, in the columns it always had
    lines = (out / "real-alfa.csv").read_text().splitlines()
    assert lines[0].startswith("method,model,k1,k1_2sigma,k2,k2_2sigma,ardupilot_ratio,")
    assert len(lines) == 6 and lines[1].startswith("pitotcal,constant,0.16")


def test_headline(alfa_summary):
    s, _ = alfa_summary
    assert s["headline"].startswith("k1 = 0.167 ± 0.038 (2σ), ArduPilot ratio 1.96 ± 0.09 "
                                    "(the autopilot flew 1.898); wind 1.8 ± 0.6 m/s from 337")


def test_calibration_plausible_and_compared(alfa_summary):
    s, _ = alfa_summary
    c = s["pitotcal"]["constant"]
    assert c["converged"]
    # a small UAV pitot reads low: k1 between 0.05 and 0.3, known to a few hundredths
    assert 0.05 < c["k1"]["value"] < 0.3
    assert c["k1"]["2sigma"] < 0.05
    # light wind, well determined (the track covers every heading)
    assert 0.5 < c["wind_speed_mps"]["value"] < 4.0
    assert c["wind_speed_mps"]["2sigma"] < 1.0
    # the autopilot flew with a fixed ARSPD_RATIO of 1.898 (its autocal did not learn)
    ap = s["autopilot"]
    assert ap["ratio"] == pytest.approx(1.898, abs=1e-3)
    assert not ap["autocal_learning"]
    cmp_ = s["comparison"]
    # our k1 agrees with the autopilot's ratio within ~1.5 of our 2-sigma: an IAS difference
    # of about 1.5 %
    assert abs(cmp_["k1_difference_in_2sigma"]) < 1.5
    assert abs(cmp_["ias_error_of_autopilot_ratio_pct"]) < 3.0
    # and our wind agrees with the autopilot's settled (second-half) wind within ~0.5 m/s, 20 deg
    assert abs(cmp_["wind_speed_difference_late_mps"]) < 0.5
    assert abs(cmp_["wind_from_difference_late_deg"]) < 20.0
