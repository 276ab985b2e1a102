"""Each study, lean (serial, quick grid, few runs): table columns, summary keys, headline,
figure files; full size under the slow marker. Plus the one protocol, Ctrl-C keeping the
finished runs, and re-running one run alone. (The command line: tests/cli/test_study.py.)"""

import json
import math
import re

import pytest
from pitotcal.studies import catalog
from pitotcal.studies.catalog import STUDIES, StudyInterrupted, rerun, run_study
from pitotcal.studies.engine.common import percent
from pitotcal.studies.engine.runner import echo_task, read_table
from pitotcal.studies.engine.study import MonteCarloStudy, Study

BASE_COLUMNS = {"run_index", "seed", "error", "elapsed_s"}
SCORE_COLUMNS = {"success", "n_samples", "k1", "k1_std", "k1_std_plain", "k1_true", "k1_err",
                 "k1_z", "k2_z_plain", "wind_speed_mps_err", "wind_from_deg_err",
                 "dv_err_max_kt", "dv_2sigma_max_kt", "dv_inside_2sigma"}
SUMMARY_COMMON = {"study", "n_runs", "n_rows", "n_failed", "errors", "seed", "elapsed_s", "files"}

LEAN = {  # name -> (runs, study columns, study summary keys, headline pattern)
    "sample-size": (1, {"n_samples_used", "window_s"}, {"by_n_samples", "settled_n_samples"},
                    (r"2σ of ΔV (\d+\.\d\d kt at \d+, )*\d+\.\d\d kt at 16000 samples"
                     r"(; no answer below \d+ samples)?$")),
    "maneuvers": (1, {"profile", "duration_s"}, {"by_profile", "best_at_240s"},
                  (r"at 240 s (step-pause|continuous|two-speed) gives the tightest 2σ of ΔV "
                  r"\(step-pause \d\.\d\d, continuous \d\.\d\d, two-speed \d\.\d\d kt\)")),
    "sensitivity": (1, {"factor", "level", "background_turbulence_mps"}, {"factors"},
                    r"2σ of ΔV changes most with .+: \S+ kt at \S+ to \S+ kt at \S+ .+"),
    "coverage": (4, {"turbulence_mps"}, {"coverage_2sigma", "coverage_2sigma_uncorrected",
                                         "parameters", "n_runs_used"},
                 (r"truth inside the corrected 2σ bounds \d+(\.\d)?% of the time, inside the "
                 r"plain Hessian ones \d+(\.\d)?% \(16 intervals from 4 runs\)")),
    "design": (1, {"design", "duration_s", "dv_2sigma_range_kt", "dv_inside_range"},
               {"by_design", "reference", "optimal_gain_at_240s"},
               (r"at 240 s optimal \d\.\d\d kt vs two-speed \d\.\d\d kt worst-row 2σ of ΔV "
                r"over 72-98 KIAS \([+-]\d+% gain\); two-speed's value reached in .+")),
    "wind": (1, {"profile", "wind_speed_mps", "wind_from_deg"}, {"by_profile"},
             (r"estimated vs flown wind within \d\.\d\d kt and \d+\.\d° RMS \(worst profile\), "
             r"truth inside 2σ in \S+ of the estimates \(paper: 0.5 kt, 4°\)")),
    "budget": (1, {"turbulence_mps", "two_sigma_kt", "U_kt", "u_statistical_kt", "u_oat_kt",
                   "u_probe_lever_arm_kt"}, {"by_turbulence_mps", "probe_arm_m"},
               (r"turbulence 0 m/s: statistical 2σ \d\.\d\d kt, U \(k = 2\) \d\.\d\d kt "
                r"\(\d+\.\dx\); largest Type B term \w+ u = \d\.\d\d kt")),
}


def test_every_study_follows_the_one_protocol():
    # the Monte Carlo ones here; peers in test_baselines.py, real-alfa in test_real_alfa.py,
    # legs and legs-flight in test_legs_study.py, monitor in test_monitor_study.py, noise in
    # test_noise_study.py, leak in test_leak_study.py, coverage-tails in accuracy/test_tails.py,
    # jets in jets/test_jets.py
    assert set(LEAN) | {"peers", "real-alfa", "legs", "legs-flight", "monitor", "noise",
                        "leak", "coverage-tails", "jets"} == set(STUDIES)
    for name, study in STUDIES.items():
        assert isinstance(study, Study) and study.name == name and study.description


@pytest.mark.parametrize("name", sorted(LEAN))
def test_study_lean(name, tmp_path, fresh_cache):
    runs, columns, keys, headline = LEAN[name]
    summary = run_study(name, runs=runs, out_dir=tmp_path, workers=0, quick=True, seed=5)
    rows = read_table(tmp_path / f"{name}.csv")
    assert len(rows) == summary["n_rows"] >= 1
    assert BASE_COLUMNS | columns <= set(rows[0])
    ok = [r for r in rows if not r["error"]]
    assert ok, summary["errors"]
    assert SCORE_COLUMNS <= set(ok[0])
    on_disk = json.loads((tmp_path / f"{name}.json").read_text())
    assert SUMMARY_COMMON | keys <= set(on_disk)
    assert on_disk["seed"] == 5 and on_disk["partial"] is False
    assert re.fullmatch(headline, on_disk["headline"]), on_disk["headline"]
    pngs = sorted(p.name for p in tmp_path.glob(f"{name}*.png"))
    assert pngs and all((tmp_path / p).stat().st_size > 5000 for p in pngs)


