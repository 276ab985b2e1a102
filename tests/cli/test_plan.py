"""`pitotcal plan` (docs/interfaces.md): files and report, refusals that name the flag, the
output checked before the solve, and no python-control on the way."""

import re
import subprocess
import sys

import numpy as np
import pytest

from pitotcal.cli import main
from pitotcal.core.geo import offset_m_from_latlon
from pitotcal.io.plan_csv import read_plan


def test_writes_files_and_reports_track_and_autothrottle(tmp_path, capsys):
    out = tmp_path / "t2.csv"
    assert main(["plan", "--no-figures", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    plan = read_plan(out)
    reach = np.hypot(plan.north_m, plan.east_m).max()
    assert lines[0] == "continuous plan: 240 s, 241 nodes, 33 IPOPT iterations"
    assert lines[1] == (f"  track within {reach:.0f} m of the centre (radius 926 m), bank up to "
                        f"25°, 70-100 KCAS")
    assert lines[2:5] == [f"  plan         {out}", f"  card_txt     {tmp_path / 't2.card.txt'}",
                          f"  autothrottle {tmp_path / 't2.autothrottle.csv'}"]
    assert lines[5] == ("auto-throttle check (PI, Kp 0.392 1/s, Ki 0.0274 1/s², 60° phase "
                        "margin): CAS error max 0.4 kt in still air, 2.4 kt in 0.5 m/s "
                        "turbulence: within ±5 KCAS")
    assert plan.settings["profile"] == "continuous" and plan.settings["radius_m"] == 926.0
    # issue 13 item 2: the card gains lines only with --center
    card = (tmp_path / "t2.card.txt").read_text().splitlines()
    assert card[1].startswith("Altitude 801 ft +-50 ft") and card[4].startswith("HDG: ")
    assert card[6].split() == ["TIME", "KCAS", "BANK", "HDG", "FROM", "CTR", "SPEED", "CUE"]


def test_step_pause_with_options(tmp_path, capsys):
    out = tmp_path / "plan.csv"
    assert main(["plan", "--profile", "step-pause", "--levels", "3", "--turn", "left",
                 "--wind-speed-mps", "0", "--no-figures", "-o", str(out)]) == 0
    assert capsys.readouterr().out.startswith("step-pause plan: 240 s")
    plan = read_plan(out)
    assert plan.settings["levels"] == 3 and plan.settings["turn"] == "left"
    assert "expected wind calm" in (tmp_path / "plan.card.txt").read_text()


REFUSALS = [
    (["--radius-m", "150"], "--radius-m 150 m is below the 399 m turn radius at 91 KCAS"),
    (["--cas-min-kt", "100", "--cas-max-kt", "90"],
     "--cas-min-kt 100 must be below the top of the airspeed range, 90 KCAS"),
    (["--duration-s", "60"], "--duration-s 60 s is too short to turn 360° in each third"),
    (["--profile", "two-speed", "--duration-s", "5"],
     "--duration-s 5 s is too short for 2 levels at the 1 m/s^2 acceleration limit"),
    (["--duration-s", "10"], "--duration-s 10 s is too short for the 1 m/s^2 acceleration"),
    (["--wind-speed-mps", "40"], "--wind-speed-mps 40 is too strong to hold position"),
    # item 7 of issue 8: 400 was silently planned as 040°
    (["--wind-from-deg", "400"], "--wind-from-deg 400 must be >= 0 and < 360"),
    (["--cas-min-kt", "-5"], "--cas-min-kt -5 must be > 0"),
    (["--altitude-m", "40000"], "--altitude-m 40000 must be >= -400 and <= 32000"),   # the ISA
    (["--bank-max-deg", "90"], "--bank-max-deg 90 must be > 0 and <= 75"),
    (["--roll-rate-max-dps", "0"], "--roll-rate-max-dps 0 must be > 0"),
    (["--accel-max-mps2", "nan"], "--accel-max-mps2 nan must be a finite number"),
    (["--profile", "step-pause", "--levels", "1"], "--levels 1 must be >= 2"),
    (["--dt-s", "0.01"], "--dt-s 0.01 s over a 240 s maneuver gives 24000 plan nodes"),
    # item 7: a solver failure is not an infeasible request (`--duration-s 4000 --dt-s 4`
    # needs ~440 iterations: the same failure, quickly)
    (["--max-iter", "3"], ("the path optimiser stopped at its iteration limit, --max-iter 3, "
                           "on 241 nodes (and when minimising the radius): a solver limit, the "
                           "request may well be feasible; raise the limit (e.g. to 6)")),
]


@pytest.mark.parametrize("argv, message", REFUSALS)
def test_refusals_exit_2_one_line_naming_the_flag(argv, message, tmp_path, capsys):
    out = tmp_path / "plan.csv"
    assert main(["plan", *argv, "--no-figures", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pitotcal plan: ") and message in err, err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize("target, message", [
    ("missing/plan.csv", "does not exist"),
    (".", "is a folder: name the plan CSV"),
])
def test_output_checked_before_solving(tmp_path, capsys, monkeypatch, target, message):
    """Item 7 of issue 8: the output folder was checked only after the solve."""
    from pitotcal.maneuvers.plan import planner

    def no_solve(*args, **kwargs):
        raise AssertionError("planned before checking the output")

    monkeypatch.setattr(planner, "plan_maneuver", no_solve)
    assert main(["plan", "-o", str(tmp_path / target)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pitotcal plan: --output {tmp_path / target}") and message in err


def test_plan_command_does_not_import_python_control_or_scipy(tmp_path):
    """Item 8 of issue 8: importing python-control (1.7 s) for the auto-throttle check was most
    of the command's time; the check is plain numpy now."""
    code = ("import sys; from pitotcal.cli import main; "
            f"main(['plan', '--no-figures', '-o', {str(tmp_path / 'p.csv')!r}]); "
            "print(sorted(m for m in ('control', 'scipy') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.splitlines()[-1] == "[]"


def test_export_ardupilot_beside_the_plan(tmp_path, capsys):
    from pymavlink import mavwp

    out = tmp_path / "p.csv"
    assert main(["plan", "--profile", "two-speed", "--radius-m", "600", "--turn", "left",
                 "--center", "-35.363262", "149.165237", "--export", "ardupilot",
                 "--magvar-deg", "11.5", "--no-figures", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert f"  mission      {tmp_path / 'p.waypoints'}" in lines
    assert lines[-1] == ("mission: 2 speed levels 70.0, 100.0 KCAS, loiter 600 m "
                         "counter-clockwise at 244 m MSL, downwind bank 29°, least heading "
                         "turn 379° per coverage group")
    loader = mavwp.MAVWPLoader()
    assert loader.load(str(tmp_path / "p.waypoints")) == 5
    loiter = loader.wp(2)
    assert (loiter.command, loiter.param3, loiter.z) == (19, -600.0, 244.0)
    assert (loiter.x, loiter.y) == pytest.approx((-35.363262, 149.165237), abs=1e-6)
    plan = read_plan(out)
    assert (plan.settings["center_lat_deg"], plan.settings["altitude_ref"]) == (-35.363262,
                                                                                "msl")
    card = (tmp_path / "p.card.txt").read_text().splitlines()
    assert card[1].startswith("Altitude 801 ft MSL +-50 ft")
    centre, start = re.fullmatch(r"Centre (.*) \| start (.*) \(WGS-84\)", card[4]).groups()
    assert centre == "35.36326°S 149.16524°E"
    lat, lon = (float(v) for v in re.findall(r"[\d.]+", start))
    north, east = offset_m_from_latlon(-35.363262, 149.165237, -lat, lon)
    assert (north, east) == pytest.approx((plan.north_m[0], plan.east_m[0]), abs=1.0)
    # magnetic = true - variation (east positive), marked M
    true_hdg = int(re.search(r"heading (\d{3})°", card[3])[1])
    assert card[5] == (f"Magnetic variation 11.5°E: start heading {(true_hdg - 11.5) % 360:03.0f}"
                       f"°M, MAG column = heading °magnetic")
    assert card[8].split()[3:5] == ["HDG", "MAG"] and card[9].split()[4].endswith("M")


@pytest.mark.parametrize("argv, message", [
    (["--export", "px4"], ("--export px4 needs --center LAT LON: the test-area centre the "
                           "mission circles")),
    (["--center", "91", "0"], "--center: lat_deg 91 must be >= -90 and <= 90"),
    (["--center", "0", "180"], "--center: lon_deg 180 must be >= -180 and < 180"),
    (["--magvar-deg", "3"], ("--magvar-deg is for a geo-referenced card: give --center "
                             "LAT LON too")),
    (["--altitude-ref", "agl"], ("--altitude-ref is for a geo-referenced card: give --center "
                                 "LAT LON too")),
    (["--center", "0", "0", "--magvar-deg", "200"],
     "--magvar-deg: magvar_deg 200 must be >= -180 and <= 180"),
])
def test_geo_options_checked_before_solving(argv, message, tmp_path, capsys, monkeypatch):
    from pitotcal.maneuvers.plan import planner

    monkeypatch.setattr(planner, "plan_maneuver", None)
    assert main(["plan", *argv, "--no-figures", "-o", str(tmp_path / "p.csv")]) == 2
    assert capsys.readouterr().err == f"pitotcal plan: {message}\n"


def test_export_refused_before_writing(tmp_path, capsys):
    """The T-2 case as planned (926 m, 240 s) is not what a loiter flies: exit 2, nothing
    written, the values that work named."""
    out = tmp_path / "p.csv"
    assert main(["plan", "--center", "47.4", "8.55", "--export", "px4", "--no-figures",
                 "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pitotcal plan: --duration-s 240 s: a 926 m loiter circle turns "
                          "only 161°") and err.endswith("export a plan with --radius-m 575 m "
                                                        "and --duration-s 290 s or more\n")
    assert list(tmp_path.iterdir()) == []


def test_export_refuses_the_downwind_bank(tmp_path, capsys):
    """A 560 m two-speed plan fits the planner (its path is not a circle) but not a loiter."""
    assert main(["plan", "--profile", "two-speed", "--radius-m", "560", "--center", "0", "0",
                 "--export", "ardupilot", "--no-figures", "-o", str(tmp_path / "p.csv")]) == 2
    assert capsys.readouterr().err == (
        "pitotcal plan: --radius-m 560 m is too small for a loiter: circling it downwind at "
        "57.0 m/s ground speed (101 KTAS in 5 m/s wind) banks 31°, over --bank-max-deg 30°: "
        "export a plan with --radius-m at least 575 m\n")
    assert list(tmp_path.iterdir()) == []


# --- plan --design optimal (issue 13) --------------------------------------------------------

@pytest.mark.parametrize("argv, message", [
    (["--stall-kt", "50"], "--stall-kt is for --design optimal"),
    (["--design", "optimal", "--profile", "two-speed"],
     "--profile two-speed is for --design paper: --design optimal chooses its own"),
    (["--design", "optimal", "--return"], "--return is for --design paper"),
    (["--design", "optimal", "--levels", "3"], "--levels 3 is for --design paper"),
    (["--design", "optimal", "--stall-kt", "62"],
     "--stall-kt 62 KCAS leaves --cas-min-kt 70 below 1.2 x the stall speed at 5° bank"),
    (["--design", "optimal", "--turbulence-mps", "0"], "--turbulence-mps 0 must be > 0"),
    (["--design", "optimal", "--duration-s", "60"],
     ("--duration-s 60 s is too short for an optimal design: each end speed must turn 360° at "
      "30° bank; 134 s is long enough")),
    (["--design", "optimal", "--check-fraction", "0.7"], "--check-fraction 0.7 must be"),
])
def test_design_refusals_exit_2_naming_the_flag(argv, message, tmp_path, capsys):
    out = tmp_path / "plan.csv"
    assert main(["plan", *argv, "--no-figures", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pitotcal plan: ") and message in err, err
    assert not out.exists()


def test_design_optimal_card_and_csv_say_why(tmp_path, capsys):
    out = tmp_path / "opt.csv"
    assert main(["plan", "--design", "optimal", "--check-fraction", "0", "--no-figures",
                 "-o", str(out)]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[0].startswith("optimal plan: 240 s")
    assert re.fullmatch(r"  design: dwells [LH](-[LH])+ \(low, check, high\), \d+% of the "
                        r"end-level time low; predicted worst 2σ of ΔV 0\.\d\d kt in 0\.5 m/s "
                        r"turbulence", printed[2]), printed[2]
    plan = read_plan(out)
    s = plan.settings
    assert s["design"] == "optimal" and s["check_fraction"] == 0.0
    assert len(set(s["levels_qc_pa"])) == 2 and s["predicted_dv_2sigma_kt"] < 1.0
    card = (tmp_path / "opt.card.txt").read_text()
    assert "Designed for information" in card and "predicted dV 2sigma" in card


def test_calibration_gives_kias_targets_that_the_correction_maps_back(tmp_path):
    """--calibration: the card's KIAS at each KCAS target is V_i with V_i + ΔV(V_i) = KCAS."""
    import json

    from pitotcal.core.models import delta_v_kt, get_model

    result = {"model": "inverse", "parameters": {"k1": {"value": 0.02}, "k2": {"value": -15.0},
                                                  "wind_speed_mps": {"value": 5.0}}}
    (tmp_path / "r.json").write_text(json.dumps(result))
    out = tmp_path / "p.csv"
    assert main(["plan", "--profile", "two-speed", "--calibration", str(tmp_path / "r.json"),
                 "--no-figures", "-o", str(out)]) == 0
    card = (tmp_path / "p.card.txt").read_text().splitlines()
    assert card[4].endswith("BANK: within 5° of the cue") and card[5].startswith("KIAS: the indicator's reading")
    head = card.index(next(line for line in card if line.split()[:3] == ["TIME", "KCAS",
                                                                            "KIAS"]))
    rows = [line.split() for line in card[head + 1:] if line.strip()]
    kcas = np.array([float(r[1].split("±")[0]) for r in rows])
    kias = np.array([float(r[2]) for r in rows])
    back = kias + delta_v_kt(get_model("inverse"), (0.02, -15.0), kias)
    # one decimal on the KIAS column (and on the KCAS of a ramp row, whose target is not a
    # whole level); an incompressible calibration's V_c is the equivalent airspeed, within
    # 0.01 kt of the CAS at 244 m
    level = np.isin(kcas, (70.0, 100.0))
    assert level.sum() >= len(rows) - 2
    np.testing.assert_allclose(back[level], kcas[level], atol=0.061)
    np.testing.assert_allclose(back[~level], kcas[~level], atol=0.111)
    # dp/qc = 0.02 - 15/q_ci > 0 at 100 KCAS: the indicator reads low there (ΔV +0.5 kt)
    assert kias[-1] < kcas[-1] - 0.3
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    assert main(["plan", "--calibration", str(bad), "--no-figures", "-o", str(out)]) == 2
