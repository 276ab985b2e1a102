"""Helpers the commands share: the reading options (--start-s, --end-s, --oat-c) and the
output checks.

A command module imports from here, never from another command's module.
"""

import os
from pathlib import Path

# Outside air temperatures anyone calibrates in, degC (ISA at 15 km is -56.5 degC).
OAT_C_RANGE = (-90.0, 60.0)

def add_reading_arguments(parser, prefix=""):
    """--start-s, --end-s and --oat-c, with one meaning wherever a flight or log is read.

    `prefix` starts each help text (e.g. "with --flight: ").
    """
    parser.add_argument("--start-s", type=float, default=None, metavar="S",
                        help=f"{prefix}use only samples with time_s >= S (logs: seconds since "
                             "the log's start)")
    parser.add_argument("--end-s", type=float, default=None, metavar="S",
                        help=f"{prefix}use only samples with time_s <= S")
    parser.add_argument("--oat-c", type=float, default=None, metavar="DEGC",
                        help=f"{prefix}logs only: measured outside air temperature, degC, for "
                             "density (default: a logged OAT sensor, else the log's airspeed or "
                             "baro sensor temperature, with a warning); a flight CSV carries its "
                             "own rho_kgm3 or oat_k")


def oat_k_from_c(oat_c, flag="--oat-c"):
    """--oat-c (or `flag`) in kelvin; a PitotcalError naming the option when it is not an OAT
    in degC."""
    from pitotcal.core.errors import PitotcalError

    if oat_c is None:
        return None
    lo, hi = OAT_C_RANGE
    if not lo <= oat_c <= hi:
        hint = (" (looks like kelvin: give degrees Celsius, K - 273.15)"
                if 180.0 <= oat_c <= 330.0 else "")
        raise PitotcalError(f"{flag} {oat_c:g}: not an outside air temperature in degC "
                            f"({lo:g} to {hi:g}){hint}")
    return oat_c + 273.15


MAX_IDLE_S = 86400.0


def idle_timeout_s(idle_s):
    """--idle-s checked, or the stream reader's own idle timeout when not given."""
    from pitotcal.core.checks import number
    from pitotcal.io.mavlink_live import IDLE_TIMEOUT_S

    if idle_s is None:
        return IDLE_TIMEOUT_S
    # a day without a message is a stream that has ended; beyond it the socket timeout overflows
    return number("idle_s", idle_s, 0.0, MAX_IDLE_S, lo_open=True)


def announce_stream(command, connection, idle_s):
    """One stderr line as a live MAVLink stream starts: where it listens, how long it waits."""
    import sys

    from pitotcal.io.mavlink_live import (
        FIRST_MESSAGE_TIMEOUT_S, LISTENING_PREFIXES, check_connection)

    check_connection(connection)
    how = "listening on" if str(connection).startswith(LISTENING_PREFIXES) else "connecting to"
    print(f"pitotcal {command}: {how} {connection} for MAVLink (up to "
          f"{FIRST_MESSAGE_TIMEOUT_S:g} s for the first message, then ends after {idle_s:g} s "
          "without one, or on Ctrl-C)", file=sys.stderr, flush=True)


def check_outputs(outputs, inputs=(), *, figures=()):
    """Refuse, before any work, an output a command must not or could not write: THE check of
    every command's output paths.

    Parameters
    ----------
    outputs : dict
        {flag: path, or None when not asked for}.
    inputs : iterable of (path or None, str)
        The command's input files, each with how a message names it ("the input log").
    figures : iterable of str
        The flags whose output is a matplotlib figure: a name without extension is written as
        PNG, so ".png" is added before the checks, and the extension must be a format
        matplotlib writes.

    Returns
    -------
    dict
        {flag: the path as written (as given, ".png" added to a figure's bare name), or None}.

    Notes
    -----
    Each output in turn: not a folder, not an input (a hard link or symlink to it counts), its
    folder exists and is writable, an existing file is writable; then no two outputs at one
    path; then the figure formats.
    """
    figures = set(figures)
    for flag, path in outputs.items():
        if path is not None:            # as given, before a figure's ".png" is added
            _check_given(flag, Path(path))
    written = {flag: None if path is None else _as_written(path, flag in figures)
               for flag, path in outputs.items()}
    for flag, out in written.items():
        if out is not None:
            _check_one(flag, Path(out), inputs)
    check_distinct(written)
    for flag in figures:
        if written.get(flag) is not None:
            check_figure_format(flag, outputs[flag])
    return written


def check_output(flag, out, source, what):
    """`check_outputs` of one output and one input; `what` names the input ("log")."""
    _check_one(flag, Path(out), [(source, f"the input {what}")])


def _as_written(path, figure):
    """The path a writer really writes: matplotlib adds ".png" to a name without extension."""
    return f"{path}.png" if figure and not Path(path).suffix else path


def _check_given(flag, out):
    from pitotcal.core.errors import PitotcalError
    from pitotcal.io.atomic import special_file

    if str(out) == "-":                 # stdout carries the summary: no JSON mixed into it
        raise PitotcalError(f"{flag} -: an output here is a file, not stdout (which carries "
                            "the summary): give a file name")
    if out.is_dir():
        raise PitotcalError(f"{flag} {out} is a folder: give the file to write")
    kind = special_file(out)
    if kind:        # renaming a file onto it would replace the FIFO or device itself
        raise PitotcalError(f"{flag} {out} is {kind}, not a file: every output is written "
                            "whole to a regular file; give a file name")


def _check_one(flag, out, inputs):
    from pitotcal.core.errors import PitotcalError

    _check_given(flag, out)
    for source, what in inputs:
        if source is not None and (out.resolve() == Path(source).resolve()
                                   or _same_file(out, source)):
            raise PitotcalError(f"{flag} {out}: would overwrite {what}")
    folder = out.resolve().parent
    if not folder.is_dir():
        raise PitotcalError(f"{flag} {out}: directory {out.parent} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PitotcalError(f"{flag} {out}: directory {out.parent} is not writable")
    if out.exists() and not os.access(out, os.W_OK):
        raise PitotcalError(f"{flag} {out}: the existing file is not writable")


def check_figure_format(flag, path):
    """Refuse a figure extension matplotlib cannot write (no extension: PNG), before any work."""
    from matplotlib.backend_bases import FigureCanvasBase

    from pitotcal.core.errors import PitotcalError

    ext = Path(path).suffix.lower().lstrip(".")
    formats = FigureCanvasBase.get_supported_filetypes()
    if ext and ext not in formats:
        raise PitotcalError(f"{flag} {path}: unknown figure format {ext!r}; use one of "
                            f"{', '.join(sorted(formats))}")


def check_distinct(outputs):
    """Refuse two outputs at one path (hard links included): `outputs` maps flag -> path or
    None (not asked for)."""
    from pitotcal.core.errors import PitotcalError

    given = [(flag, Path(path)) for flag, path in outputs.items() if path is not None]
    for i, (flag, path) in enumerate(given):
        for other, other_path in given[:i]:
            if path.resolve() == other_path.resolve() or _same_file(path, other_path):
                raise PitotcalError(f"{flag} {path}: same file as {other} {other_path}; "
                                    "give each output its own path")


def _same_file(a, b):
    """Both exist and are one file (a hard link or a symlink to it counts)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False