def test_coverage_lean_values_and_rerun(tmp_path, fresh_cache):
    summary = run_study("coverage", runs=4, out_dir=tmp_path, workers=0, quick=True, seed=11)
    assert summary["n_failed"] == 0, summary["errors"]
    for key in ("coverage_2sigma", "coverage_2sigma_uncorrected"):
        assert 0.0 <= summary[key] <= 1.0
    # corrected bounds are never narrower than the plain ones on turbulent flights
    assert summary["coverage_2sigma"] >= summary["coverage_2sigma_uncorrected"]
    assert summary["n_intervals"] == 4 * 4
    rows = read_table(tmp_path / "coverage.csv")
    again = rerun("coverage", 2, runs=4, seed=11, quick=True)[0]
    assert again["seed"] == rows[2]["seed"] == 13
    for key in ("k1", "k2", "wind_speed_mps", "wind_from_deg", "dv_2sigma_max_kt"):
        assert math.isclose(again[key], rows[2][key], rel_tol=1e-9, abs_tol=1e-12)


@pytest.mark.parametrize("kwargs, match", [
    ({"name": "nope"}, "study 'nope' is not one of sample-size"),
    ({"name": "coverage", "runs": 0}, "runs 0 must be >= 1"),
])
def test_run_study_bad_arguments(kwargs, match, tmp_path):
    with pytest.raises(ValueError, match=match):
        run_study(out_dir=tmp_path, **kwargs)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(LEAN))
def test_study_full_size(name, tmp_path):
    summary = run_study(name, out_dir=tmp_path)
    assert summary["n_failed"] < summary["n_runs"]
    if name == "coverage":
        assert 0.90 <= summary["coverage_2sigma"] <= 0.98
        assert summary["coverage_2sigma_uncorrected"] < summary["coverage_2sigma"]


@pytest.mark.slow
def test_peers_full_size(tmp_path):
    """`pitotcal study peers` at full size (10 flights per truth case, 30-600 s): pitotcal's
    wind is honest within 0.5 m/s well before the filters', and in the inverse case the peers'
    single scale is structurally biased at the ends of the flown range."""
    summary = run_study("peers", out_dir=tmp_path)
    assert summary["n_failed"] == 0, summary["errors"]
    assert {"peers.csv", "peers.json", "peers.png", "peers-inverse.png"} <= {
        p.name for p in tmp_path.iterdir()}
    for case in (summary, summary["inverse_truth"]):
        ours = case["by_method"]["pitotcal"]["600"]
        assert ours["dv_coverage"] >= 0.8 and ours["wind_coverage"] >= 0.8
        assert case["time_to_tolerance_s"]["pitotcal"]["wind"] is not None
        assert case["time_to_tolerance_s"]["px4"]["wind"] is None
    inv = summary["inverse_truth"]["by_method"]
    for peer in ("ardupilot", "px4"):
        assert inv[peer]["600"]["dv_range_rms_err_kt"] > inv[peer]["600"]["dv_rms_err_kt"]


def test_rerun_of_the_one_run_study():
    with pytest.raises(ValueError, match=r"run index 1 is outside 0..0 \(real-alfa is one run\)"):
        rerun("real-alfa", 1)


def test_coverage_headline_keeps_the_decimal():
    """8.5% stays 8.5% (not 8%), 96.1% stays 96.1%, a whole number has no ".0"."""
    assert [percent(x) for x in (0.961, 0.085, 1.0, 0.0)] == ["96.1%", "8.5%", "100%", "0%"]
    text = STUDIES["coverage"].headline({"coverage_2sigma": 0.961,
                                         "coverage_2sigma_uncorrected": 0.085,
                                         "n_intervals": 800, "n_runs_used": 200, "n_runs": 200})
    assert text == ("truth inside the corrected 2σ bounds 96.1% of the time, inside the plain "
                    "Hessian ones 8.5% (800 intervals from 200 runs)")


def _echo_study(stop_at):
    """A tiny study of `echo_task` whose run `stop_at` acts as a Ctrl-C."""
    return MonteCarloStudy(
        "echo", "echo runs for tests", echo_task,
        cases=lambda runs, quick: [{"value": float(i), "stop": i == stop_at}
                                   for i in range(runs)],
        summarize=lambda rows, cases: {"n_values": len(rows)},
        plot=lambda rows, summary, out_dir: [],
        headline=lambda summary: f"{summary['n_values']} values")


def test_interrupted_study_keeps_the_finished_runs(tmp_path, monkeypatch):
    monkeypatch.setitem(catalog.STUDIES, "echo", _echo_study(stop_at=2))
    with pytest.raises(StudyInterrupted) as stop:
        run_study("echo", runs=5, out_dir=tmp_path, workers=0, seed=10)
    lines = (tmp_path / "echo.csv").read_text().splitlines()
    assert lines[0] == "# partial: 2 of 5 runs (interrupted)"
    rows = read_table(tmp_path / "echo.csv")
    assert [r["seed"] for r in rows] == [10.0, 11.0] and [r["value"] for r in rows] == [0.0, 1.0]
    on_disk = json.loads((tmp_path / "echo.json").read_text())
    assert on_disk == stop.value.summary | {"files": on_disk["files"]}
    assert on_disk["partial"] is True and on_disk["n_done"] == 2 and on_disk["n_runs"] == 5
    assert on_disk["headline"] == ("interrupted: 2 of 5 runs finished, kept in echo.csv "
                                   "(marked partial)")


def test_uninterrupted_echo_study(tmp_path, monkeypatch):
    monkeypatch.setitem(catalog.STUDIES, "echo", _echo_study(stop_at=None))
    summary = run_study("echo", runs=3, out_dir=tmp_path, workers=0)
    assert summary["headline"] == "3 values" and summary["partial"] is False
    assert not (tmp_path / "echo.csv").read_text().startswith("#")


def test_the_command_lines_names_are_the_catalogs():
    from pitotcal.studies import STUDY_NAMES
    from pitotcal.studies.catalog import STUDIES

    assert tuple(STUDIES) == STUDY_NAMES
