"""cli.common: the output checks the commands share."""

import os
from pathlib import Path

import pytest

from pitotcal.cli.common import check_distinct, check_output
from pitotcal.core.errors import PitotcalError


def test_an_output_hard_linked_to_the_input_is_refused(tmp_path):
    flight = tmp_path / "flight.csv"
    flight.write_text("x")
    os.link(flight, tmp_path / "r.json")
    with pytest.raises(PitotcalError, match="would overwrite the input flight file"):
        check_output("--json", tmp_path / "r.json", flight, "flight file")


def test_two_outputs_at_one_path_are_refused(tmp_path):
    check_distinct({"--json": tmp_path / "a.json", "--plot": tmp_path / "a.png", "-x": None})
    with pytest.raises(PitotcalError, match="--plot .*same file as --json"):
        check_distinct({"--json": tmp_path / "a.png", "--plot": tmp_path / "./a.png"})


def test_check_outputs_returns_the_paths_as_written(tmp_path):
    from pitotcal.cli.common import check_outputs

    written = check_outputs({"--json": str(tmp_path / "r.json"), "--plot": str(tmp_path / "r"),
                             "--params": None}, figures=["--plot"])
    assert written == {"--json": str(tmp_path / "r.json"), "--plot": f"{tmp_path / 'r'}.png",
                       "--params": None}


def test_an_unwritable_folder_or_file_is_refused(tmp_path, monkeypatch):
    """Only `plan` checked this before (maneuvers.plan.outputs.check_output_paths); monkeypatched
    because root may write anywhere."""
    from pitotcal.cli import common

    (tmp_path / "old.csv").write_text("x")
    monkeypatch.setattr(common.os, "access", lambda path, mode: Path(path).is_file())
    with pytest.raises(PitotcalError, match=r"-o .*new.csv: directory .* is not writable"):
        common.check_outputs({"-o": tmp_path / "new.csv"})
    monkeypatch.setattr(common.os, "access", lambda path, mode: not Path(path).is_file())
    with pytest.raises(PitotcalError, match=r"-o .*old.csv: the existing file is not writable"):
        common.check_outputs({"-o": tmp_path / "old.csv"})


LIVE = ["identify", "--live", "udp:127.0.0.1:14550"]
CAL = '{"model": "inverse", "parameters": {"k1": {"value": 0.0}, "k2": {"value": 0.0}}}'


@pytest.mark.parametrize("argv, match", [
    (["legs", "LEGS", "--plot", "f.xyz"], r"--plot .*f\.xyz: unknown figure format 'xyz'"),
    ([*LIVE, "--json", "a.png", "--plot", "a"], r"--plot .*a\.png: same file as --json .*a\.png"),
    ([*LIVE, "--plot", "a.xyz"], r"--plot .*a\.xyz: unknown figure format 'xyz'"),
    (["simulate", "LEGS", "-o", "f.csv"], r"-o \(its truth file\) .*f\.truth\.json is a folder"),
    (["plan", "--calibration", "cal.json", "--no-figures", "-o", "cal.json"],
     r"--output .*cal\.json: would overwrite the input calibration"),
])
def test_checks_one_command_lacked_are_made_by_all(tmp_path, capsys, monkeypatch, argv, match):
    """Each case was checked by some commands and not by the one run here."""
    import re

    from pitotcal.cli import main

    monkeypatch.chdir(tmp_path)
    Path("LEGS").write_text("point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg\n")
    Path("f.truth.json").mkdir()                # the truth goes beside the flight: a folder
    Path("cal.json").write_text(CAL)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(match, err), err
    assert Path("cal.json").read_text() == CAL
    assert sorted(p.name for p in tmp_path.iterdir()) == ["LEGS", "cal.json", "f.truth.json"]
