"""Inputs that can be read only once: ``-`` (standard input), a FIFO, a pipe, a device.

A flight CSV is opened several times while it is parsed (the binary check, the header, the
body, the row numbers of a message); a FIFO or a pipe gives its bytes to the first reader only
and blocks the next one forever. Such an input is read once, whole, into memory, and every
later opening reads those bytes. A regular file is opened as it is (never loaded twice).

What a second read gets
    `read_once` of a FIFO reads it anew each time: a FIFO is a channel, and a program that
    reads one flight after another from it gets each (a caller that needs one input twice,
    as `pitotcal legs` does to tell a leg file from a flight, passes the `InputBytes` on).
    Standard input is the process's one stream: once read, every later ``-`` gets the same
    bytes (while ``sys.stdin`` is the same object).

Autopilot logs
    The log libraries read a file by its name: `log_file` gives a stream's bytes to them as a
    temporary file named like the stream (``flight.bin``, or ``stdin.ulg`` by the log's first
    bytes), so a log arrives through a pipe or a FIFO as it would from its file.
"""

import contextlib
import io
import os
import stat
import sys
import tempfile
from pathlib import Path

__all__ = ["STDIN", "InputBytes", "is_stream", "log_file", "log_suffix", "naming", "open_binary",
           "read_once"]

STDIN = "-"                  # the input path that means standard input
_STDIN_NAME = "stdin"
# The first bytes of the autopilot logs pitotcal reads, and the extension that names them.
_LOG_MAGIC = ((b"ULog\x01\x12\x35", ".ulg"), (b"\xa3\x95", ".bin"))

# Standard input once read: (the sys.stdin object it was read from, its InputBytes).
_STDIN_READ = [None, None]


class InputBytes:
    """The whole content of a stream input, read once; `name` is how messages call it."""

    def __init__(self, name, data):
        self.name = name
        self.data = data

    def __str__(self):
        return self.name

    def __fspath__(self):
        # path-like for messages and `Path(...).suffix`: a stream has no extension
        return self.name


def is_stream(path):
    """True for ``-`` and for anything that is not a regular file (FIFO, pipe, device)."""
    if str(path) == STDIN:
        return True
    try:
        return not stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False                 # missing: the ordinary open names the problem


def read_once(path):
    """`path` itself for a regular file; the `InputBytes` of ``-``, a FIFO, a pipe or a device.

    Raises
    ------
    OSError
        The stream cannot be read (as `open` would raise it).
    """
    if isinstance(path, InputBytes) or not is_stream(path):
        return path
    if str(path) != STDIN:
        with open(path, "rb") as f:
            return InputBytes(str(path), f.read())
    if _STDIN_READ[0] is not sys.stdin:
        _STDIN_READ[:] = [sys.stdin, InputBytes(_STDIN_NAME, sys.stdin.buffer.read())]
    return _STDIN_READ[1]


def log_suffix(source):
    """".ulg" or ".bin" when `source` (a path, or `InputBytes`) is a stream whose bytes
    begin as a PX4 ULog or an ArduPilot DataFlash log does, else None."""
    if not isinstance(source, InputBytes):
        return None
    return next((suffix for magic, suffix in _LOG_MAGIC if source.data.startswith(magic)),
                None)


@contextlib.contextmanager
def log_file(source, suffixes):
    """Yield a path the log libraries can open: `source` itself when it is a file, else the
    stream's bytes in a temporary file named like it (with the extension of `suffixes` it
    has, or the one its first bytes show), removed afterwards."""
    source = read_once(source)
    if not isinstance(source, InputBytes):
        yield source
        return
    name = Path(source.name).name or _STDIN_NAME
    if Path(name).suffix.lower() not in suffixes:
        name += log_suffix(source) or ""
    with tempfile.TemporaryDirectory(prefix="pitotcal-") as folder:
        path = Path(folder) / name
        path.write_bytes(source.data)
        yield path


@contextlib.contextmanager
def naming(path):
    """An `OSError` raised inside that names no file (a read's EIO, not an open's ENOENT)
    names `path`: the command line's one line then says which input failed."""
    try:
        yield
    except OSError as exc:
        if not exc.filename:
            exc.filename = str(path)
        raise


def open_binary(source):
    """A binary file object of `source` (a path, or `InputBytes` read before)."""
    if isinstance(source, InputBytes):
        return io.BytesIO(source.data)
    return open(source, "rb")           # read-only: an input is never modified
