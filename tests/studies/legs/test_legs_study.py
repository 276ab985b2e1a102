"""The `legs` study: lean in CI (a few runs), full size (100 runs per case) marked slow."""

import json
import re
import warnings

import pytest
from pitotcal.studies.catalog import STUDIES, rerun, run_study
from pitotcal.studies.engine.runner import read_table

HEADLINE = (r"scatter: global ΔV ±\d\.\d\d kt vs per point ±\d+\.\d\d kt \(median 95 % "
            r"half-widths\), coverage global \S+%, per point \S+%; stated: .+")


def test_legs_study_lean(tmp_path):
    summary = run_study("legs", runs=3, out_dir=tmp_path, workers=0, quick=True, seed=5)
    rows = read_table(tmp_path / "legs.csv")
    assert len(rows) == summary["n_rows"] == 3 * 2 * 7 and summary["n_failed"] == 0
    assert {"run_index", "seed", "bound", "ias_kt", "dv_true_kt", "point_half_kt",
            "global_half_kt", "point_inside", "global_inside"} <= set(rows[0])
    on_disk = json.loads((tmp_path / "legs.json").read_text())
    assert set(on_disk["by_bound"]) == {"scatter", "stated"}
    assert re.fullmatch(HEADLINE, summary["headline"]), summary["headline"]
    assert (tmp_path / "legs.png").stat().st_size > 20_000
    # the same legs: the global band is the narrower in (nearly) every point
    assert on_disk["by_bound"]["stated"]["global_narrower_share"] == 1.0
    assert rerun("legs", 1, runs=3, seed=5, quick=True)[0]["seed"] == rows[7]["seed"]
    assert STUDIES["legs"].description


@pytest.mark.slow
def test_legs_study_full_size(tmp_path):
    """100 leg flights per case: coverage of both methods within 90-98 %, global narrower."""
    summary = run_study("legs", out_dir=tmp_path, workers=1, seed=0)
    for case in summary["by_bound"].values():
        assert 0.90 <= case["coverage_point"] <= 0.98
        assert 0.90 <= case["coverage_global"] <= 0.98
        assert case["median_half_global_kt"] < case["median_half_point_kt"]


LEGS_FLIGHT_HEADLINE = (r"legs detected as flown in \S+% of runs \(\S+% of the legs' time used\); "
                        r"median 95 % half-widths of ΔV: per point ±\d\.\d\d kt \(coverage \S+%\), "
                        r"leg global ±\d\.\d\d kt \(coverage \S+%\), time series ±\d\.\d\d kt "
                        r"\(coverage \S+%\)")


def test_legs_flight_study_lean(tmp_path):
    with warnings.catch_warnings():       # one line per run on stderr was 100 lines per study
        warnings.simplefilter("error")
        summary = run_study("legs-flight", runs=2, out_dir=tmp_path, workers=0, quick=True,
                            seed=5)
    rows = read_table(tmp_path / "legs-flight.csv")
    assert len(rows) == summary["n_rows"] == 2 * 4 and summary["n_failed"] == 0
    assert {"dv_true_kt", "point_half_kt", "global_half_kt", "series_half_kt",
            "series_inside", "legs_match", "leg_time_used"} <= set(rows[0])
    assert summary["legs_match_share"] == 1.0
    assert re.fullmatch(LEGS_FLIGHT_HEADLINE, summary["headline"]), summary["headline"]
    assert (tmp_path / "legs-flight.png").stat().st_size > 20_000


@pytest.mark.slow
def test_legs_flight_study_full_size(tmp_path):
    """100 leg flights: legs detected as flown; every method's coverage within 90-98 %."""
    summary = run_study("legs-flight", out_dir=tmp_path, workers=1, seed=0)
    assert summary["legs_match_share"] >= 0.95
    for m in summary["methods"].values():
        assert 0.90 <= m["coverage"] <= 0.98
