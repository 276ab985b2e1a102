"""Files written whole or not at all: a temporary file in the same folder, then a rename.

A reader never sees half a file, a run cut off (Ctrl-C, a broken pipe, a full disk) leaves the
previous file as it was, and two runs writing the same path give one run's file, never a
splice of both (`os.replace` is atomic on one filesystem).
"""

import contextlib
import os
import stat
import tempfile
from pathlib import Path

from pitotcal.core.errors import PitotcalError

__all__ = ["atomic_open", "atomic_path", "save_figure", "special_file"]

_SPECIAL = ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a device"), (stat.S_ISBLK, "a device"),
            (stat.S_ISSOCK, "a socket"))


def special_file(path):
    """"a FIFO", "a device" or "a socket" when `path` exists as one (a symlink followed),
    else None (a regular file, a folder or nothing)."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return None
    return next((what for test, what in _SPECIAL if test(mode)), None)


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path beside `path`; on success it is renamed onto `path`.

    On an exception the temporary file is removed and `path` is untouched. The new file gets
    the permissions a plain ``open(path, "w")`` would give it (umask applied).

    Raises
    ------
    PitotcalError
        `path` is a FIFO, a device or a socket (``/dev/null`` included): a rename would
        replace it, and a stream cannot be written whole or not at all.
    """
    path = Path(path)
    kind = special_file(path)
    if kind:            # os.replace would put a regular file in place of /dev/null or a FIFO
        raise PitotcalError(f"{path} is {kind}, not a file: pitotcal writes its outputs whole "
                            "to regular files")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_open(path, mode="w", **kwargs):
    """``open(path, mode, **kwargs)`` that writes through `atomic_path`."""
    with atomic_path(path) as tmp, open(tmp, mode, **kwargs) as fh:
        yield fh


def save_figure(fig, path, **kwargs):
    """``fig.savefig(path, **kwargs)`` through `atomic_path` (format from `path`'s suffix)."""
    fmt = kwargs.pop("format", None) or Path(path).suffix.lstrip(".").lower() or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **kwargs)
    return path


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask
