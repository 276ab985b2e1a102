"""`pitotcal report`: from a real identify result with its flight; JSON and errors."""

import json

import pytest
from reportfixtures import result_json
from synthetic import synthetic_flight

from pitotcal.cli import main
from pitotcal.io import write_flight_csv


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    flight, _ = synthetic_flight(seed=5, n=3000, k=(0.02, -15.0))
    csv = tmp / "flight.csv"
    write_flight_csv(flight, csv)
    result = tmp / "result.json"
    assert main(["identify", str(csv), "--json", str(result)]) == 0
    return csv, result


def test_report_with_flight_has_three_figures_and_provenance(identified, tmp_path, capsys):
    csv, result = identified
    html, out_json = tmp_path / "r.html", tmp_path / "r.json"
    assert main(["report", str(result), "--flight", str(csv), "-o", str(html),
                 "--json", str(out_json), "--speed-range-kt", "72", "95"]) == 0
    out = capsys.readouterr().out
    assert "Compliance (23.1323): not demonstrated, 72.0-95.0 KCAS (given range" in out
    text = html.read_text()
    assert text.count("data:image/png;base64,") == 3    # correction, calibration, track
    assert "does not reproduce" not in text
    assert str(csv) in text and "SHA-256" in text
    block = json.loads(out_json.read_text())["compliance"]
    assert block["speed_range_kt"] == [72.0, 95.0] and block["airspeed"]["verdict"] == "complies"
    assert block["verdict"] == "not demonstrated"        # no static data: no altimeter check


@pytest.mark.parametrize("args, match", [
    (["--regulation", "CS-VLA"], "--regulation 'CS-VLA' is not one of 23.1323, 25.1323, none"),
    (["--speed-range-kt", "90", "80"], "--speed-range-kt 90 80: the highest speed must be"),
    (["--aircraft", "missing.toml"], "missing.toml"),
])
def test_bad_options_exit_2_with_one_line(tmp_path, capsys, args, match):
    res = tmp_path / "res.json"
    res.write_text(json.dumps(result_json()))
    assert main(["report", str(res), "-o", str(tmp_path / "r.html"), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0]


def test_output_on_top_of_input_refused(tmp_path, capsys):
    res = tmp_path / "res.json"
    res.write_text(json.dumps(result_json()))
    assert main(["report", str(res), "-o", str(res)]) == 2
    assert "would overwrite the input result JSON" in capsys.readouterr().err


def test_console_verdict_states_airspeed_and_altimeter(tmp_path, capsys):
    res = tmp_path / "res.json"
    res.write_text(json.dumps(result_json(dv_kt=-1.0, u_kt=1.0, dh_ft=-40.0)))
    assert main(["report", str(res), "-o", str(tmp_path / "r.html")]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("Compliance"))
    assert line.startswith("Compliance (23.1323): does not comply, ")
    assert "airspeed complies, altimeter does not comply" in line


def test_configuration_without_an_airspeed_range_is_said_not_a_traceback(tmp_path, capsys):
    """25.1323(c) has no airspeed range for take-off flaps: the console line says so."""
    res = tmp_path / "res.json"
    res.write_text(json.dumps(result_json(dv_kt=-1.0, u_kt=0.5, dh_ft=20.0, dh_u_ft=3.0,
                                          altitude_ft=5000.0)))
    aircraft = tmp_path / "a.toml"
    aircraft.write_text('[aircraft]\nvsr0_kcas = 60.0\nvsr1_kcas = 70.0\nvfe_kcas = 100.0\n'
                        'vmo_kcas = 110.0\n')
    args = ["report", str(res), "-o", str(tmp_path / "r.html"), "--aircraft", str(aircraft),
            "--regulation", "25.1323", "--configuration", "takeoff"]
    assert main(args) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("Compliance"))
    assert line.startswith("Compliance (25.1323): not demonstrated, no speed range ")
    # the altimeter window 1.23 V_SR0 = 73.8 KCAS to the flown top (1.7 V_SR1 = 119 beyond it)
    assert "altimeter not demonstrated over 73.8-119.0 KCAS" in line


