"""Inputs that can be read only once: ``-`` (standard input), a FIFO, a pipe, a device.

A flight CSV is opened several times while it is parsed (the binary check, the header, the
body, the row numbers of a message); a FIFO or a pipe gives its bytes to the first reader only
and blocks the next one forever. Such an input is read once, whole, into memory, and every
later opening reads those bytes. A regular file is opened as it is (never loaded twice).
"""

import io
import os
import stat
import sys

__all__ = ["STDIN", "InputBytes", "open_binary", "read_once"]

STDIN = "-"                  # the input path that means standard input
_STDIN_NAME = "stdin"

# Bytes already read from a stream, by its path: a process reads its stdin or a FIFO once,
# and a second read_flight of the same stream (a re-read after a failed guess) gets these.
_READ = {}


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
    key = str(path)
    if key not in _READ:
        if key == STDIN:
            _READ[key] = InputBytes(_STDIN_NAME, sys.stdin.buffer.read())
        else:
            with open(path, "rb") as f:
                _READ[key] = InputBytes(key, f.read())
    return _READ[key]


def open_binary(source):
    """A binary file object of `source` (a path, or `InputBytes` read before)."""
    if isinstance(source, InputBytes):
        return io.BytesIO(source.data)
    return open(source, "rb")           # read-only: an input is never modified
