"""`pitotcal identify --model mach-spline`: the Mach-dependent output error from the command
line, on a seeded synthetic jet test point with known truth (docs/interfaces.md §1b, §3)."""

import json

import pytest
from jets import OAT_K, RECOVERY, WIND, jet_point

from pitotcal.cli import main
from pitotcal.io import write_flight_csv


@pytest.fixture(scope="module")
def jet_csv(tmp_path_factory):
    """The tests' jet point at 2 Hz as a flight CSV (ps_pa, tat_k, alt_m among its columns)."""
    return write_flight_csv(jet_point(3, hz=2.0), tmp_path_factory.mktemp("jet") / "jet.csv")


def test_mach_spline_prints_and_writes_the_fit(jet_csv, tmp_path, capsys):
    out = tmp_path / "r.json"
    status = main(["identify", str(jet_csv), "--model", "mach-spline", "--json", str(out)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert "Mach-dependent output error" in captured.out and "  0.95  " in captured.out
    record = json.loads(out.read_text())
    assert record["method"] == "output_error_mach" and record["source"] == str(jet_csv)
    assert record["airspeed_model"] == "magnitude" and record["mach_ic_max"] > 1.0
    assert abs(record["recovery"] - RECOVERY) < 2 * record["recovery_2sigma"] + 0.002
    assert abs(record["oat_k"] - OAT_K) < 2 * record["oat_2sigma_k"] + 0.05
    assert abs(record["wind_n_mps"] - WIND[0]) < 0.2 and abs(record["wind_e_mps"] - WIND[1]) < 0.2
    assert all("dpp_ps_spline_2sigma" in s for s in record["spe"])


@pytest.mark.parametrize("option", ["--plot", "--params"])
def test_mach_spline_refuses_what_it_does_not_make(jet_csv, tmp_path, capsys, option):
    status = main(["identify", str(jet_csv), "--model", "mach-spline", option,
                   str(tmp_path / "x.png")])
    assert status == 2
    assert f"{option} is not made by --model mach-spline" in capsys.readouterr().err