@pytest.mark.parametrize("flag, what", [("--flight", "flight"),
                                        ("--aircraft", "aircraft file")])
@pytest.mark.parametrize("out", ["-o", "--json", "--pdf"])
def test_no_output_on_top_of_any_input(tmp_path, capsys, flag, what, out):
    res, other = tmp_path / "res.json", tmp_path / "input.file"
    res.write_text(json.dumps(result_json()))
    other.write_text("[aircraft]\ntype = 'X'\n")
    args = ["report", str(res), flag, str(other)]
    args += ["-o", str(tmp_path / "r.html")] if out != "-o" else []
    assert main([*args, out, str(other)]) == 2
    assert f"would overwrite the input {what}" in capsys.readouterr().err
    assert other.read_text() == "[aircraft]\ntype = 'X'\n"


def test_incompressible_result_reproduced_with_its_air_data(tmp_path):
    """The re-fit uses the result's air-data mode: an `--air incompressible` result of a flight
    that has ps_pa and oat_k (a compressible fit would differ) is reproduced, no warning."""
    from dataclasses import replace

    import numpy as np

    flight, _ = synthetic_flight(seed=6, n=3000, k=(0.02, -15.0), cas_kt=(90.0, 150.0))
    oat = np.full(flight.n, 288.15)
    flight = replace(flight, oat_k=oat, ps_pa=flight.rho_kgm3 * 287.05287 * oat)
    csv, result = tmp_path / "flight.csv", tmp_path / "result.json"
    write_flight_csv(flight, csv)
    assert main(["identify", str(csv), "--air", "incompressible", "--no-budget",
                 "--json", str(result)]) == 0
    out_json = tmp_path / "r.json"
    assert main(["report", str(result), "--flight", str(csv), "-o", str(tmp_path / "r.html"),
                 "--json", str(out_json)]) == 0
    assert "does not reproduce" not in (tmp_path / "r.html").read_text()


def test_report_reads_the_flight_as_identify_recorded(tmp_path):
    """identify's --temp-recovery, --rh-percent and window go into the JSON ("reading"), and
    `report --flight` reads the flight the same way without being told again: the re-fit
    reproduces the result (with a total temperature the recovery factor moves the fit)."""
    from dataclasses import replace

    import numpy as np

    flight, _ = synthetic_flight(seed=6, n=3000, k=(0.02, -15.0), cas_kt=(90.0, 150.0))
    oat = np.full(flight.n, 288.15)
    flight = replace(flight, tat_k=oat + 3.0, ps_pa=flight.rho_kgm3 * 287.05287 * oat)
    csv, result = tmp_path / "flight.csv", tmp_path / "result.json"
    write_flight_csv(flight, csv)
    assert main(["identify", str(csv), "--temp-recovery", "0.8", "--rh-percent", "60",
                 "--end-s", "55", "--no-budget", "--json", str(result)]) == 0
    reading = json.loads(result.read_text())["reading"]
    assert reading == {"start_s": None, "end_s": 55.0, "oat_k": None, "temp_recovery": 0.8,
                       "rh_pct": 60.0, "oat_source": "tat_k, recovery factor 0.8"}
    html = tmp_path / "r.html"
    assert main(["report", str(result), "--flight", str(csv), "-o", str(html)]) == 0
    assert "does not reproduce" not in html.read_text()
    # told otherwise, the report reads it otherwise (and says the fit differs)
    assert main(["report", str(result), "--flight", str(csv), "-o", str(html),
                 "--temp-recovery", "1.0"]) == 0
    assert "does not reproduce" in html.read_text()


