"""`pitotcal identify --air`: the compressible default on a flight CSV with ps_pa and oat_k,
the incompressible convention on request, and the refusal of an unknown mode."""

import json

import pytest
from plans import circle_plan

from pitotcal.cli import main
from pitotcal.io import read_flight, write_flight_csv


@pytest.fixture(scope="module")
def compressible_csv(tmp_path_factory):
    from pitotcal.maneuvers.fly.simulator import simulate

    plan = circle_plan(duration_s=240.0, cas_kt=(90.0, 150.0), radius_m=1500.0,
                       altitude_m=2438.4, wind_speed_mps=5.0)
    flight, truth = simulate(plan, seed=0, turbulence_mps=0.0, rate_hz=10.0,
                             air_data="compressible")
    return write_flight_csv(flight, tmp_path_factory.mktemp("air") / "flight.csv"), flight, truth


def test_flight_csv_round_trip_keeps_the_static_columns(compressible_csv, tmp_path):
    import dataclasses

    path, flight, _ = compressible_csv
    got = read_flight(path)
    for name in ("ps_pa", "oat_k", "rho_kgm3"):
        assert getattr(got, name) == pytest.approx(getattr(flight, name), rel=1e-8)
    assert got.ps_ref_pa is None
    with_ref = dataclasses.replace(flight, ps_ref_pa=flight.ps_pa - 50.0)
    again = read_flight(write_flight_csv(with_ref, tmp_path / "ref.csv"))
    assert again.ps_ref_pa == pytest.approx(with_ref.ps_ref_pa, rel=1e-8)


@pytest.mark.parametrize("air", ["compressible", "incompressible", None])
def test_air_modes_in_summary_and_json(compressible_csv, tmp_path, capsys, air):
    path, _, truth = compressible_csv
    out = tmp_path / "r.json"
    status = main(["identify", str(path), "--json", str(out)]
                  + ([] if air is None else ["--air", air]))
    captured = capsys.readouterr()
    assert status == 0, captured.err
    d = json.loads(out.read_text())
    assert d["air_data"] == (air or "compressible")
    row = d["airspeed_correction"][0]
    if d["air_data"] == "compressible":
        assert "Assumed: all pressure error in the static source" in captured.out
        assert "Static-source position error" in captured.out
        assert d["static_source"]["assumed"].startswith("all pressure error in the static")
        assert 7500 < d["static_source"]["pressure_altitude_ic_ft"] < 8000
        assert {"mach_i", "dmach", "dh_ft", "dh_2sigma_ft"} <= set(row)
        k1 = d["parameters"]["k1"]
        assert abs(k1["value"] - truth.parameters["k1"]) < 3 * k1["std"]
    else:
        assert "Static-source" not in captured.out and "static_source" not in d
        assert "dh_ft" not in row


def test_unknown_air_mode_exits_2(compressible_csv, capsys):
    path, _, _ = compressible_csv
    status = main(["identify", str(path), "--air", "isentropic"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1
    assert "--air 'isentropic' is not one of compressible, incompressible" in err
