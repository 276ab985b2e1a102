"""Issue 15: a value argparse refuses is one line naming the flag (exit 2), never the usage
block, for every command through one mechanism (pitotcal.cli._Parser)."""

import pytest

from pitotcal.cli import main


@pytest.mark.parametrize("argv, line", [
    (["study", "coverage", "--runs", "abc"],
     "pitotcal study: argument --runs: invalid int value: 'abc' (see pitotcal study --help)"),
    (["simulate", "p.csv", "-o", "f.csv", "--engine", "xyz"],
     ("pitotcal simulate: argument --engine: invalid choice: 'xyz' (choose from 'own', "
     "'jsbsim') (see pitotcal simulate --help)")),
    (["identify", "f.csv", "--start-s", "abc"],
     ("pitotcal identify: argument --start-s: invalid float value: 'abc' (see pitotcal "
     "identify --help)")),
    (["simulate", "p.csv"],
     ("pitotcal simulate: the following arguments are required: -o/--output (see pitotcal "
     "simulate --help)")),
    (["report", "r.json", "-o", "x.html", "--speed-range-kt", "60"],
     ("pitotcal report: argument --speed-range-kt: expected 2 arguments (see pitotcal report "
     "--help)")),
    (["nope"], None),
])
def test_a_refused_option_value_is_one_line_naming_the_flag(argv, line, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1 and "usage:" not in err
    if line is not None:
        assert err == line + "\n"
    else:
        assert err.startswith("pitotcal: argument COMMAND: invalid choice: 'nope'")


def test_a_negative_number_in_exponent_form_is_a_value(tmp_path, capsys):
    from plans import circle_plan

    from pitotcal.io.plan_csv import write_plan

    path = write_plan(circle_plan(duration_s=20.0), tmp_path / "plan.csv")
    assert main(["simulate", str(path), "-o", str(tmp_path / "f.csv"), "--k2", "-1e6"]) == 2
    assert "--k2 -1e+06: the inverse pressure error" in capsys.readouterr().err


# --- one check per value: the library's, shown with the flag ---------------------------------

def _library_line(command, argv, exc):
    """The one line the CLI should print for the library's error `exc`: its message with the
    field shown as the flag (pitotcal.cli.flag_message)."""
    from pitotcal.cli import build_parser, flag_message

    parser = build_parser()
    return f"pitotcal {command}: {flag_message(parser, parser.parse_args(argv), exc)}\n"


@pytest.mark.parametrize("flags, fields, flag", [
    (["--gps-noise-mps", "10.5"], {"gps_noise_mps": 10.5}, "--gps-noise-mps"),
    (["--rate-hz", "0"], {"rate_hz": 0.0}, "--rate-hz"),
    (["--model", "cubic"], {"model": "cubic"}, "--model"),
    (["--model", "constant", "--k2", "3"], {"model": "constant", "k": {"k2": 3.0}}, "--k2"),
    (["--k1", "inf"], {"k": {"k1": float("inf")}}, "--k1"),
    (["--wind-drift-e-mps2", "1"], {"wind_drift_mps2": (0.0, 1.0)}, "--wind-drift-e-mps2"),
    (["--gps-gm-tau-s", "0"], {"gps_gm_tau_s": 0.0}, "--gps-gm-tau-s"),
    (["--rh-percent", "200"], {"air_sensors": {"rh_pct": 200.0}}, "--rh-percent"),
    (["--aircraft", "c172x"], {"aircraft": "c172x"}, "--aircraft"),
    (["--engine", "jsbsim", "--air-data", "incompressible"],
     {"engine": "jsbsim", "air_data": "incompressible"}, "--air-data"),
    (["--engine", "jsbsim", "--turbulence-length-m", "300"],
     {"engine": "jsbsim", "turbulence_length_m": 300.0}, "--turbulence-length-m"),
    (["--engine", "jsbsim", "--probe-arm-m", "1"],
     {"engine": "jsbsim", "air_sensors": {"probe_arm_m": 1.0}}, "--probe-arm-m"),
])
def test_simulate_refuses_a_bad_value_once_as_the_library_does(flags, fields, flag, tmp_path,
                                                               capsys):
    from plans import circle_plan

    from pitotcal.core.errors import PitotcalError
    from pitotcal.io.plan_csv import write_plan
    from pitotcal.maneuvers import SimulationOptions

    with pytest.raises(PitotcalError) as info:
        SimulationOptions(**fields)
    path = write_plan(circle_plan(duration_s=20.0), tmp_path / "plan.csv")
    argv = ["simulate", str(path), "-o", str(tmp_path / "f.csv"), *flags]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == _library_line("simulate", argv, info.value) and flag in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.csv"]


@pytest.mark.parametrize("flags, fields, flag", [
    (["--cas-min-kt", "-5"], {"cas_min_kt": -5.0}, "--cas-min-kt"),
    (["--bank-max-deg", "90"], {"bank_max_deg": 90.0}, "--bank-max-deg"),
    (["--profile", "step-pause", "--levels", "1"], {"profile": "step-pause", "levels": 1},
     "--levels"),
    (["--max-iter", "0"], {"max_iter": 0}, "--max-iter"),
    (["--stall-kt", "50"], {"design_options": {"stall_kt": 50.0}}, "--stall-kt"),
    (["--design", "optimal", "--check-fraction", "0.7"],
     {"design": "optimal", "design_options": {"check_fraction": 0.7}}, "--check-fraction"),
])
def test_plan_refuses_a_bad_value_once_as_the_library_does(flags, fields, flag, tmp_path, capsys):
    from pitotcal.core.errors import PitotcalError
    from pitotcal.maneuvers import PlanRequest

    with pytest.raises(PitotcalError) as info:
        PlanRequest(**fields)
    argv = ["plan", *flags, "--no-figures", "-o", str(tmp_path / "p.csv")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == _library_line("plan", argv, info.value) and flag in err
    assert list(tmp_path.iterdir()) == []


def test_gps_noise_bound_is_one_for_simulate_and_identify(tmp_path, capsys):
    """--gps-noise-mps takes 0 to 10 m/s in both commands, from the library's one bound."""
    from synthetic import synthetic_flight

    from pitotcal.core.errors import PitotcalError
    from pitotcal.core.scenario import GPS_NOISE_MAX_MPS
    from pitotcal.estimation import identify
    from pitotcal.io import write_flight_csv
    from pitotcal.maneuvers import SimulationOptions
    from pitotcal.maneuvers.fly.options import SIM_LIMITS

    assert SIM_LIMITS["gps_noise_mps"][0] == GPS_NOISE_MAX_MPS == 10.0
    flight, _ = synthetic_flight(seed=1, n=1500, turbulence_mps=0.0)
    assert identify(flight, gps_noise_std_mps=GPS_NOISE_MAX_MPS).success      # the bound: taken
    assert SimulationOptions(gps_noise_mps=GPS_NOISE_MAX_MPS).gps_noise_mps == 10.0
    for call in (lambda: identify(flight, gps_noise_std_mps=10.5),
                 lambda: SimulationOptions(gps_noise_mps=10.5)):
        with pytest.raises(PitotcalError, match=r"10.5 must be >= 0 and <= 10"):
            call()
    path = write_flight_csv(flight, tmp_path / "f.csv")
    assert main(["identify", str(path), "--gps-noise-mps", "10.5"]) == 2
    line = capsys.readouterr().err
    assert line == "pitotcal identify: --gps-noise-mps 10.5 must be >= 0 and <= 10\n"
