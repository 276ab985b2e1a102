"""Issue 15: a value argparse refuses is one line naming the flag (exit 2), never the usage
block, for every command through one mechanism (pitotcal.cli._Parser)."""

import pytest

from pitotcal.cli import main


@pytest.mark.parametrize("argv, line", [
    (["study", "coverage", "--runs", "abc"],
     "pitotcal study: argument --runs: invalid int value: 'abc' (see pitotcal study --help)"),
    (["simulate", "p.csv", "-o", "f.csv", "--engine", "xyz"],
     ("pitotcal simulate: argument --engine: invalid choice: 'xyz' (choose from 'own', "
     "'jsbsim') (see pitotcal simulate --help)")),
    (["identify", "f.csv", "--start-s", "abc"],
     ("pitotcal identify: argument --start-s: invalid float value: 'abc' (see pitotcal "
     "identify --help)")),
    (["simulate", "p.csv"],
     ("pitotcal simulate: the following arguments are required: -o/--output (see pitotcal "
     "simulate --help)")),
    (["report", "r.json", "-o", "x.html", "--speed-range-kt", "60"],
     ("pitotcal report: argument --speed-range-kt: expected 2 arguments (see pitotcal report "
     "--help)")),
    (["nope"], None),
])
def test_a_refused_option_value_is_one_line_naming_the_flag(argv, line, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1 and "usage:" not in err
    if line is not None:
        assert err == line + "\n"
    else:
        assert err.startswith("pitotcal: argument COMMAND: invalid choice: 'nope'")


def test_a_negative_number_in_exponent_form_is_a_value(tmp_path, capsys):
    from plans import circle_plan

    from pitotcal.io.plan_csv import write_plan

    path = write_plan(circle_plan(duration_s=20.0), tmp_path / "plan.csv")
    assert main(["simulate", str(path), "-o", str(tmp_path / "f.csv"), "--k2", "-1e6"]) == 2
    assert "--k2 -1e+06: the inverse pressure error" in capsys.readouterr().err
