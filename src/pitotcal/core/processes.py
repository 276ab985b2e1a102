"""Process-level helpers: two drawings side by side on two cores, a child started before its
input exists (its slow imports overlap the parent's work), and Ctrl-C during a solve.

Both concern the operating system, not the physics; they live here so that every layer can
use the one version.
"""

import contextlib
import os
import pickle
import signal
import sys
import threading
import warnings

__all__ = ["EarlyChild", "side_by_side", "solver_interrupts"]


def _can_fork():
    """Fork only on Linux, from the main thread, and where the caller can wait for the child
    (a parent that ignores SIGCHLD has its children reaped by the kernel)."""
    return (sys.platform.startswith("linux") and hasattr(os, "fork")
            and threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGCHLD) != signal.SIG_IGN)


def _fork():
    """`os.fork()`, or None where forking is not possible or fails."""
    if not _can_fork():
        return None
    try:
        with warnings.catch_warnings():
            # Python >= 3.12 warns about fork in a threaded process; the only other threads
            # here are the BLAS pool's, idle, and the child only draws and writes files
            warnings.simplefilter("ignore", DeprecationWarning)
            return os.fork()
    except OSError:
        return None


def side_by_side(first, second):
    """Run `first()` in a forked child while `second()` runs here, and wait for the child.

    One after the other where forking is not possible or fails. A child that fails, or whose
    end cannot be seen, has `first()` re-run here, so its error, if any, is raised as usual.
    `first` must only write files (the child leaves with `os._exit`: no output is flushed
    twice, nothing is cleaned up twice).
    """
    pid = _fork()
    if pid is None:
        first()
        second()
        return
    if pid == 0:                                   # the child: do `first`, and leave at once
        status = 1
        try:
            first()
            status = 0
        finally:
            os._exit(status)
    try:
        second()
    finally:
        try:
            _, status = os.waitpid(pid, 0)
            ok = os.waitstatus_to_exitcode(status) == 0
        except ChildProcessError:
            ok = False
    if not ok:
        first()


class EarlyChild:
    """A forked child started before its input exists: it runs `prepare()` at once (slow
    imports, while this process computes the input), then `work(value)` on the one value
    `send` gives it.

    `work` must only write files (the child leaves with `os._exit`). `join` says whether the
    child did the work; when it did not (no fork on this platform, a failure in the child, the
    value not picklable), the caller does the work itself, so that an error is raised as usual.
    Use as a context manager: leaving the block before `send` (an error while computing the
    input) stops the child at once, before it does anything; after `send`, it is waited for.
    """

    def __init__(self, prepare, work):
        self._pid = self._write_fd = None
        self._sent = False
        read_fd, write_fd = os.pipe()
        pid = _fork()
        if pid == 0:                               # the child
            os.close(write_fd)
            status = 1
            try:
                prepare()
                with os.fdopen(read_fd, "rb") as fh:
                    data = fh.read()
                if data:                           # nothing: the parent gave up
                    work(pickle.loads(data))
                status = 0
            finally:
                os._exit(status)
        os.close(read_fd)
        if pid is None:
            os.close(write_fd)
            return
        self._pid, self._write_fd = pid, write_fd

    @property
    def sent(self):
        """Whether `send` gave the child its input."""
        return self._sent

    def send(self, value):
        """Give the child its input; False if it cannot have it (the caller does the work)."""
        if self._write_fd is None:
            return False
        try:
            data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
            with os.fdopen(self._write_fd, "wb") as fh:
                self._write_fd = None
                self._sent = True
                fh.write(data)
        except (OSError, pickle.PicklingError, TypeError, AttributeError):
            return False
        return True

    def join(self):
        """Wait for the child; True if it did the work (it was sent its input and succeeded)."""
        self._close()
        if self._pid is None:
            return False
        pid, self._pid = self._pid, None
        try:
            _, status = os.waitpid(pid, 0)
        except ChildProcessError:
            return False
        return self._sent and os.waitstatus_to_exitcode(status) == 0

    def _close(self):
        if self._write_fd is not None:
            fd, self._write_fd = self._write_fd, None
            os.close(fd)                           # the child reads nothing and leaves

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._close()
        if self._pid is not None and not self._sent:
            # it has nothing to do: no need to wait for its `prepare` (our own child, by pid)
            with contextlib.suppress(ProcessLookupError):
                os.kill(self._pid, signal.SIGKILL)
        if self._pid is not None:
            self.join()
        return False


@contextlib.contextmanager
def solver_interrupts():
    """Let Ctrl-C stop a CasADi solve.

    CasADi catches the KeyboardInterrupt that Python raises inside a solver callback and
    returns a failed solve (`NonIpopt_Exception_Thrown`), which would read as an ordinary
    failure. Inside this block a Ctrl-C is noted, and KeyboardInterrupt is raised again when the
    solve returns. Where Ctrl-C is ignored (Dask workers) or outside the main thread, nothing
    changes.
    """
    previous = signal.getsignal(signal.SIGINT)
    if (threading.current_thread() is not threading.main_thread()
            or previous in (signal.SIG_IGN, None)):
        yield
        return
    hit = []

    def note(signum, frame):
        hit.append(signum)
        raise KeyboardInterrupt

    signal.signal(signal.SIGINT, note)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if hit:
        raise KeyboardInterrupt
