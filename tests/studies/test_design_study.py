"""The `design` study at full size (slow): coverage of the flown designs, the prediction
against what identify reports, and the gain against the information bound."""

import pytest
from pitotcal.studies.catalog import run_study


@pytest.mark.slow
def test_design_study_full_size(tmp_path):
    summary = run_study("design", out_dir=tmp_path)       # 20 seeds per case
    assert summary["n_failed"] == 0, summary["errors"]
    for design, entries in summary["by_design"].items():
        at_240 = entries["240"]
        assert 0.88 <= at_240["coverage"] <= 1.0, (design, at_240)
        # identify's median reported bound against the prediction (30 two-speed seeds: 1.16)
        assert 0.8 < at_240["dv_2sigma_range_kt"] / at_240["predicted_kt"] < 1.5
        # no schedule beats the ideal two-point bound by more than the seeds' scatter
        assert at_240["predicted_kt"] >= 0.97 * at_240["ideal_bound_kt"]
    gain = summary["optimal-2-level_gain_at_240s"]
    if gain <= -0.1:
        # measured 2026-11-23: -0.143 at 20 seeds, -0.073 at 60 (docs/measured.md); the
        # design's one-level Dryden information model predates the estimator's multi-time-scale
        # noise model, and aligning them is open work (issue 13)
        pytest.xfail(f"two-level design {gain:+.3f} against two-speed in the reported bound")
