"""`pitotcal` command line: parses arguments and delegates to one module per command.

Each `pitotcal/cli/NAME.py` has `add_parser(subparsers)`, which sets `run=` on its parser, and
imports heavy libraries only inside `run`: parsing, a call into the library, printing. Our input
errors (`PitotcalError`) become one line on stderr and the error's exit status
(docs/interfaces.md): never a traceback for bad input. An error about a library parameter
(`PitotcalError.param`, e.g. ``cas_min_kt``) is shown with the command's flag (``--cas-min-kt``).
"""

import argparse
import importlib
import logging
import os
import re
import sys
import warnings

from pitotcal import __version__

COMMANDS = ("demo", "plan", "simulate", "identify", "convert", "study", "legs", "report",
            "monitor")


_NEGATIVE_NUMBER = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")


class _Parser(argparse.ArgumentParser):
    """An option value argparse refuses (``--runs abc``, ``--engine xyz``, a missing argument)
    is one line naming the flag, exit status 2, like our own errors: not the usage block.
    Subcommand parsers are of this class too (argparse makes them of their parent's)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # `--k2 -1e6` is a value, not an option (argparse before 3.13 knows only -1 and -1.5)
        if hasattr(self, "_negative_number_matcher"):
            self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message):
        self.exit(2, f"{self.prog}: {message} (see {self.prog} --help)\n")

    def help_from(self, constants):
        """Fill the ``{name}`` fields of this parser's help texts from `constants()`, a
        function returning {name: value}, when the help is shown: the texts quote the library's
        own constants, and only ``--help`` imports the (numpy-heavy) modules holding them."""
        self._help_constants = constants

    def format_help(self):
        constants = getattr(self, "_help_constants", None)
        if constants is not None:
            values = constants()
            for action in self._actions:
                if action.help and action.help is not argparse.SUPPRESS:
                    action.help = action.help.format_map(values)
            for group in self._action_groups:
                if group.description:
                    group.description = group.description.format_map(values)
            if self.description:
                self.description = self.description.format_map(values)
            self._help_constants = None
        return super().format_help()


def build_parser():
    parser = _Parser(
        prog="pitotcal",
        description="In-flight GPS calibration of pitot-static systems: plan the maneuver, "
                    "simulate it, identify the pressure error and the wind with honest bounds.")
    parser.add_argument("--version", action="version", version=f"pitotcal {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"pitotcal.cli.{name}").add_parser(sub)
    for command in sub.choices.values():
        # -v works after the subcommand too; SUPPRESS keeps a -v given before it
        command.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS,
                             help="log progress details")
    return parser


# The readers' window parameters, shown as the flags where a message names them with a value
# or a rule ("start_s=10", "start_s 5 must be ..."), never inside a file name.
_WINDOW = re.compile(r"(?<![\w/.\\-])(start_s|end_s)(?:(=)|(?= (?:[-+]?[\d.]|must\b|is\b)))")
# Library parameters whose flag has another name (or unit: oat_k is also a flight-CSV column,
# so it is replaced only when the error is about it, or named in backquotes).
_FLAG_DEST = {"oat_k": "oat_c", "oat_ground_k": "oat_ground_c", "gps_noise_std_mps": "gps_noise_mps", "aircraft_path": "aircraft",
              "pdf_path": "pdf"}


# A library message (error or warning) names a Python argument in backquotes (`oat_k`): the
# command line shows the command's flag for it (--oat-c), the Python user reads the argument.
_ARGUMENT = re.compile(r"`([a-z][a-z0-9_]*)`")


def flag_message(parser, args, exc):
    """The error's (or warning's) message as the command's user knows it: the library
    parameters it names (`exc.param`, `exc.mentions`, e.g. ``cas_min_kt``, or any in
    backquotes, ```oat_k```) and the window parameters shown as flags (``--cas-min-kt``,
    ``--oat-c``, ``start_s=10`` as ``--start-s 10``)."""
    message = str(exc)
    command = parser._subparsers._group_actions[0].choices[args.command]
    flags = {a.dest: max(a.option_strings, key=len) for a in command._actions if a.option_strings}
    message = _WINDOW.sub(lambda m: (flags[m[1]] + (" " if m[2] else "")) if m[1] in flags
                          else m[0], message)
    # the backquoted names first: `columns` becomes --columns, never `--columns`
    message = _ARGUMENT.sub(lambda m: flags.get(_FLAG_DEST.get(m[1], m[1]), m[0]), message)
    names = [getattr(exc, "param", None), *getattr(exc, "mentions", ())]
    for name in filter(None, names):
        flag = flags.get(_FLAG_DEST.get(name, name))
        if flag:            # the parameter as a word of its own, not part of a file name
            message = re.sub(rf"(?<![\w/.\\-]){re.escape(name)}(?![\w/.\\-])", flag, message)
    return message


def _warning_printer(parser, args):
    """`warnings.showwarning` of the command line: one ``warning:`` line, with its flags."""
    def show(message, category, filename, lineno, file=None, line=None):
        print(f"warning: {flag_message(parser, args, message)}", file=file or sys.stderr)

    return show


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(message)s")
    warnings.showwarning = _warning_printer(parser, args)
    from pitotcal.core.errors import PitotcalError

    try:
        return int(args.run(args) or 0)
    except BrokenPipeError:
        # the reader of our output (`| head`) went away: not an error of ours; silence the
        # interpreter's own complaint when it flushes stdout at exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except PitotcalError as exc:
        print(f"pitotcal {args.command}: {flag_message(parser, args, exc)}", file=sys.stderr)
        return exc.exit_status
    except OSError as exc:
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"pitotcal {args.command}: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"pitotcal {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
