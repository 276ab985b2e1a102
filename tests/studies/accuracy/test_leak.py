"""The `leak` study (issue 15, item 2): lean run in CI, the full size marked slow."""

import json

import pytest
from pitotcal.studies.catalog import run_study
from pitotcal.studies.accuracy.leak import LEAK, ONSET_S, PLANS


def test_leak_lean(tmp_path):
    """One flight, the one-way sweep with a 3 % leak from t = 120 s in 0.5 m/s turbulence:
    flagged, by the jump test at the leak's sample, and no tight wrong answer."""
    summary = run_study("leak", runs=1, out_dir=tmp_path, workers=0, quick=True, seed=0)
    assert summary["n_rows"] == 1 and not summary["errors"]
    rows = (tmp_path / "leak.csv").read_text().splitlines()
    header, row = rows[-2].split(","), rows[-1].split(",")
    assert float(row[header.index("jump_time_s")]) == pytest.approx(ONSET_S, abs=0.05)
    on_disk = json.loads((tmp_path / "leak.json").read_text())
    assert [c["plan"] for c in on_disk["cases"]] == ["one-way"]
    for case in on_disk["cases"]:
        assert case["leak"] == LEAK and case["n_runs_used"] == 1
        assert case["flagged"] == 1.0 and case["silent_wrong"] == 0.0
    assert (tmp_path / "leak.png").exists()
    assert "leak flagged 100%" in summary["headline"], summary["headline"]
    assert set(PLANS) == {"one-way", "up-and-down"}


@pytest.mark.slow
def test_leak_full_size(tmp_path):
    """50 flights per case (~10 min on 2 cores): clean flights flagged in at most 5 % (plus
    the Monte Carlo's own slack: 6 of 50), a 3 % leak flagged in 95 % or more in calm air and
    in 0.5 m/s turbulence on both maneuvers; the one-way sweep saying that it hides a change
    of scale where a 3 % leak goes unseen (1 m/s: the jump test catches a sudden change only
    from ~4 %, which moves ΔV ~1.5 kt, beyond the default 1 kt) and not where the jump test
    catches it (0.5 m/s: from ~2 %, ~0.75 kt), the up-and-down one never (docs/measured.md)."""
    summary = run_study("leak", runs=50, out_dir=tmp_path, workers=2, seed=0)
    for c in summary["cases"]:
        name = (c["plan"], c["turbulence_mps"], c["leak"])
        if c["leak"] == 0:
            assert c["flagged"] <= 0.12, name
        elif c["turbulence_mps"] <= 0.5:
            assert c["flagged"] >= 0.95, name
        if c["turbulence_mps"] > 0 and c["leak"] == 0:
            one_way_loud = c["plan"] == "one-way" and c["turbulence_mps"] >= 1.0
            assert c["hidden"] >= 0.9 if one_way_loud else c["hidden"] <= 0.1, name
