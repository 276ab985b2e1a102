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
