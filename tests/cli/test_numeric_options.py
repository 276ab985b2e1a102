"""Every float option of every command, fed NaN, inf, -1 and 1e300 on a small valid input:
exit 2 with one stderr line naming the flag, or (where the value is legitimate, listed in
ALLOWED) the same exit status as without the option."""

import argparse
import json
import warnings

import pytest
from plans import circle_plan

from pitotcal.cli import build_parser, main
from pitotcal.io.plan_csv import write_plan

VALUES = ("nan", "inf", "-1", "1e300")

# (command, flag) -> the values of VALUES that are legitimate there, and why. Every other
# (command, flag, value) must be refused in one line naming the flag.
ALLOWED = {
    # signed quantities: a negative value is a value
    ("plan", "--center"): {"-1"},                        # latitude, longitude
    ("plan", "--magvar-deg"): {"-1"},                    # west variation
    ("plan", "--ground-elevation-m"): {"-1"},            # below sea level (Schiphol -3 m)
    ("plan", "--altitude-m"): {"-1"},                    # likewise
    ("simulate", "--k2"): {"-1"},
    ("simulate", "--qc-bias-pa"): {"-1"},
    ("simulate", "--oat-bias-k"): {"-1"},
    ("simulate", "--gps-bias-mps"): {"-1"},
    ("simulate", "--probe-arm-m"): {"-1"},               # ahead of or behind the CG
    ("identify", "--probe-arm-m"): {"-1"},
    ("convert", "--oat-c"): {"-1"},                      # a log's OAT, degC
    ("convert", "--oat-ground-c"): {"-1"},               # a ground temperature, degC
    # a limit: a huge one is no limit (the plan converges as without it)
    ("plan", "--roll-rate-max-dps"): {"1e300"},
    ("plan", "--accel-max-mps2"): {"1e300"},
    # a correlation time: a huge one is a constant bias
    ("simulate", "--gps-gm-tau-s"): {"1e300"},
    ("identify", "--gps-error-tau-s"): {"1e300"},
    # a precision target: a huge one is met by any fit (and said so)
    ("identify", "--target-2sigma-kt"): {"1e300"},
    # a time window: a start before the record or an end after it keeps the whole record
    **{(c, "--start-s"): {"-1"} for c in ("identify", "convert", "legs", "monitor")},
    **{(c, "--end-s"): {"1e300"} for c in ("identify", "convert", "legs", "monitor")},
}

# Options that need a companion to mean anything: given with it.
COMPANIONS = {
    ("plan", "--magvar-deg"): ["--center", "47", "8"],
    ("plan", "--ground-elevation-m"): ["--center", "47", "8", "--export", "ardupilot"],
    ("identify", "--gps-error-sigma-mps"): ["--gps-error-tau-s", "30"],
    ("identify", "--gps-error-tau-s"): ["--gps-error-sigma-mps", "0.05"],
}


def _float_options():
    """(command, flag, nargs) of every option whose type is float."""
    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices
    out = []
    for name, sub in commands.items():
        for action in sub._actions:
            if action.option_strings and action.type is float:
                out.append((name, max(action.option_strings, key=len), action.nargs))
    return out


OPTIONS = _float_options()


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """A 60-s plan, its simulated flight (10 Hz) as a CSV and a DataFlash log, and the
    flight's result JSON."""
    from logwriters import write_dataflash_bin

    from pitotcal.io import read_flight

    root = tmp_path_factory.mktemp("numeric")
    plan = write_plan(circle_plan(duration_s=60.0), root / "plan.csv")
    flight, result = root / "flight.csv", root / "result.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["simulate", str(plan), "-o", str(flight), "--rate-hz", "10"]) == 0
        assert main(["identify", str(flight), "--json", str(result)]) == 0
        log = write_dataflash_bin(root / "flight.bin", read_flight(flight)) or root / "flight.bin"
    return {"plan": plan, "flight": flight, "result": result, "log": log}


def _base(command, inputs, out):
    f, r = str(inputs["flight"]), str(inputs["result"])
    return {"demo": ["demo", "--out", str(out / "demo")],
            "plan": ["plan", "-o", str(out / "p.csv"), "--no-figures"],
            "simulate": ["simulate", str(inputs["plan"]), "-o", str(out / "f.csv")],
            "identify": ["identify", f, "--json", str(out / "r.json")],
            "convert": ["convert", str(inputs["log"]), "-o", str(out / "c.csv")],
            "legs": ["legs", f],
            "report": ["report", r, "-o", str(out / "r.html")],
            "monitor": ["monitor", f, "--calibration", r]}[command]


def _run(argv, capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            code = main(argv)
        except SystemExit as stop:
            code = stop.code
    return code, capsys.readouterr().err


_BASELINE = {}


# An option whose companion needs it: the baseline gives it this value instead of none.
PAIRED = {("identify", "--gps-error-sigma-mps"): "0.05", ("identify", "--gps-error-tau-s"): "30"}


def _baseline(command, flag, inputs, tmp_path, capsys):
    """Exit status without the option (with its companions), or with a plain value of it."""
    plain = [flag, PAIRED[(command, flag)]] if (command, flag) in PAIRED else []
    key = (command, tuple(COMPANIONS.get((command, flag), [])) + tuple(plain))
    if key not in _BASELINE:
        tmp_path.mkdir(exist_ok=True)
        _BASELINE[key] = _run(_base(command, inputs, tmp_path) + list(key[1]), capsys)[0]
    return _BASELINE[key]


@pytest.mark.parametrize("command, flag, nargs", OPTIONS, ids=[f"{c} {f}" for c, f, _ in OPTIONS])
def test_every_float_option_refuses_nan_inf_and_out_of_range(inputs, tmp_path, capsys, command,
                                                             flag, nargs):
    problems = []
    for value in VALUES:
        argv = (_base(command, inputs, tmp_path) + COMPANIONS.get((command, flag), [])
                + [flag] + [value] * (nargs or 1))
        code, err = _run(argv, capsys)
        if value in ALLOWED.get((command, flag), ()):
            if code != _baseline(command, flag, inputs, tmp_path / "base", capsys) \
                    or "Traceback" in err:
                problems.append(f"{value}: allowed but exit {code}: {err.strip()}")
        elif not (code == 2 and err.count("\n") == 1 and flag in err and "Traceback" not in err):
            problems.append(f"{value}: exit {code}: {err.strip()[:200]}")
    assert not problems, f"pitotcal {command} {flag}:\n" + "\n".join(problems)


def test_the_table_names_only_real_options():
    real = {(c, f) for c, f, _ in OPTIONS}
    assert set(ALLOWED) | set(COMPANIONS) <= real, (set(ALLOWED) | set(COMPANIONS)) - real
    assert isinstance(build_parser(), argparse.ArgumentParser)
