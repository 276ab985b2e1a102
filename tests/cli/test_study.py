"""`pitotcal study` (docs/interfaces.md §7): a lean run prints its result and writes its files,
--run-index repeats a run, --data / $PITOTCAL_ALFA_DATA find the real flight from any folder,
Ctrl-C keeps the finished runs (exit 130), and bad input is one line (exit 2)."""

import json

import pytest
from pitotcal.studies import catalog
from pitotcal.studies.engine.runner import echo_task, read_table
from pitotcal.studies.engine.study import MonteCarloStudy

import pitotcal.cli.study as study_cli
from pitotcal.cli import main


def test_lean_coverage_prints_its_result_and_repeats_a_run(tmp_path, capsys):
    args = ["study", "coverage", "--runs", "3", "--workers", "0", "--quick", "--seed", "2"]
    assert main([*args, "--out", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("study coverage: 3 runs, 0 failed, ")
    assert "  result: truth inside the corrected 2σ bounds " in out
    assert "coverage_2sigma:" in out and "coverage: 3/3 runs" in err
    assert {"coverage.csv", "coverage.json", "coverage.png"} <= {p.name for p in tmp_path.iterdir()}
    for name in ("coverage.csv", "coverage.json", "coverage.png"):
        assert f"  wrote {tmp_path / name}" in out
    assert main([*args, "--run-index", "1"]) == 0
    row = json.loads(capsys.readouterr().out)[0]
    assert row["seed"] == 3 and row["run_index"] == 1


def test_real_alfa_from_any_folder_with_the_environment_variable(shared_file, tmp_path,
                                                                 monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PITOTCAL_ALFA_DATA", str(shared_file("alfa-carbonz")))
    assert main(["study", "real-alfa", "--out", "out"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("study real-alfa: 1 run, 0 failed, ")
    assert "  result: k1 = 0.167 ± 0.038 (2σ), ArduPilot ratio 1.96 ± 0.09" in out
    assert {"real-alfa.csv", "real-alfa.json", "real-alfa.png", "real-alfa_tracks.csv"} <= {
        p.name for p in (tmp_path / "out").iterdir()}


def test_real_alfa_data_absent_says_where_it_looked(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("PITOTCAL_ALFA_DATA", raising=False)
    assert main(["study", "real-alfa", "--data", str(tmp_path / "none")]) == 2
    assert capsys.readouterr().err == (
        f"pitotcal study: ALFA flight data (scaled_pressure.csv) not found: looked in "
        f"{tmp_path / 'none'}, {tmp_path / 'none' / 'alfa-carbonz'} (--data)\n")
    assert main(["study", "real-alfa"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"looked in {tmp_path / 'alfa-carbonz'} (current folder)" in err
    assert "PITOTCAL_ALFA_DATA is not set; pass --data or set PITOTCAL_ALFA_DATA" in err


def test_ctrl_c_keeps_the_finished_runs(tmp_path, monkeypatch, capsys):
    stops = MonteCarloStudy(
        "echo", "echo runs; run 2 acts as Ctrl-C", echo_task,
        cases=lambda runs, quick: [{"value": float(i), "stop": i == 2} for i in range(runs)],
        summarize=lambda rows, cases: {}, plot=lambda rows, summary, out_dir: [],
        headline=lambda summary: "")
    monkeypatch.setitem(catalog.STUDIES, "echo", stops)
    monkeypatch.setattr(study_cli, "STUDY_NAMES", (*study_cli.STUDY_NAMES, "echo"))
    assert main(["study", "echo", "--runs", "4", "--workers", "0", "--out", str(tmp_path)]) == 130
    err = capsys.readouterr().err.splitlines()
    assert err[:2] == ["echo: 1/4 runs", "echo: 2/4 runs"]        # the progress so far
    stopped = ("pitotcal study: echo interrupted: 2 of 4 runs finished, kept in echo.csv "
               "(marked partial)")
    assert err[2:] == [stopped, f"  wrote {tmp_path / 'echo.csv'}",
                       f"  wrote {tmp_path / 'echo.json'}"]
    assert (tmp_path / "echo.csv").read_text().startswith(
        "# partial: 2 of 4 runs (interrupted)\n")
    assert len(read_table(tmp_path / "echo.csv")) == 2
    assert json.loads((tmp_path / "echo.json").read_text())["partial"] is True


NOT_A_FOLDER = ("--out must be a folder (it receives coverage.csv, coverage.json and "
                "coverage*.png); FILE is a file")


@pytest.mark.parametrize("args, error", [
    (["--runs", "0"], "--runs 0 must be >= 1"),
    (["--out", "FILE"], NOT_A_FOLDER),
    (["--out", "FILE/sub"], NOT_A_FOLDER),
])
def test_bad_input_is_one_line(args, error, tmp_path, capsys):
    (tmp_path / "FILE").write_text("not a folder\n")
    args = [a.replace("FILE", str(tmp_path / "FILE")) for a in args]
    assert main(["study", "coverage", "--quick", "--workers", "0", *args]) == 2
    error = error.replace("FILE", str(tmp_path / "FILE"))
    assert capsys.readouterr().err == f"pitotcal study: {error}\n"


@pytest.mark.parametrize("args, error", [
    (["nope"], "argument NAME: invalid choice: 'nope'"),
    (["coverage", "--runs", "two"], "argument --runs: invalid int value: 'two'"),
])
def test_bad_arguments(args, error, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["study", *args])
    assert stop.value.code == 2 and error in capsys.readouterr().err


def test_a_negative_seed_is_refused(capsys):
    assert main(["study", "coverage", "--quick", "--workers", "0", "--seed", "-1"]) == 2
    assert capsys.readouterr().err == "pitotcal study: --seed -1 must be >= 0\n"


def test_runs_above_the_cap_are_refused_with_the_cap(capsys):
    from pitotcal.cli import main

    assert main(["study", "coverage", "--runs", "100000000"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == ("pitotcal study: --runs 100000000 is more than one study takes (100000, "
                   "held in memory): run several studies, each with its own --seed")


def test_jets_needs_a_folder_of_test_points(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["study", "jets"]) == 2
    err = capsys.readouterr().err
    assert err == ("pitotcal study: study jets needs --data, the folder of the CLASS*.csv "
                   "test points\n")
    assert main(["study", "jets", "--data", str(tmp_path)]) == 2
    assert "has no CLASS*.csv test point" in capsys.readouterr().err
