"""`study coverage --engine jsbsim`: the coverage study flown by JSBSim; others refuse it."""

import json

import pytest

from pitotcal.cli import main

pytest.importorskip("jsbsim", reason="JSBSim is not installed (pip install jsbsim)")


def test_coverage_flown_by_jsbsim(tmp_path, capsys):
    assert main(["study", "coverage", "--engine", "jsbsim", "--runs", "1", "--workers", "0",
                 "--out", str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "coverage.json").read_text())
    assert summary["engine"] == "jsbsim" and summary["n_failed"] == 0
    assert summary["parameters"]["k1"]["n"] == 1


def test_a_study_that_flies_only_the_own_model_refuses_jsbsim(tmp_path, capsys):
    assert main(["study", "sample-size", "--engine", "jsbsim", "--runs", "1",
                 "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err.strip() == (
        "pitotcal study: --engine jsbsim: study sample-size flies only own")
    assert not any(tmp_path.iterdir())


@pytest.mark.slow
def test_coverage_on_200_jsbsim_flights(tmp_path):
    """Issue 11's JSBSim target (200 flights, ~10-15 min on 2 cores): k1, k2 and the wind
    speed inside 2 sigma 90-98% of the time, rms z 0.85-1.15. The wind direction is left out:
    JSBSim's Milspec turbulence is fixed in the mean-wind frame (FGWinds rotates it by the
    wind azimuth) with a first-order spectrum along the wind and a faster second-order one
    across it, so the cross-wind bound (the direction) is ~1.3x wide, the along-wind one
    ~1.2x narrow, where the noise model assumes the same spectrum in both (docs/measured.md)."""
    from pitotcal.studies.catalog import run_study

    summary = run_study("coverage", runs=200, out_dir=tmp_path, workers=2, seed=0,
                        engine="jsbsim")
    for name in ("k1", "k2", "wind_speed_mps"):
        p = summary["parameters"][name]
        assert 0.90 <= p["coverage_2sigma"] <= 0.98, (name, p)
        assert 0.85 <= p["z_std"] <= 1.15, (name, p)
