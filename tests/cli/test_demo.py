"""`pitotcal demo` (docs/interfaces.md §6): a short run prints the calibration table next to the
truth and names its files; bad options are one line naming the flag (exit 2)."""

import subprocess
import sys
from pathlib import Path

import pytest

from pitotcal.cli import main

FILES = {"plan.csv", "flight.csv", "flight.truth.json", "result.json", "plan.png",
         "calibration.png", "residuals.png", "report.html"}


def test_short_demo_prints_table_and_files(tmp_path, capsys):
    out_dir = tmp_path / "d"
    args = ["demo", "--out", str(out_dir), "--seed", "1", "--duration-s", "200", "--rate-hz", "25"]
    assert main(args) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == ("pitotcal demo: T-2 case, continuous 70-100 KCAS, 926 m radius, 244 m, "
                      "200 s, 5 m/s wind from 270°, seed 1")
    assert out[1].startswith("identified inverse model from 5001 samples (converged)")
    assert "Airspeed correction ΔV = V_c - V_i (KCAS = V_i + ΔV):" in out
    assert "  V_i kt   ΔV kt    ±2σ kt   truth ΔV kt   inside ±2σ" in out
    assert f"wrote into {out_dir}/:" in out
    assert FILES == {p.name for p in out_dir.iterdir()}
    assert {line.split()[0] for line in out[out.index(f"wrote into {out_dir}/:") + 1:]} == FILES
    assert out[-1].split()[0] == "report.html"          # the demo ends with the report
    assert "Compliance" in (out_dir / "report.html").read_text()


NOT_A_FOLDER = "--out must be a folder (it receives the plan, flight, result and figures); " \
    "FILE is a file"


@pytest.mark.parametrize("args, error", [
    (["--duration-s", "0"], "--duration-s 0 must be > 0"),
    (["--rate-hz", "-5"], "--rate-hz -5 must be > 0"),
    (["--out", "FILE"], NOT_A_FOLDER),
])
def test_bad_options(args, error, tmp_path, capsys):
    (tmp_path / "FILE").write_text("not a folder\n")
    args = [a.replace("FILE", str(tmp_path / "FILE")) for a in args]
    assert main(["demo", "--out", str(tmp_path / "d"), *args]) == 2
    error = error.replace("FILE", str(tmp_path / "FILE"))
    assert capsys.readouterr().err == f"pitotcal demo: {error}\n"


@pytest.mark.slow
def test_pitotcal_demo_cli_defaults(tmp_path):
    script = Path(sys.executable).with_name("pitotcal")      # the installed entry point
    done = subprocess.run([str(script), "demo"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    assert FILES <= {p.name for p in (tmp_path / "pitotcal-demo").iterdir()}
    assert "ΔV kt" in done.stdout and "calibration.png" in done.stdout


def test_python_m_pitotcal_demo_bad_option_exit_status(tmp_path):
    """The same one line through the installed entry point's module (no traceback)."""
    done = subprocess.run([sys.executable, "-m", "pitotcal", "demo", "--out", str(tmp_path),
                           "--duration-s", "0"], capture_output=True, text=True, timeout=60,
                          check=False)
    assert done.returncode == 2 and done.stderr == "pitotcal demo: --duration-s 0 must be > 0\n"
