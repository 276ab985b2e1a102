"""Words a user or a new engineer reads: no history in the package's code or `--help` (it goes
to commit messages and docs/measured.md), and no module paths in `--help`."""

import re
from pathlib import Path

import pytest

import pitotcal
from pitotcal.cli import COMMANDS, build_parser

HISTORY = re.compile(r"\bissues? #?\d|\(issue\b|\bthe issue's\b|\bas before\b", re.IGNORECASE)
# a dotted module path of the package, or a source file name
MODULE_PATH = re.compile(r"\b(?:pitotcal|core|io|estimation|maneuvers|studies|cli)\.[a-z_]+"
                         r"|\b[a-z_]+/[a-z_]+\.py\b")


def _package_sources():
    roots = [Path(p) for p in pitotcal.__path__]
    for sub in ("estimation", "maneuvers", "studies"):
        roots += [Path(p) for p in __import__(f"pitotcal.{sub}", fromlist=["_"]).__path__]
    return sorted({p for root in roots for p in root.rglob("*.py")})


def help_texts():
    """{command: its --help text}, the top-level parser's as "pitotcal"."""
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")  # noqa: SLF001
    return {"pitotcal": parser.format_help(),
            **{name: sub.choices[name].format_help() for name in COMMANDS}}


def test_no_history_in_package_code():
    found = [f"{path.name}:{i}: {line.strip()}" for path in _package_sources()
             for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if HISTORY.search(line)]
    assert len(_package_sources()) > 100
    assert not found, "\n".join(found)


@pytest.mark.parametrize("command", ["pitotcal", *COMMANDS])
def test_help_has_no_history_and_no_module_paths(command):
    text = help_texts()[command]
    assert "usage:" in text
    assert not HISTORY.search(text), HISTORY.search(text)
    assert not MODULE_PATH.search(text), MODULE_PATH.search(text)
