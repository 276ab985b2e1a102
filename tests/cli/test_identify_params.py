"""`pitotcal identify --params`: from a converted flight CSV's autopilot comments; refusals exit 2."""

import pytest
from synthetic import synthetic_flight

from pitotcal.cli import main
from pitotcal.io import write_flight_csv


@pytest.fixture(scope="module")
def flight():
    return synthetic_flight(seed=3, n=3000, model="constant", k=(0.18,))[0]


def test_csv_with_the_autopilot_ratio_comment(flight, tmp_path, capsys):
    path = tmp_path / "f.csv"
    write_flight_csv(flight, path, comments={"autopilot_ARSPD_RATIO": "1.9936"})
    out = tmp_path / "new.param"
    assert main(["identify", str(path), "--model", "constant", "--params", str(out)]) == 0
    assert "Recommended ARSPD_RATIO = 1.99" in capsys.readouterr().out
    assert "current value 1.9936" in out.read_text()


def test_csv_without_autopilot_is_refused(flight, tmp_path, capsys):
    path = tmp_path / "f.csv"
    write_flight_csv(flight, path)
    assert main(["identify", str(path), "--params", str(tmp_path / "p.param")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "ArduPilot or PX4 log" in err[0]


def test_params_on_top_of_input_refused_before_work(flight, tmp_path, capsys):
    path = tmp_path / "f.csv"
    write_flight_csv(flight, path)
    assert main(["identify", str(path), "--params", str(path)]) == 2
    assert "--params" in capsys.readouterr().err
