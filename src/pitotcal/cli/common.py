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
                             "density (default: the log's airspeed or baro sensor temperature, "
                             "with a warning); a flight CSV carries its own rho_kgm3 or oat_k")


def oat_k_from_c(oat_c):
    """--oat-c in kelvin; a PitotcalError naming the option when it is not an OAT in degC."""
    from pitotcal.core.errors import PitotcalError

    if oat_c is None:
        return None
    lo, hi = OAT_C_RANGE
    if not lo <= oat_c <= hi:
        hint = (" (looks like kelvin: give degrees Celsius, K - 273.15)"
                if 180.0 <= oat_c <= 330.0 else "")
        raise PitotcalError(f"--oat-c {oat_c:g}: not an outside air temperature in degC "
                            f"({lo:g} to {hi:g}){hint}")
    return oat_c + 273.15


def check_output(flag, out, source, what):
    """Refuse an output file on top of the input or in a missing folder, before any work.

    `what` names the input in the message ("log", "flight file").
    """
    from pitotcal.core.errors import PitotcalError

    out = Path(out)
    if out.is_dir():
        raise PitotcalError(f"{flag} {out} is a folder: give the file to write")
    if out.resolve() == Path(source).resolve() or _same_file(out, source):
        raise PitotcalError(f"{flag} {out}: would overwrite the input {what}")
    if not out.resolve().parent.is_dir():
        raise PitotcalError(f"{flag} {out}: directory {out.parent} does not exist")


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
