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


def _flat(text):
    return " ".join(text.split())


def _constants():
    """(command, words its --help must contain), the numbers from the library's constants."""
    from pitotcal.core.dynamics import Limits
    from pitotcal.estimation.identification import budget
    from pitotcal.estimation.legs.flight import DETECT_DEFAULTS, POINT_TOL_KT
    from pitotcal.estimation.legs.global_fit import BAND_FT
    from pitotcal.estimation.monitor.cusum import MonitorOptions
    from pitotcal.io.alfa import ALFA_DATA_ENV, ALFA_DIR_NAME
    from pitotcal.io.mavlink_live import IDLE_TIMEOUT_S
    from pitotcal.maneuvers.fly.jsbsim_engine import DEFAULT_AIRCRAFT
    from pitotcal.maneuvers.fly.options import ENGINE_AIR_DATA
    from pitotcal.maneuvers.plan.design import STALL_DEFAULT_RATIO
    from pitotcal.maneuvers.plan.design_request import DesignOptions
    from pitotcal.maneuvers.plan.planner import MAX_ITER
    from pitotcal.maneuvers.plan.request import PlanRequest
    from pitotcal.studies.demo import DEMO_SIM

    from pitotcal.estimation.identification import sensor_inputs

    b, d, m = budget.BudgetInputs(), DesignOptions(), MonitorOptions()
    c = sensor_inputs.CLASS_DEFAULTS[sensor_inputs.DEFAULT_SENSOR_CLASS]
    return [
        ("identify", f"else {budget.RH_U_UNKNOWN_PCT:.0f} (dry assumed"),
        ("identify", f"default {budget.RH_U_GIVEN_PCT:g} with a humidity"),
        ("identify", f"up to {2 * len(budget.SOURCES)} extra solves"),
        ("identify", f"static air temperature, K; default by its source: a probe "
                     f"{c['u_oat_probe_k']:g} (flight-test)"),
        ("identify", f"bias per axis, m/s; default {c['u_gps_velocity_mps']:g}"),
        ("identify", f"time alignment, s; default {c['u_gps_latency_s']:g}"),
        ("identify", f"V_t - r y; default {b.probe_arm_m:g}"),
        ("identify", f"% of reading; default {100 * c['u_qc_scale']:g}"),
        ("identify", f"zero offset, Pa; default {c['u_qc_offset_pa']:g}"),
        ("identify", f"static-pressure transducer, Pa; default {c['u_ps_pa']:g}"),
        ("identify", f"default {100 * sensor_inputs.ARM_U_FRACTION:g} % of --probe-arm-m"),
        *[("legs", f"(default: {value:g})") for value in DETECT_DEFAULTS.values()],
        ("legs", f"form one point (default {POINT_TOL_KT:g})"),
        ("legs", f"one wind per {BAND_FT:,.0f} ft"),
        ("plan", f"roll-rate limit (default: {Limits().roll_rate_max_dps:g})"),
        ("plan", f"acceleration limit (default: {Limits().accel_max_mps2:g})"),
        ("plan", "step-pause levels (default: "
                 f"{PlanRequest().levels})"),
        ("plan", f"iteration limit (default: {MAX_ITER})"),
        ("plan", f"--cas-min-kt / {STALL_DEFAULT_RATIO:g})"),
        ("plan", f"(default: {d.turbulence_mps:g})"),
        ("plan", f"(default: {d.criterion})"),
        ("plan", f"limits the bank (default: {d.stall_margin:g})"),
        ("plan", f"(default: {d.check_fraction:g}; 0: two speeds only)"),
        ("demo", f"the demo's {DEMO_SIM['rate_hz']:g})"),
        ("simulate", f"default {ENGINE_AIR_DATA['own']}, as identify"),
        ("simulate", f"(default {DEFAULT_AIRCRAFT})"),
        ("study", f"${ALFA_DATA_ENV}, else ./{ALFA_DIR_NAME}"),
        ("study", f"JSBSim's {DEFAULT_AIRCRAFT};"),
        *[(command, f"without a message (default {IDLE_TIMEOUT_S:g})")
          for command in ("identify", "monitor")],
        ("monitor", f"per flight hour (default {m.false_alarms_per_hour:g})"),
        ("monitor", f"without alarms (default {m.warmup_s:g})"),
        ("monitor", f"kt/min (default {m.drift_kt_per_min:g})"),
    ]


