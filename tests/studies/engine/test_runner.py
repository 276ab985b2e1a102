"""The Monte Carlo engine: seeds, failed runs as rows, serial and Dask paths give equal rows."""

import contextlib
import math

import pytest
from pitotcal.studies.engine.runner import (
    SERIAL_BELOW,
    RunsInterrupted,
    echo_task,
    read_table,
    run_cases,
    run_one,
    write_table,
)


def _cases(n, fail_at=()):
    return [{"value": float(i), "fail": i in fail_at} for i in range(n)]


def test_serial_rows_seeds_and_failures():
    rows = run_cases(echo_task, _cases(5, fail_at={3}), base_seed=100, workers=0)
    assert [r["run_index"] for r in rows] == [0, 1, 2, 3, 4]
    assert [r["seed"] for r in rows] == [100, 101, 102, 103, 104]
    assert rows[2]["twice_seed"] == 204 and rows[2]["error"] == ""
    assert rows[3]["error"] == "RuntimeError: run with seed 103 failed on purpose"
    assert "twice_seed" not in rows[3]


def test_seed_offset_shares_seeds_and_run_one_repeats():
    cases = [{"value": 1.0, "seed_offset": 7}, {"value": 2.0, "seed_offset": 7}, {"value": 3.0}]
    rows = run_cases(echo_task, cases, base_seed=10, workers=0)
    assert [r["seed"] for r in rows] == [17, 17, 12]
    again = run_one(echo_task, cases, 1, base_seed=10)
    assert again[0]["seed"] == 17 and again[0]["value"] == 2.0


@pytest.mark.parametrize("kwargs, match", [
    ({"workers": -1}, "workers -1 must be >= 0"),
    ({"workers": 1.5}, "workers 1.5 must be a whole number"),
])
def test_bad_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        run_cases(echo_task, _cases(2), **kwargs)


def test_run_one_bad_index():
    with pytest.raises(ValueError, match="run_index 9 must be >= 0 and <= 1"):
        run_one(echo_task, _cases(2), 9)


def test_dask_local_cluster_matches_serial():
    n = SERIAL_BELOW + 2
    cases = _cases(n, fail_at={5})
    seen = []
    rows = run_cases(echo_task, cases, base_seed=3, workers=2,
                     progress=lambda done, total: seen.append((done, total)))
    serial = run_cases(echo_task, cases, base_seed=3, workers=0)
    strip = [{k: v for k, v in r.items() if k != "elapsed_s"} for r in rows]
    assert strip == [{k: v for k, v in r.items() if k != "elapsed_s"} for r in serial]
    assert seen[-1] == (n, n) and len(seen) == n


def test_ctrl_c_keeps_the_finished_runs():
    cases = [{"value": float(i), "stop": i == 3} for i in range(6)]
    with pytest.raises(RunsInterrupted) as stop:
        run_cases(echo_task, cases, base_seed=7, workers=0)
    assert (stop.value.n_done, stop.value.n_runs) == (3, 6)
    assert [r["seed"] for r in stop.value.rows] == [7, 8, 9]
    assert isinstance(stop.value, KeyboardInterrupt)     # uncaught, it is still a Ctrl-C


def test_table_round_trip(tmp_path):
    rows = [{"a": 1.0, "b": "x"}, {"a": float("nan"), "c": 2.5}]
    back = read_table(write_table(rows, tmp_path / "t.csv"))
    assert back[0]["a"] == 1.0 and back[0]["b"] == "x" and math.isnan(back[0]["c"])
    assert math.isnan(back[1]["a"]) and back[1]["c"] == 2.5


def test_table_comments_and_leading_columns(tmp_path):
    path = write_table([{"b": 1.0, "a": 2.0}, {"c": 3.0}], tmp_path / "t.csv",
                       comments=["partial: 2 of 3 runs (interrupted)"], columns=("c", "x", "a"))
    assert path.read_text().splitlines()[:2] == ["# partial: 2 of 3 runs (interrupted)", "c,a,b"]
    row = read_table(path)[0]
    assert math.isnan(row["c"]) and (row["a"], row["b"]) == (2.0, 1.0)


@pytest.mark.parametrize("address", ["nonsense", "tcp://127.0.0.1"])
def test_bad_scheduler_address_is_one_line_error(address):
    with pytest.raises(ValueError, match=f"`scheduler` '{address}': cannot connect"):
        run_cases(echo_task, _cases(2), scheduler=address)


@pytest.fixture
def not_dask_port():
    """A local port that answers a connection with bytes that are not Dask's protocol."""
    import socket
    import threading

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    held = []

    def serve():
        with contextlib.suppress(OSError):
            while True:
                conn, _ = server.accept()
                conn.sendall(b"\xff" * 64)      # a length header of ~2**64: garbage
                held.append(conn)

    threading.Thread(target=serve, daemon=True).start()
    yield server.getsockname()[1]
    server.close()


def test_a_port_that_is_not_dask_is_one_line_error_not_a_hang(not_dask_port, monkeypatch):
    from pitotcal.studies.engine import runner

    monkeypatch.setattr(runner, "CONNECT_TIMEOUT_S", 1.0)
    address = f"tcp://127.0.0.1:{not_dask_port}"
    with pytest.raises(ValueError, match=f"`scheduler` '{address}': cannot connect"):
        run_cases(echo_task, _cases(2), scheduler=address)