def test_report_refits_with_the_probe_lever_arm_identify_corrected(identified, tmp_path):
    """identify --probe-arm-m corrects the data and records the arm (reading.probe_arm_m);
    `report --flight` corrects it the same way, so its re-fit reproduces the result (it
    re-fitted the uncorrected flight: k1 -0.0016 against the result's -0.0036 on a simulated
    T-2 flight with a 1.5 m arm)."""
    csv, _ = identified
    result = tmp_path / "armed.json"
    assert main(["identify", str(csv), "--probe-arm-m", "1.5", "--no-budget", "--json",
                 str(result)]) == 0
    assert json.loads(result.read_text())["reading"]["probe_arm_m"] == 1.5
    html = tmp_path / "r.html"
    assert main(["report", str(result), "--flight", str(csv), "-o", str(html)]) == 0
    assert "does not reproduce" not in html.read_text()


def test_report_refits_with_the_wind_model_identify_used(tmp_path):
    """identify --wind drifting --wind-knot-s 100 records the drift; `report --flight` fits the
    same drift, so its re-fit reproduces the result (it re-fitted with the default wind, the
    constant one the Wald test keeps here: k1 0.0263 against the result's 0.0200, truth 0.02,
    on this seeded 300-s flight in 0.3 m/s turbulence)."""
    flight, _ = synthetic_flight(seed=3, n=3000, turns=3.0, gps_noise_mps=0.1,
                                 turbulence_mps=0.3)
    csv, result, html = tmp_path / "f.csv", tmp_path / "drift.json", tmp_path / "r.html"
    write_flight_csv(flight, csv)
    assert main(["identify", str(csv), "--wind", "drifting", "--wind-knot-s", "100",
                 "--no-budget", "--json", str(result)]) == 0
    record = json.loads(result.read_text())
    assert record["wind_model"]["kind"] == "drifting" and record["wind_model"]["knot_s"] == 100
    assert abs(record["parameters"]["k1"]["value"] - 0.02) < 2 * record["parameters"]["k1"]["std"]
    assert main(["report", str(result), "--flight", str(csv), "-o", str(html)]) == 0
    assert "does not reproduce" not in html.read_text()


def test_report_warnings_in_json_and_stderr(tmp_path, capsys):
    res, out_json = tmp_path / "res.json", tmp_path / "r.json"
    res.write_text(json.dumps(result_json(dv_kt=-1.0)))       # no dv_U_kt: no expanded U
    assert main(["report", str(res), "-o", str(tmp_path / "r.html"),
                 "--json", str(out_json)]) == 0
    written = json.loads(out_json.read_text())["warnings"]
    assert written[0] == "constructed for a test"            # the result's own, kept
    assert any("no expanded uncertainty U" in w for w in written)
    err = capsys.readouterr().err
    assert "warning: the result has no expanded uncertainty U" in err
    assert "constructed for a test" not in err               # said by identify already


def test_legs_json_is_a_report_input(tmp_path, capsys):
    """`pitotcal legs --json` gives the report: the global fit as the result, the points as
    the legs table (docs/legs-example.csv: truth k1 = 0.03, k2 = -40 Pa)."""
    from pathlib import Path

    example = Path(__file__).resolve().parents[2] / "docs" / "legs-example.csv"
    legs_json, html, out_json = tmp_path / "legs.json", tmp_path / "r.html", tmp_path / "r.json"
    assert main(["legs", str(example), "--json", str(legs_json)]) == 0
    capsys.readouterr()
    assert main(["report", str(legs_json), "-o", str(html), "--json", str(out_json)]) == 0
    text = html.read_text()
    assert 'id="legs-table"' in text and "4-leg" in text
    legs = json.loads(legs_json.read_text())
    out = json.loads(out_json.read_text())
    assert out["airspeed_correction"] == legs["global"]["airspeed_correction"]
    assert out["points"] == legs["points"]
    assert out["compliance"]["airspeed"]["rows"]
    # the leg file's warnings come with it
    assert set(legs["warnings"]) <= set(out["warnings"])