def test_help_quotes_the_library_constants():
    texts = {name: _flat(text) for name, text in help_texts().items()}
    missing = [(command, words) for command, words in _constants()
               if words not in texts[command]]
    assert not missing, missing
    assert "else 29" not in texts["identify"]           # the 0-100 % rectangular u is 100/√3


def test_help_fields_are_all_filled_and_stay_filled():
    """No ``{name}`` field is left in any help, and a help shown twice is the same."""
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")  # noqa: SLF001
    for name in COMMANDS:
        first = sub.choices[name].format_help()
        assert not re.search(r"\{[a-z_]+(?::[^}]*)?\}", first), (name, first)
        assert sub.choices[name].format_help() == first, name


# Strings of the library that may hold a command-line flag: a command line it runs or records,
# and the commands a result file comes from.
FLAG_STRINGS_ALLOWED = ("--headless", "--no-sandbox", "--disable-gpu", "--no-pdf-header-footer",
                        "--print-to-pdf=", "pitotcal simulate --engine jsbsim",
                        "`pitotcal identify --json`", "`pitotcal legs --json`")
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]+")


def _strings(path):
    """The string constants of a module (f-string parts included), docstrings left out."""
    import ast

    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = {id(node.body[0].value) for node in ast.walk(tree)
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
            and node.body and isinstance(node.body[0], ast.Expr)
            and isinstance(node.body[0].value, ast.Constant)}
    return [node.value for node in ast.walk(tree) if isinstance(node, ast.Constant)
            and isinstance(node.value, str) and id(node) not in docs]


def test_library_messages_name_arguments_not_flags():
    """A message of the library names the Python argument (`oat_k`); the command line shows
    its flag (--oat-c): no flag in the library's strings outside `pitotcal.cli`."""
    found = []
    for path in _package_sources():
        if "cli" in path.parts:
            continue
        for text in _strings(path):
            rest = text
            for allowed in FLAG_STRINGS_ALLOWED:
                rest = rest.replace(allowed, "")
            if FLAG.search(rest):
                found.append(f"{path.name}: {text[:80]!r}")
    assert not found, "\n".join(found)


@pytest.mark.parametrize("argv, message, shown", [
    (["report", "r.json", "-o", "r.html"], "`aircraft_path` a.toml: not valid TOML",
     "--aircraft a.toml: not valid TOML"),
    (["report", "r.json", "-o", "r.html"], "`pdf_path`: Chromium failed", "--pdf: Chromium failed"),
    (["study", "coverage"], "`scheduler` 'tcp://x:1': cannot connect to a Dask scheduler",
     "--scheduler 'tcp://x:1': cannot connect to a Dask scheduler"),
    (["identify", "f.bin"], "not OAT (give the outside air temperature, `oat_k`)",
     "not OAT (give the outside air temperature, --oat-c)"),
    (["identify", "f.bin"], "calibrate it apart (`start_s`, `end_s`)",
     "calibrate it apart (--start-s, --end-s)"),
    # a command without that flag keeps the argument's name
    (["plan", "-o", "p.csv"], "give `oat_k`", "give `oat_k`"),
])
def test_the_command_line_shows_flags_for_the_named_arguments(argv, message, shown):
    from pitotcal.cli import flag_message
    from pitotcal.core.errors import PitotcalError

    parser = build_parser()
    args = parser.parse_args(argv)
    assert flag_message(parser, args, PitotcalError(message)) == shown
    assert flag_message(parser, args, UserWarning(message)) == shown


def test_gitignore_ignores_no_tracked_file():
    """Every .gitignore line is for generated files: none matches a file the repository tracks
    (docs, figures, examples)."""
    import shutil
    import subprocess

    root = Path(__file__).resolve().parents[1]
    if shutil.which("git") is None or not (root / ".git").exists():
        pytest.skip(f"{root} is not a git checkout")
    patterns = [line for line in (root / ".gitignore").read_text().splitlines()
                if line and not line.startswith("#")]
    run = subprocess.run(["git", "ls-files", "-ci", "--exclude-standard"], cwd=root,
                         capture_output=True, text=True, check=True)
    assert patterns and run.stdout == ""
