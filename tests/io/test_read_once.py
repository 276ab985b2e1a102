"""A flight from a FIFO, a pipe or standard input (``-``) is read once, whole, then parsed:
`identify` neither blocks on a FIFO nor says "no header row" on /dev/stdin."""

import json
import os
import subprocess
import sys
import threading

import pytest

import pitotcal
from pitotcal.io import read_flight
from pitotcal.io.flight_csv import write_flight_csv
from pitotcal.io.read_once import InputBytes, read_once


@pytest.fixture(scope="module")
def flight_csv(tmp_path_factory):
    root = tmp_path_factory.mktemp("once")
    flight, _ = pitotcal.simulate(pitotcal.plan_maneuver(), seed=0, turbulence_mps=0.5,
                                  rate_hz=10)
    return write_flight_csv(flight, root / "flight.csv")


def _identify(argv, stdin_bytes=None):
    return subprocess.run([sys.executable, "-m", "pitotcal", "identify", *map(str, argv)],
                          input=stdin_bytes, capture_output=True, timeout=120,
                          env={**os.environ, "MPLBACKEND": "Agg"})


@pytest.mark.parametrize("path", ["-", "/dev/stdin"])
def test_identify_reads_a_pipe_on_stdin(flight_csv, tmp_path, path):
    proc = _identify([flight_csv, "--json", tmp_path / "file.json"])
    assert proc.returncode == 0, proc.stderr.decode()
    proc = _identify([path, "--json", tmp_path / "r.json"], flight_csv.read_bytes())
    assert proc.returncode == 0, proc.stderr.decode()
    ref = json.loads((tmp_path / "file.json").read_text())
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["source"] == path
    assert doc["n_samples"] == read_flight(flight_csv).n == ref["n_samples"]
    for key, value in ref["parameters"].items():       # the same numbers as from the file
        assert doc["parameters"][key]["value"] == value["value"], key
        assert doc["parameters"][key]["std"] == value["std"], key


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_identify_on_a_fifo_reads_it_once(flight_csv, tmp_path):
    fifo = tmp_path / "flight.fifo"
    os.mkfifo(fifo)

    def write_once():
        with open(fifo, "wb") as f:
            f.write(flight_csv.read_bytes())

    writer = threading.Thread(target=write_once, daemon=True)
    writer.start()
    proc = _identify([fifo, "--json", tmp_path / "r.json"])
    writer.join(timeout=5)
    assert proc.returncode == 0, proc.stderr.decode()
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["n_samples"] == read_flight(flight_csv).n


def test_a_regular_file_is_not_loaded_and_a_stream_is_read_once(flight_csv, tmp_path):
    assert read_once(flight_csv) is flight_csv
    fifo = tmp_path / "f.fifo"
    os.mkfifo(fifo)
    threading.Thread(target=lambda: fifo.write_bytes(b"time_s,qc_pa\n1,2\n"), daemon=True).start()
    first = read_once(fifo)
    assert isinstance(first, InputBytes) and first.data == b"time_s,qc_pa\n1,2\n"
    assert read_once(fifo) is first          # a second reader gets the bytes, does not block


def test_garbage_on_stdin_is_one_line(tmp_path):
    proc = _identify(["-"], b"1,2,3\n4,5,6\n")
    err = proc.stderr.decode()
    assert proc.returncode == 2 and err.count("\n") == 1, err
    assert err.startswith("pitotcal identify: stdin: line 1: no header row"), err


def test_legs_reads_a_flight_on_stdin_as_from_the_file(flight_csv):
    def legs(path, data=None):
        return subprocess.run([sys.executable, "-m", "pitotcal", "legs", str(path)], input=data,
                              capture_output=True, timeout=120,
                              env={**os.environ, "MPLBACKEND": "Agg"})

    from_file, from_stdin = legs(flight_csv), legs("-", flight_csv.read_bytes())
    assert from_stdin.returncode == from_file.returncode
    assert from_stdin.stdout == from_file.stdout
    assert from_stdin.stderr.decode() == from_file.stderr.decode().replace(str(flight_csv),
                                                                           "stdin")
