"""`pitotcal simulate` (docs/interfaces.md): flight CSV + truth JSON, same seed same file,
tolerance warnings, one-line errors that name the flag, the plan never overwritten."""

import json

import pytest
from plans import circle_plan

from pitotcal.cli import main
from pitotcal.io import read_flight
from pitotcal.io.plan_csv import write_plan


@pytest.fixture(scope="module")
def plan_csv(tmp_path_factory):
    return write_plan(circle_plan(), tmp_path_factory.mktemp("sim") / "plan.csv")


def test_writes_flight_and_truth_same_seed_same_file(tmp_path, plan_csv, capsys):
    for name in ("a.csv", "b.csv"):
        assert main(["simulate", str(plan_csv), "-o", str(tmp_path / name), "--seed", "4",
                     "--k1", "0.01", "--turbulence-mps", "1.0"]) == 0
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
    truth = json.loads((tmp_path / "a.truth.json").read_text())
    assert truth["parameters"]["k1"] == 0.01 and truth["options"]["turbulence_mps"] == 1.0
    flight = read_flight(tmp_path / "a.csv")
    assert flight.n == 12001 and flight.meta.get("seed") in (4, "4")
    out = capsys.readouterr().out.splitlines()
    assert out[0] == (f"wrote {tmp_path / 'a.csv'} (12001 samples, 240 s) and "
                      f"{tmp_path / 'a.truth.json'}")
    assert out[1].startswith("truth: inverse k1 0.01, k2 -15; wind ")


def test_model_and_its_default_coefficients(tmp_path, plan_csv, capsys):
    assert main(["simulate", str(plan_csv), "-o", str(tmp_path / "lin.csv"), "--model",
                 "linear", "--turbulence-mps", "0"]) == 0
    assert "truth: linear k1 0.03, k2 -1e-05;" in capsys.readouterr().out
    truth = json.loads((tmp_path / "lin.truth.json").read_text())
    assert truth["model"] == "linear" and truth["k"] == [0.03, -1e-05]


def test_warns_when_the_flight_leaves_the_paper_tolerances(tmp_path, plan_csv, capsys):
    assert main(["simulate", str(plan_csv), "-o", str(tmp_path / "calm.csv"),
                 "--turbulence-mps", "0"]) == 0
    assert "warning" not in capsys.readouterr().err
    assert main(["simulate", str(plan_csv), "-o", str(tmp_path / "rough.csv"),
                 "--turbulence-mps", "2.5", "--seed", "1"]) == 0
    err = capsys.readouterr().err
    assert "warning: the simulated auto-throttle left the ±5 KCAS band (max" in err
    truth = json.loads((tmp_path / "rough.truth.json").read_text())
    assert truth["tracking"]["max_cas_error_kt"] > 5.0


