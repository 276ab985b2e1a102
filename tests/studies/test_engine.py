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
    """Issue 11's JSBSim target (200 flights, ~90 s on 2 cores): k1, k2 and the wind inside
    2 sigma 90-98% of the time (measured 96.5 / 96.5 / 92 / 97.5%, z spread 0.93 / 0.90 /
    1.10 / 0.79). JSBSim's Milspec turbulence is fixed in the mean-wind frame (FGWinds rotates
    it by the wind azimuth), first-order along the wind and a faster second-order across it,
    where the noise model has one spectrum for both: the wind speed (along) spreads a little
    wider, the direction (across) narrower than the bounds, which are then safe but ~1.3x
    wide there; no noise model fitted from one flight can tell (docs/measured.md, "the
    across-wind bound on JSBSim"), hence the direction's lower limit 0.75."""
    from pitotcal.studies.catalog import run_study

    summary = run_study("coverage", runs=200, out_dir=tmp_path, workers=2, seed=0,
                        engine="jsbsim")
    for name, p in summary["parameters"].items():
        assert 0.90 <= p["coverage_2sigma"] <= 0.98, (name, p)
        low = 0.75 if name == "wind_from_deg" else 0.8
        assert low <= p["z_std"] <= 1.25, (name, p)
