"""Issue 15, safe outputs: files are written before anything is printed (a reader that goes
away early never costs a file), outputs of one command are distinct and never the input, and
two writers of one path never splice it."""

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from plans import circle_plan
from synthetic import synthetic_flight

from pitotcal.cli import main
from pitotcal.io import write_flight_csv
from pitotcal.io.plan_csv import write_plan

ENV = {**os.environ, "PYTHONWARNINGS": "ignore"}
PITOTCAL = [sys.executable, "-m", "pitotcal"]


@pytest.fixture(scope="module")
def flight_csv(tmp_path_factory):
    flight, _ = synthetic_flight(seed=5, n=1000, turbulence_mps=0.3)
    return write_flight_csv(flight, tmp_path_factory.mktemp("safe") / "flight.csv")


def sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _identify_into_head(flight, out):
    """`pitotcal identify FLIGHT --json OUT | head -3` through a real shell pipe."""
    cmd = " ".join([*PITOTCAL, "identify", str(flight), "--json", str(out)]) + " | head -3"
    return subprocess.Popen(["bash", "-c", f"set -o pipefail; {cmd}"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=ENV)


@pytest.mark.parametrize("runs", [
    4, pytest.param(20, marks=pytest.mark.slow, id="20-runs")])
def test_head_never_loses_the_json(flight_csv, tmp_path, runs):
    outs = [tmp_path / f"r{i}.json" for i in range(runs)]
    for batch in range(0, runs, 4):                 # four at a time: two cores, shared
        procs = [_identify_into_head(flight_csv, out) for out in outs[batch:batch + 4]]
        for proc in procs:
            stdout, stderr = proc.communicate(timeout=300)
            assert proc.returncode == 0, stderr
            assert stdout.decode().startswith("Flight: ") and stdout.count(b"\n") == 3
            assert b"Traceback" not in stderr
    for out in outs:
        assert json.loads(out.read_text())["converged"] is True


def test_a_pipe_closed_before_the_first_line_still_gets_every_file(flight_csv, tmp_path):
    read_end, write_end = os.pipe()
    os.close(read_end)                              # the reader is gone before we print
    out_json, out_png = tmp_path / "r.json", tmp_path / "r.png"
    proc = subprocess.run([*PITOTCAL, "identify", str(flight_csv), "--json", str(out_json),
                           "--plot", str(out_png)], stdout=write_end, stderr=subprocess.PIPE,
                          env=ENV, timeout=300, check=False)
    os.close(write_end)
    assert proc.returncode == 0 and b"Traceback" not in proc.stderr, proc.stderr
    assert json.loads(out_json.read_text())["n_samples"] == 1000
    assert out_png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("args, match", [
    (["--json", "X.png", "--plot", "X.png"], "--plot .*X.png: same file as --json .*X.png"),
    (["--json", "X.png", "--plot", "X"], "--plot .*X.png: same file as --json .*X.png"),
])
def test_two_outputs_at_one_path_are_refused_before_the_work(flight_csv, tmp_path, capsys,
                                                              args, match):
    import re

    args = [a if a.startswith("--") else str(tmp_path / a) for a in args]
    status = main(["identify", str(flight_csv), *args])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and re.search(match, err), err
    assert list(tmp_path.iterdir()) == []


def test_a_hard_link_to_the_input_is_never_an_output(flight_csv, tmp_path, capsys):
    before = sha(flight_csv)
    link = tmp_path / "r.json"
    os.link(flight_csv, link)
    status = main(["identify", str(flight_csv), "--json", str(link)])
    err = capsys.readouterr().err
    assert status == 2 and "would overwrite the input flight file" in err
    assert sha(flight_csv) == before


def test_legs_and_report_outputs_are_checked_distinct(tmp_path, capsys):
    legs = tmp_path / "legs.csv"
    legs.write_text("point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg\n")
    assert main(["legs", str(legs), "--json", str(tmp_path / "a.png"),
                 "--plot", str(tmp_path / "a")]) == 2
    assert "same file as --json" in capsys.readouterr().err
    result = tmp_path / "r.json"
    result.write_text("{}")
    assert main(["report", str(result), "-o", str(tmp_path / "x.html"),
                 "--json", str(tmp_path / "x.html")]) == 2
    assert "--json" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["legs.csv", "r.json"]


def test_two_simulate_runs_on_one_output_never_splice(tmp_path, capsys):
    plan = write_plan(circle_plan(duration_s=20.0), tmp_path / "plan.csv")
    options = ["--rate-hz", "10"]
    both = [subprocess.Popen([*PITOTCAL, "simulate", str(plan), "-o", str(tmp_path / "same.csv"),
                              "--seed", str(seed), *options], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, env=ENV) for seed in (1, 2)]
    for seed in (1, 2):                     # the reference files, meanwhile, in this process
        assert main(["simulate", str(plan), "-o", str(tmp_path / f"ref{seed}.csv"),
                     "--seed", str(seed), *options]) == 0
    for proc in both:
        _, stderr = proc.communicate(timeout=300)
        assert proc.returncode == 0, stderr
    flight = (tmp_path / "same.csv").read_bytes()
    assert flight in {(tmp_path / f"ref{s}.csv").read_bytes() for s in (1, 2)}
    truth = json.loads((tmp_path / "same.truth.json").read_text())
    assert truth["seed"] in (1, 2)
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".part")]