@pytest.mark.parametrize("content, args, message", [
    ("x,y\n1,2\n", [], "missing column time_s"),
    (None, [], "cannot read plan"),
    ("PLAN", ["--model", "cubic"], "--model 'cubic' is not one of constant, linear, inverse"),
    ("PLAN", ["--model", "constant", "--k2", "3"], "--k2: model 'constant' has only 1"),
    # every option the simulator checks is named by its flag
    ("PLAN", ["--rate-hz", "-5"], "--rate-hz -5 must be > 0"),
    ("PLAN", ["--rate-hz", "1e9"], "--rate-hz 1e+09 gives 2.4e+11 samples"),
    ("PLAN", ["--seed", "-1"], "--seed -1 must be >= 0"),
    ("PLAN", ["--wind-speed-mps", "-1"], "--wind-speed-mps -1 must be >= 0"),
    ("PLAN", ["--wind-from-deg", "400"], "--wind-from-deg 400 must be >= 0 and < 360"),
    ("PLAN", ["--wind-drift-n-mps2", "nan"], "--wind-drift-n-mps2 nan must be a finite number"),
    ("PLAN", ["--turbulence-mps", "-1"], "--turbulence-mps -1 must be >= 0"),
    ("PLAN", ["--turbulence-length-m", "0"], "--turbulence-length-m 0 must be > 0"),
    ("PLAN", ["--qc-noise-pa", "-1"], "--qc-noise-pa -1 must be >= 0"),
    ("PLAN", ["--qc-quantization-pa", "inf"], "--qc-quantization-pa inf must be a finite"),
    ("PLAN", ["--qc-bias-pa", "nan"], "--qc-bias-pa nan must be a finite number"),
    ("PLAN", ["--qc-scale-error", "-0.9"], "--qc-scale-error -0.9 must be >= -0.5"),
    ("PLAN", ["--pneumatic-lag-s", "-1"], "--pneumatic-lag-s -1 must be >= 0"),
    ("PLAN", ["--gps-rate-hz", "-1"], "--gps-rate-hz -1 must be >= 0"),
    ("PLAN", ["--gps-noise-mps", "-1"], "--gps-noise-mps -1 must be >= 0"),
    ("PLAN", ["--gps-latency-s", "300"], "--gps-latency-s 300 must be shorter than the plan's"),
])
def test_bad_input_exit_2_one_line_naming_the_flag(tmp_path, plan_csv, capsys, content, args,
                                                   message):
    path = plan_csv
    if content != "PLAN":
        path = tmp_path / "plan.csv"
        if content is not None:
            path.write_text(content)
    assert main(["simulate", str(path), "-o", str(tmp_path / "f.csv"), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pitotcal simulate:") and message in err[0]
    assert not (tmp_path / "f.csv").exists()


def test_never_overwrites_the_plan_and_keeps_truth_beside(tmp_path, capsys):
    plan_path = write_plan(circle_plan(duration_s=60.0), tmp_path / "plan.csv")
    before = plan_path.read_bytes()
    assert main(["simulate", str(plan_path), "-o", str(plan_path)]) == 2
    assert main(["simulate", str(plan_path), "-o", str(tmp_path / "f.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "would overwrite the plan" in err[0]
    assert "the flight is a CSV" in err[1] and "f.truth.json" in err[1]
    # a plan named like a truth file is not overwritten by the truth either
    odd = tmp_path / "x.truth.json"
    odd.write_bytes(before)
    assert main(["simulate", str(odd), "-o", str(tmp_path / "x.csv")]) == 2
    assert plan_path.read_bytes() == before == odd.read_bytes()
    assert not (tmp_path / "f.json").exists() and not (tmp_path / "x.csv").exists()


def test_air_data_compressible_truth(tmp_path, plan_csv, capsys):
    out = tmp_path / "f.csv"
    assert main(["simulate", str(plan_csv), "-o", str(out), "--air-data", "compressible",
                 "--turbulence-mps", "0", "--rate-hz", "2"]) == 0
    assert json.loads((tmp_path / "f.truth.json").read_text())["air_data"] == "compressible"
    assert read_flight(out).meta["air_data"] == "compressible"
    assert main(["simulate", str(plan_csv), "-o", str(out), "--air-data", "ideal"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "pitotcal simulate: --air-data 'ideal' is not one of incompressible, compressible"]


def test_non_finite_truth_coefficient_is_refused(plan_csv, tmp_path, capsys):
    assert main(["simulate", str(plan_csv), "-o", str(tmp_path / "f.csv"), "--k1", "nan"]) == 2
    assert capsys.readouterr().err == "pitotcal simulate: --k1 nan must be a finite number\n"
    assert not (tmp_path / "f.csv").exists()


def test_a_plan_beyond_what_plan_makes_is_refused_before_flying(tmp_path, plan_csv, capsys):
    lines = plan_csv.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    col = lines[header].split(",").index("alt_m")
    cells = lines[header + 3].split(",")
    cells[col] = "1e6"
    lines[header + 3] = ",".join(cells)
    bad = tmp_path / "high.csv"
    bad.write_text("\n".join(lines) + "\n")
    assert main(["simulate", str(bad), "-o", str(tmp_path / "f.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"pitotcal simulate: {bad}: column alt_m, row 3 (line {header + 4}): 1e+06 "
                   "is outside -400 to 32000 m (what a plan can hold)")
    assert not (tmp_path / "f.csv").exists() and not (tmp_path / "f.truth.json").exists()


# --- issue 9: the air-data sensor options ---------------------------------------------------

def test_air_sensor_options(tmp_path, plan_csv, capsys):
    out = tmp_path / "s.csv"
    assert main(["simulate", str(plan_csv), "-o", str(out), "--rate-hz", "5",
                 "--tat-recovery", "0.98", "--rh-percent", "60", "--probe-arm-m", "1",
                 "--oat-bias-k", "0.5", "--gps-bias-mps", "0.1", "0", "0"]) == 0
    sensors = json.loads((tmp_path / "s.truth.json").read_text())["options"]["air_sensors"]
    assert sensors == {"tat_recovery": 0.98, "rh_pct": 60.0, "probe_arm_m": 1.0,
                       "oat_bias_k": 0.5, "gps_bias_mps": [0.1, 0.0, 0.0]}
    flight = read_flight(out)
    assert flight.tat_k is not None and flight.rh_pct[0] == 60.0
    for argv, flag in ((["--rh-percent", "200"], "--rh-percent"),
                       (["--tat-recovery", "-1"], "--tat-recovery"),
                       (["--engine", "jsbsim", "--probe-arm-m", "1"], "--engine own only")):
        capsys.readouterr()
        assert main(["simulate", str(plan_csv), "-o", str(tmp_path / "x.csv"), *argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and flag in err
