"""`pitotcal identify` per INTERFACES §3: outputs, exit statuses 0/2/3, one-line errors."""

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from synthetic import synthetic_flight

from pitotcal.cli import main
from pitotcal.io import write_flight_csv

N = 4000


@pytest.fixture(scope="module")
def flight_csv(tmp_path_factory):
    flight, truth = synthetic_flight(seed=5, n=N, turbulence_mps=0.3, gps_rate_hz=5.0,
                                     gps_noise_mps=0.05)
    path = write_flight_csv(flight, tmp_path_factory.mktemp("cli") / "flight.csv",
                            comments={"aircraft": "T-2"})
    return path, truth


def sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def test_identify_writes_summary_json_and_plot(flight_csv, tmp_path, capsys):
    path, truth = flight_csv
    before = sha(path)
    out_json, out_png = tmp_path / "r.json", tmp_path / "r.png"
    status = main(["identify", str(path), "--json", str(out_json), "--plot", str(out_png)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert sha(path) == before
    assert captured.out.startswith(f"Flight: {path} ({N} samples, 0.0-80.0 s)")
    assert "Pressure-error model: inverse   dp/qc = k1 + k2/qci" in captured.out
    assert "KIAS" in captured.out and "wind from" in captured.out
    assert f"Wrote {out_json}" in captured.out and f"Wrote {out_png}" in captured.out
    d = json.loads(out_json.read_text())
    assert d["model"] == "inverse" and d["n_samples"] == N and d["converged"] is True
    assert d["source"] == str(path) and d["n_dropped"] == 0
    assert d["covariance"]["names"] == ["k1", "k2", "wind_speed_mps", "wind_from_deg"]
    for name, true in truth["parameters"].items():
        assert abs(d["parameters"][name]["value"] - true) < 3 * d["parameters"][name]["std"]
    assert out_png.stat().st_size > 20_000


def test_model_auto_window_and_gps_noise_option(flight_csv, tmp_path, capsys):
    path, _ = flight_csv
    out_json = tmp_path / "r.json"
    status = main(["identify", str(path), "--model", "auto", "--start-s", "5", "--end-s", "75",
                   "--gps-noise-mps", "0.05", "--json", str(out_json)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    d = json.loads(out_json.read_text())
    assert {c["model"] for c in d["candidates"]} == {"constant", "linear", "inverse"}
    assert d["criterion"] and "Candidate structures" in captured.out
    assert d["n_samples"] == 3501 and d["gps_noise_std_mps"] == pytest.approx(0.05)


def _write(tmp_path, content, name="bad.csv"):
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return path


def _good_lines(n=200, qc_scale=1.0, nan_rows=()):
    flight, _ = synthetic_flight(seed=6, n=n)
    lines = ["time_s,qc_pa,gps_vn_mps,gps_ve_mps,rho_kgm3"]
    for i in range(n):
        qc = "nan" if i in nan_rows else f"{flight.qci_pa[i] * qc_scale:.6g}"
        lines.append(f"{flight.time_s[i]:.3f},{qc},{flight.gps_vn_mps[i]:.6g},"
                     f"{flight.gps_ve_mps[i]:.6g},{flight.rho_kgm3[i]:.6g}")
    return lines


def _edited(cells=None, scale=None, celsius=False):
    """_good_lines with {(row, column): text} cells, {column: factor} scales, or ps/oat in degC."""
    lines = _good_lines()
    names = lines[0].split(",")
    rows = [line.split(",") for line in lines[1:]]
    for c, k in (scale or {}).items():
        for row in rows:
            row[names.index(c)] = f"{float(row[names.index(c)]) * k:.6g}"
    for (r, c), text in (cells or {}).items():
        rows[r][names.index(c)] = text
    if celsius:                      # rho -> ps_pa at 15 degC, oat written in degC
        names[-1:] = ["ps_pa", "oat_k"]
        rows = [row[:-1] + [f"{float(row[-1]) * 287.05287 * 288.15:.6g}", "15.0"]
                for row in rows]
    return "\n".join([",".join(names)] + [",".join(row) for row in rows]) + "\n"


def _cells(column, text, rows=range(10, 20)):
    return {(r, column): text for r in rows}


BAD = [
    ("not a CSV", "hello world\nthis is text\n", r"bad.csv: line 1: not a CSV header"),
    ("non-numeric", _edited(_cells("gps_vn_mps", "abc")),
     r"bad.csv: column gps_vn_mps, row 11 \(line 12\): non-numeric value 'abc'"),
    ("inf", _edited(_cells("rho_kgm3", "inf")), r"bad.csv: column rho_kgm3, row 11 \(line 12\): "
     "infinite"),
    ("q_ci <= 0", _edited(_cells("qc_pa", "0")),
     r"bad.csv: column qc_pa, row 11 \(line 12\): q_ci = 0 Pa is not positive"),
    ("time backwards", _edited({(30, "time_s"): "-1"}),
     r"bad.csv: column time_s, row 31 \(line 32\): time -1 s is before the previous row's"),
    ("q_ci in kPa", _edited(scale={"qc_pa": 0.001}), r"bad.csv: column qc_pa: median .* looks "
     "like kPa"),
    ("speeds in knots", _edited(scale={"gps_vn_mps": 1.9438, "gps_ve_mps": 1.9438}),
     r"bad.csv: columns gps_vn_mps/gps_ve_mps: median ground speed .* looks like knots"),
    ("oat in Celsius", _edited(celsius=True),
     r"bad.csv: column oat_k: median 15 looks like degrees Celsius"),
    ("empty", "", "bad.csv: empty file"),
    ("binary", b"ULog\x01\x12\x35\x00\x00", r"bad.csv: PX4 ULog file \(name it \.ulg"),
    ("header only", "time_s,qc_pa,gps_vn_mps,gps_ve_mps,rho_kgm3\n", "bad.csv: header only"),
    ("missing column", "time_s,gps_vn_mps,gps_ve_mps,rho_kgm3\n0,1,2,3\n",
     "bad.csv: missing column qc_pa"),
    ("no density", "time_s,qc_pa,gps_vn_mps,gps_ve_mps,ps_pa\n0,1,2,3,4\n",
     r"bad.csv: missing column for density: needs rho_kgm3, or both ps_pa and oat_k"),
    ("NaN rows", "\n".join(_good_lines(nan_rows=range(10, 20))) + "\n",
     r"bad.csv: column qc_pa, row 11 \(line 12\): NaN \(10 of 200 rows unusable"),
    ("duplicate time", "\n".join(_good_lines()[:50] + _good_lines()[49:]) + "\n",
     r"bad.csv: column time_s, row 50 \(line 51\): time .* duplicates the previous"),
    ("q_ci in hPa", "\n".join(_good_lines(qc_scale=0.01)) + "\n",
     r"bad.csv: column qc_pa: median .* looks like hPa"),
]


@pytest.mark.parametrize("case, content, match", BAD, ids=[b[0] for b in BAD])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, case, content, match):
    import re

    path = _write(tmp_path, content)
    before = sha(path)
    status = main(["identify", str(path), "--json", str(tmp_path / "r.json")])
    err = capsys.readouterr().err
    assert status == 2
    assert err.count("\n") == 1 and err.startswith("pitotcal identify: ")
    assert re.search(match, err), err
    assert "Traceback" not in err and not (tmp_path / "r.json").exists()
    assert sha(path) == before


@pytest.mark.parametrize("args, match", [
    (["--model", "quadratic"], "--model 'quadratic' is not one of constant, linear, inverse, auto"),
    (["--start-s", "500"], (r"flight\.csv: column time_s: no rows in the window --start-s 500 "
                            r"\(the file spans 0 to 79.98 s\)")),
    (["--start-s", "50", "--end-s", "10"], "--start-s 50 must be before --end-s 10$"),
    (["--end-s", "nan"], "--end-s nan must be a finite number$"),
    (["--gps-noise-mps", "-1"], "--gps-noise-mps -1 must be >= 0 and <= 10"),
])
def test_bad_options_exit_2(flight_csv, capsys, args, match):
    import re

    path, _ = flight_csv
    status = main(["identify", str(path), *args])
    err = capsys.readouterr().err
    assert status == 2 and re.search(match, err) and err.count("\n") == 1, err


def test_output_on_top_of_input_is_refused(flight_csv, capsys):
    path, _ = flight_csv
    before = sha(path)
    assert main(["identify", str(path), "--json", str(path)]) == 2
    assert "would overwrite the input flight file" in capsys.readouterr().err
    assert sha(path) == before


def test_a_plan_is_named_as_a_plan(tmp_path, capsys):
    from plans import circle_plan

    from pitotcal.io import write_plan

    path = write_plan(circle_plan(duration_s=20.0), tmp_path / "plan.csv")
    assert main(["identify", str(path)]) == 2
    assert capsys.readouterr().err == (
        f"pitotcal identify: {path}: this is a plan (the columns of pitotcal plan), not a flight: "
        "fly or simulate it first (pitotcal simulate PLAN.csv -o FLIGHT.csv)\n")


def test_reader_warnings_are_in_the_json(flight_csv, tmp_path, capsys):
    """Rows dropped by the reader: exit 0, the warning on stderr AND in the JSON's warnings.

    cli/identify.py adds the flight's warnings that the result does not already carry, so this
    holds before and after `identify` itself copies `flight.warnings` into `result.warnings`;
    each warning appears once either way.
    """
    path, _ = flight_csv
    lines = path.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("time_s"))
    for k in range(header + 101, header + 101 + 30 * 7, 7):       # 30 NaN q_ci of 4000 rows
        cells = lines[k].split(",")
        cells[1] = "nan"
        lines[k] = ",".join(cells)
    bad = tmp_path / "nan.csv"
    bad.write_text("\n".join(lines) + "\n")
    out = tmp_path / "r.json"
    assert main(["identify", str(bad), "--json", str(out)]) == 0
    captured = capsys.readouterr()
    warning = (f"{bad}: dropped 30 of 4000 rows with unusable values (first: column qc_pa, "
               "row 101 (line 103): NaN)")
    assert captured.err == f"warning: {warning}\n"
    assert f"({N - 30} samples, 0.0-80.0 s, 30 rows dropped)" in captured.out.splitlines()[0]
    d = json.loads(out.read_text())
    assert d["warnings"].count(warning) == 1 and d["n_dropped"] == 30


def test_missing_file_exits_2(tmp_path, capsys):
    assert main(["identify", str(tmp_path / "nope.csv")]) == 2
    assert "nope.csv: No such file or directory" in capsys.readouterr().err


def test_no_heading_change_exits_3(tmp_path, capsys):
    flight, _ = synthetic_flight(seed=7, n=2000, turns=0.1)
    path = write_flight_csv(flight, tmp_path / "straight.csv")
    status = main(["identify", str(path)])
    err = capsys.readouterr().err
    assert status == 3
    assert err.count("\n") == 1 and "straight.csv" in err and "turns through only" in err


def test_real_subprocess_bad_input_and_good_run(flight_csv, tmp_path):
    bad = _write(tmp_path, "\n".join(_good_lines(qc_scale=0.001)) + "\n")
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    proc = subprocess.run([sys.executable, "-m", "pitotcal", "identify", str(bad)],
                          capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "looks like kPa" in proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    path, _ = flight_csv
    proc = subprocess.run([sys.executable, "-m", "pitotcal", "identify", str(path)],
                          capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "Airspeed correction" in proc.stdout


@pytest.mark.parametrize("args, match", [
    (["--plot", "r.xyz"], r"--plot .*r\.xyz: unknown figure format 'xyz'; use one of .*png"),
    (["--json", "nodir/r.json"], r"--json .*nodir/r\.json: directory .*nodir does not exist"),
    (["--plot", "nodir/r.png"], r"--plot .*nodir/r\.png: directory .*nodir does not exist"),
])
def test_unwritable_outputs_are_refused_before_the_work(flight_csv, tmp_path, capsys, args,
                                                        match):
    import re

    path, _ = flight_csv
    args = [a if a.startswith("--") else str(tmp_path / a) for a in args]
    status = main(["identify", str(path), *args])
    captured = capsys.readouterr()
    assert status == 2 and captured.err.count("\n") == 1 and re.search(match, captured.err), \
        captured.err
    assert captured.out == "" and "Traceback" not in captured.err


def test_plot_without_extension_is_png_and_named(flight_csv, tmp_path, capsys):
    path, _ = flight_csv
    assert main(["identify", str(path), "--plot", str(tmp_path / "fig")]) == 0
    assert f"Wrote {tmp_path / 'fig.png'}" in capsys.readouterr().out
    assert (tmp_path / "fig.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("turbulence_mps, low, high", [(0.0, 0.95, 1.0), (0.5, 1e-4, 0.05)])
def test_auto_effective_n_is_n_over_the_bounds_variance_inflation(turbulence_mps, low, high):
    """N_eff of `--model auto` follows the corrected covariance: ~N in calm air, tiny in gusts."""
    import numpy as np
    from pitotcal.estimation import identify

    flight, _ = synthetic_flight(seed=3, n=N, turbulence_mps=turbulence_mps)
    result = identify(flight, "auto")
    fits = {m: identify(flight, m) for m in ("constant", "linear", "inverse")}
    best = min(fits.values(), key=lambda r: float(r.residuals_pa @ r.residuals_pa))
    shrink = np.diag(best.internal_covariance_plain) / np.diag(best.internal_covariance)
    n_eff = [c["n_eff"] for c in result.candidates]
    assert n_eff == [pytest.approx(min(N, N * np.median(shrink)), rel=1e-9)] * 3
    assert low * N <= n_eff[0] <= high * N
    assert "variance inflation" in result.criterion


# --- issue 9: temperature/humidity options and the uncertainty budget -----------------------

def test_budget_in_summary_json_and_no_budget(flight_csv, tmp_path, capsys):
    path, _ = flight_csv
    out_json = tmp_path / "b.json"
    assert main(["identify", str(path), "--json", str(out_json), "--probe-arm-m", "1.0",
                 "--u-oat-k", "2"]) == 0
    out = capsys.readouterr().out
    assert "Uncertainty budget (GUM; U = 2 u_c" in out and "probe_lever_arm" in out
    d = json.loads(out_json.read_text())
    budget = d["uncertainty_budget"]
    assert budget[0]["source"] == "statistical"
    assert [b["source"] for b in budget[1:]] == ["oat", "humidity", "gps_velocity_bias",
                                                 "gps_latency", "probe_lever_arm", "qc_scale",
                                                 "qc_offset", "static_pressure"]
    by = {b["source"]: b for b in budget}
    assert by["oat"]["u_input"] == 2.0 and by["oat"]["origin"] == "flag --u-oat-k"
    # the arm is corrected in the data: the term is its own 10 %
    assert by["probe_lever_arm"]["u_input"] == pytest.approx(0.1)
    assert by["probe_lever_arm"]["u_dv_kt"] > 0.001 and d["reading"]["probe_arm_m"] == 1.0
    for row in d["airspeed_correction"]:
        # U (k = 2) is at least the statistical 2σ and at most 2σ + 2 Σ u_j
        assert row["dv_2sigma_kt"] <= row["dv_U_kt"]
        assert row["dv_U_kt"] <= row["dv_2sigma_kt"] + 2 * sum(b["u_dv_kt"] for b in budget[1:])
    assert main(["identify", str(path), "--json", str(out_json), "--no-budget"]) == 0
    d = json.loads(out_json.read_text())
    assert "uncertainty_budget" not in d and "dv_U_kt" not in d["airspeed_correction"][0]


@pytest.mark.parametrize("argv, flag", [(["--u-oat-k", "-1"], "--u-oat-k"),
                                        (["--temp-recovery", "1.5"], "--temp-recovery"),
                                        (["--rh-percent", "120"], "--rh-percent"),
                                        (["--u-rh-percent", "-3"], "--u-rh-percent")])
def test_budget_and_air_options_refused(flight_csv, capsys, argv, flag):
    path, _ = flight_csv
    assert main(["identify", str(path), *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and flag in err


def test_no_flight_and_no_live_connection_says_what_to_give(capsys):
    from pitotcal.cli import main

    assert main(["identify"]) == 2
    assert capsys.readouterr().err.strip() == (
        "pitotcal identify: give the FLIGHT to identify (a flight CSV or a ULog/DataFlash log), "
        "or --live CONNECTION")


def test_json_is_the_librarys_record(flight_csv, tmp_path, capsys):
    """`identify --json` writes `IdentificationResult.to_dict()` of `identify` on the flight as
    `read_flight` reads it, with the budget `identify(budget=...)` computes: the CLI adds
    nothing (the source is the path as given)."""
    from pitotcal.estimation import identify
    from pitotcal.estimation.identification.budget import BudgetInputs
    from pitotcal.io import read_flight

    path, _ = flight_csv
    out = tmp_path / "r.json"
    assert main(["identify", str(path), "--end-s", "250", "--u-oat-k", "2",
                 "--json", str(out)]) == 0
    capsys.readouterr()
    written = json.loads(out.read_text())
    flight = read_flight(path, end_s=250.0)
    given = BudgetInputs(u_oat_k=2.0, origins={"u_oat_k": "flag --u-oat-k"})
    record = json.loads(json.dumps(identify(flight, budget=given).to_dict()))
    del written["timing_s"], record["timing_s"]
    assert written == record
    assert written["reading"]["end_s"] == 250.0 and written["source"] == str(path)
    assert {"noise_model", "gps_error", "reading", "uncertainty_budget",
            "budget_inputs"} <= set(written)


def test_sensor_class_from_the_aircraft_file_and_flags(flight_csv, tmp_path, capsys):
    """The class and inputs of the aircraft file's [sensors], a flag over them, and the JSON's
    `budget_inputs` saying where each came from; the text lists them too."""
    path, _ = flight_csv
    toml = tmp_path / "a.toml"
    toml.write_text('[aircraft]\ntype = "T-2"\n[sensors]\nclass = "mems-uav"\n'
                    'u_ps_pa = 80\nu_oat_k = 3.0\n')
    out = tmp_path / "s.json"
    assert main(["identify", str(path), "--aircraft", str(toml), "--u-oat-k", "2",
                 "--oat-source", "user", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "sensor_class: mems-uav (aircraft file sensors.class)" in text
    rows = {r["input"]: r for r in json.loads(out.read_text())["budget_inputs"]}
    assert rows["sensor_class"]["value"] == "mems-uav"
    assert rows["u_ps_pa"] == {"input": "u_ps_pa", "value": 80.0, "unit": "Pa",
                               "origin": "aircraft file sensors.u_ps_pa"}
    assert rows["u_oat_k"]["value"] == 2.0 and rows["u_oat_k"]["origin"] == "flag --u-oat-k"
    assert rows["oat_source"]["value"] == "user"
    assert rows["u_qc_scale"] == {"input": "u_qc_scale", "value": 0.015, "unit": "1",
                                  "origin": "default of class mems-uav"}


@pytest.mark.parametrize("text, shown", [
    ('[sensors]\nclass = "hobby"\n', "sensors.class 'hobby' is not one of"),
    ('[sensors]\nu_ps_pa = -5\n', "sensors.u_ps_pa"),
    ('[sensors]\nu_ps_pb = 5\n', "did you mean sensors.u_ps_pa"),
])
def test_bad_sensor_table_refused(flight_csv, tmp_path, capsys, text, shown):
    path, _ = flight_csv
    toml = tmp_path / "bad.toml"
    toml.write_text(text)
    assert main(["identify", str(path), "--aircraft", str(toml)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and shown in err and "--aircraft" in err
