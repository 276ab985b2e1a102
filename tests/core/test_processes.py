"""Two drawings side by side (a forked child where possible), and Ctrl-C during a solve."""

import os
import signal
import threading

import pytest

from pitotcal.core.processes import EarlyChild, side_by_side, solver_interrupts


def test_both_run_and_the_childs_file_is_there(tmp_path):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    side_by_side(lambda: a.write_text(str(os.getpid())), lambda: b.write_text("parent"))
    assert b.read_text() == "parent" and a.read_text().isdigit()


def test_a_failure_in_the_child_is_raised_here():
    def fail():
        raise ValueError("cannot draw")
    with pytest.raises(ValueError, match="cannot draw"):
        side_by_side(fail, lambda: None)


def test_no_fork_when_sigchld_is_ignored(tmp_path, monkeypatch):
    """A parent ignoring SIGCHLD cannot wait for a child: draw here, one after the other."""
    monkeypatch.setattr(signal, "getsignal",
                        lambda s: signal.SIG_IGN if s == signal.SIGCHLD else signal.SIG_DFL)
    pids = []
    side_by_side(lambda: pids.append(os.getpid()), lambda: pids.append(os.getpid()))
    assert pids == [os.getpid(), os.getpid()]


@pytest.fixture
def python_ctrl_c():
    """Python's own Ctrl-C handler for the test: a process started in the background by a
    non-interactive shell inherits SIGINT ignored, and Python then installs none."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_ctrl_c_swallowed_by_a_solver_is_raised_again(python_ctrl_c):
    def solver_that_catches():
        try:
            signal.raise_signal(signal.SIGINT)
        except KeyboardInterrupt:
            return "failed solve"          # what CasADi does with it
    with pytest.raises(KeyboardInterrupt):
        with solver_interrupts():
            assert solver_that_catches() == "failed solve"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_where_ctrl_c_is_ignored_nothing_changes(monkeypatch):
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with solver_interrupts():
            assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def test_outside_the_main_thread_nothing_changes():
    seen = []
    t = threading.Thread(target=lambda: seen.append(solver_interrupts().__enter__() is None))
    t.start()
    t.join()
    assert seen == [True]


def test_early_child_prepares_then_works_on_what_it_is_sent(tmp_path):
    out = tmp_path / "out.txt"
    with EarlyChild(lambda: None, lambda value: out.write_text(f"{value} {os.getpid()}")) as c:
        assert c.send({"k": 3})
        assert c.join()
    value, pid = out.read_text().rsplit(" ", 1)
    assert value == "{'k': 3}" and int(pid) != os.getpid()


@pytest.mark.parametrize("where", ["prepare", "work"])
def test_early_child_that_fails_says_so(tmp_path, where):
    def fail(*_):
        raise ValueError("cannot draw")
    prepare, work = (fail, lambda v: None) if where == "prepare" else (lambda: None, fail)
    child = EarlyChild(prepare, work)
    child.send(list(range(100_000)))           # more than a pipe holds: no hang either way
    assert child.join() is False


def test_early_child_left_without_input_does_nothing(tmp_path):
    out = tmp_path / "out.txt"
    with pytest.raises(RuntimeError, match="no plan"):
        with EarlyChild(lambda: None, lambda value: out.write_text("drawn")):
            raise RuntimeError("no plan")
    assert not out.exists()


def test_early_child_without_fork_asks_the_caller(monkeypatch):
    monkeypatch.setattr(signal, "getsignal",
                        lambda s: signal.SIG_IGN if s == signal.SIGCHLD else signal.SIG_DFL)
    child = EarlyChild(lambda: None, lambda value: None)
    assert child.send(1) is False and child.join() is False


def test_early_child_given_nothing_did_nothing():
    child = EarlyChild(lambda: None, lambda value: None)
    assert child.join() is False


def test_early_child_abandoned_does_not_wait_for_its_preparation():
    import time

    t0 = time.perf_counter()
    with pytest.raises(RuntimeError):
        with EarlyChild(lambda: time.sleep(30), lambda value: None):
            raise RuntimeError("bad input")
    assert time.perf_counter() - t0 < 10
