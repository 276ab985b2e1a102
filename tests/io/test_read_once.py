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
    assert read_once(first) is first          # a reader given the bytes does not block


def test_a_fifo_read_twice_gives_each_writers_bytes(tmp_path):
    """A FIFO is a channel: the second flight written to it is the second one read (the
    bytes were once cached by path, and a second read returned the first flight)."""
    fifo = tmp_path / "f.fifo"
    os.mkfifo(fifo)
    for text in (b"time_s,qc_pa\n1,2\n", b"time_s,qc_pa\n3,4\n"):
        writer = threading.Thread(target=lambda t=text: fifo.write_bytes(t), daemon=True)
        writer.start()
        assert read_once(fifo).data == text
        writer.join(timeout=5)


def test_stdin_read_twice_gives_the_same_bytes(monkeypatch):
    import io

    class Stdin:
        buffer = io.BytesIO(b"time_s,qc_pa\n1,2\n")

    monkeypatch.setattr(sys, "stdin", Stdin())
    assert read_once("-").data == read_once("-").data == b"time_s,qc_pa\n1,2\n"


@pytest.mark.parametrize("kind", ["bin", "ulg"])
@pytest.mark.parametrize("how", ["stdin", "fifo"])
def test_an_autopilot_log_on_stdin_or_a_fifo_is_read_as_from_its_file(kind, how, tmp_path):
    """A log through a pipe (`cat f.bin | pitotcal convert - ...`) or a FIFO: the same flight
    as from the file, known on stdin by its first bytes."""
    from logwriters import write_dataflash_bin, write_ulog
    from synthetic import synthetic_flight

    flight, _ = synthetic_flight(seed=2, n=3000, rate_hz=10.0)
    log = (write_dataflash_bin if kind == "bin" else write_ulog)(tmp_path / f"f.{kind}", flight)
    log = tmp_path / f"f.{kind}"
    ref = tmp_path / "ref.csv"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    convert = [sys.executable, "-m", "pitotcal", "convert"]
    assert subprocess.run(convert + [str(log), "-o", str(ref)], capture_output=True,
                          timeout=120, env=env).returncode == 0
    out = tmp_path / "out.csv"
    if how == "stdin":
        proc = subprocess.run(convert + ["-", "-o", str(out)], input=log.read_bytes(),
                              capture_output=True, timeout=120, env=env)
    else:
        fifo = tmp_path / f"log.{kind}.fifo" if kind == "ulg" else tmp_path / "log.fifo"
        os.mkfifo(fifo)
        threading.Thread(target=lambda: fifo.write_bytes(log.read_bytes()), daemon=True).start()
        proc = subprocess.run(convert + [str(fifo), "-o", str(out)], capture_output=True,
                              timeout=120, env=env)
    assert proc.returncode == 0, proc.stderr.decode()
    a, b = read_flight(ref), read_flight(out)
    assert a.n == b.n > 100
    for name in ("time_s", "qci_pa", "gps_vn_mps", "rho_kgm3"):
        assert (getattr(a, name) == getattr(b, name)).all(), name


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
