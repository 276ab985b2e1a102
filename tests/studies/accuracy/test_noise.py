"""The `noise` study: lean run (one flight per noise case) scored against truth."""

import json
import re

import pytest
from pitotcal.studies.catalog import STUDIES, run_study
from pitotcal.studies.accuracy.noise import NOISE_CASES, PARAMETERS

HEADLINE = r"truth inside ±2σ: (\S+: parameters \S+-\S+, rows \S+, rms z \d+\.\d\d(; )?){5}$"


def test_noise_lean(tmp_path):
    summary = run_study("noise", runs=1, out_dir=tmp_path, workers=0, quick=True, seed=2)
    assert summary["n_rows"] == len(NOISE_CASES) and not summary["errors"]
    assert re.match(HEADLINE, summary["headline"]), summary["headline"]
    on_disk = json.loads((tmp_path / "noise.json").read_text())
    assert set(on_disk["cases"]) == set(NOISE_CASES)
    for case in on_disk["cases"].values():
        for name in PARAMETERS:
            p = case["parameters"][name]
            # one flight: the truth within 3 sigma (rms z of one estimate = |z|)
            assert p["rms_z"] < 3.0 and p["median_2sigma"] > 0, (name, p)
        assert 0.0 <= case["rows_inside_2sigma"] <= 1.0
        assert case["p90_dv_2sigma_max_kt"] >= case["median_dv_2sigma_max_kt"] > 0
    assert (tmp_path / "noise.png").exists()
    assert STUDIES["noise"].engines == ("own", "jsbsim")


@pytest.mark.slow
def test_noise_full_size(tmp_path):
    """Issue 11's cases over 100 flights each (~5 min on 2 cores; docs/measured.md has what
    each case gives): every parameter covered 90-98%, table rows 90% or more, rms z of all
    parameters 0.85-1.15 (each 0.8-1.2), except a slow GPS error nobody stated: it looks
    like wind, so the wind's bounds are too narrow there (measured 90%, rms z 1.20 / 1.34)."""
    summary = run_study("noise", runs=100, out_dir=tmp_path, workers=2, seed=0)
    for name, case in summary["cases"].items():
        assert case["rows_inside_2sigma"] >= 0.90, name
        params = case["parameters"]
        if name == "gauss-markov-gps-calm":
            assert params["wind_from_deg"]["rms_z"] > 1.15, params
            continue
        assert 0.85 <= case["rms_z"] <= 1.15, name
        for p in PARAMETERS:
            assert 0.90 <= params[p]["coverage_2sigma"] <= 0.98, (name, p)
            assert 0.8 <= params[p]["rms_z"] <= 1.2, (name, p)
