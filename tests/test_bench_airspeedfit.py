"""The AirspeedFit benchmark runs end to end on one drifting-wind flight: every tool it has is
timed and scored against the truth, and the drifting wind shows where it should (AirspeedFit's
drifting mode follows it; a constant wind cannot)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_airspeedfit.py"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("afbench")
    done = subprocess.run([sys.executable, str(BENCH), "--flights", "1", "--constant-flights",
                           "0", "--no-sitl", "--no-fetch", "--out", str(out)],
                          capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    return json.loads((out / "airspeedfit.json").read_text()), (out / "airspeedfit.md").read_text()


def test_every_tool_it_has_is_timed_and_scored(run):
    data, text = run
    tools = {"pitotcal inverse", "pitotcal constant", "oracle: inverse, true wind track"}
    if data["skipped"] is None:
        tools |= {"AirspeedFit constant", "AirspeedFit drifting"}
    else:
        assert f"AirspeedFit skipped: {data['skipped']}" in text
    drifting = data["summary"]["drifting"]
    assert set(drifting) == tools and set(data["summary"]) == {"drifting"}
    for name, s in drifting.items():
        assert s["n_ok"] == 1, name
        assert 0 < s["wall_s_median"] < 60 and 0 <= s["covered"] <= 1
    assert "| 15-min everyday flight, wind drifting 3 m/s and 40°, 1 | pitotcal inverse |" in text


def test_the_answers_are_near_the_truth_and_the_drift_is_seen(run):
    """pitotcal's constant-scale fit and AirspeedFit both within 0.6 kt of the true ΔV over the
    flown speeds; pitotcal's drifting wind (chosen by its test) and AirspeedFit's smoothed
    track within 1 m/s rms of the true track (a constant wind is ~2 m/s off it); everyone's
    mean wind within 0.5 m/s of the mean flown through."""
    data, _ = run
    s = data["summary"]["drifting"]
    assert s["pitotcal constant"]["dv_err_max_kt_median"] < 0.6
    assert s["pitotcal constant"]["wind_track_rms_mps_median"] < 1.0
    for name in s:
        assert s[name]["wind_mean_err_mps_median"] < 0.5, name
    if data["skipped"] is None:
        assert s["AirspeedFit drifting"]["dv_err_max_kt_median"] < 0.6
        assert s["AirspeedFit drifting"]["wind_track_rms_mps_median"] < 1.0


def test_the_oracle_knows_the_wind_and_is_scored_like_the_tools(run):
    """The oracle (the true drift taken out, then a constant-wind inverse fit) has the true
    wind track but for its mean's error, and its ΔV error is of the tools' size."""
    data, _ = run
    oracle = data["summary"]["drifting"]["oracle: inverse, true wind track"]
    assert oracle["wind_track_rms_mps_median"] < 0.3
    assert oracle["wind_track_rms_mps_median"] == pytest.approx(
        oracle["wind_mean_err_mps_median"], abs=0.05)
    assert oracle["dv_err_max_kt_median"] < 0.6


@pytest.mark.slow
def test_the_sitl_log_ratios(shared_file, tmp_path):
    """The SITL log alone (≈ 15 s): identify's recommended ARSPD_RATIO within 0.5 % of the
    simulator's 1.9936 and inside its 2σ; AirspeedFit's constant-wind ratio too."""
    import os

    log = shared_file("ardupilot/arduplane_sitl.log")
    env = {**os.environ, "PITOTCAL_SHARED_DATA": str(log.parents[1])}
    done = subprocess.run([sys.executable, str(BENCH), "--flights", "0", "--constant-flights",
                           "0", "--no-fetch", "--out", str(tmp_path)], capture_output=True,
                          text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stderr
    data = json.loads((tmp_path / "airspeedfit.json").read_text())
    tools = data["sitl"]["tools"]
    for name in ("pitotcal inverse", "pitotcal constant"):
        assert abs(tools[name]["error_percent"]) < 0.5 and tools[name]["covered"], name
    if data["skipped"] is None:
        assert abs(tools["AirspeedFit constant"]["error_percent"]) < 0.5
