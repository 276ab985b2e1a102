"""`pitotcal plan`: plan a calibration maneuver and write its CSV, pilot card and setpoints
(docs/interfaces.md). Defaults are the T-2 case of the reference paper."""

import dataclasses
import sys


def add_parser(subparsers):
    # numpy-free modules: the parser is built for every command
    from pitotcal.core.plan import PROFILES, TURNS
    from pitotcal.core.scenario import T2_PLAN

    p = subparsers.add_parser(
        "plan", help="plan a calibration maneuver (CasADi/IPOPT)",
        description="Plan a calibration maneuver: the airspeed schedule holds q uniform (or in "
                    "equal steps), the optimised ground track stays inside the radius in the "
                    "wind and turns through every 30° heading sector in each third of the q "
                    "range. Writes PLAN.csv and beside it PLAN.card.txt/.card.png (pilot "
                    "card), PLAN.autothrottle.csv and PLAN.png (plan figure).")
    p.add_argument("--profile", choices=PROFILES, default=None,
                   help=f"airspeed schedule (default: {T2_PLAN['profile']}; not with "
                        f"--design optimal, which chooses its own)")
    for name, unit in (("cas-min-kt", "KCAS"), ("cas-max-kt", "KCAS"), ("radius-m", "m"),
                       ("altitude-m", "m"), ("duration-s", "s"), ("bank-max-deg", "deg"),
                       ("wind-speed-mps", "m/s"),
                       ("wind-from-deg", "deg true, blowing from, 0-360")):
        p.add_argument(f"--{name}", type=float, default=T2_PLAN[name.replace("-", "_")],
                       metavar=unit.split()[0], help=f"{unit} (default: %(default)g)")
    p.add_argument("--roll-rate-max-dps", type=float, default=None, metavar="DEG/S",
                   help="roll-rate limit (default: 10)")
    p.add_argument("--accel-max-mps2", type=float, default=None, metavar="M/S2",
                   help="acceleration limit (default: 1)")
    p.add_argument("--levels", type=int, default=None, help="step-pause levels (default: 4)")
    p.add_argument("--return", dest="return_leg", action="store_true",
                   help="continuous profile: sweep back down to --cas-min-kt")
    p.add_argument("--turn", choices=(*TURNS, "both"), default=TURNS[0],
                   help="turn direction; both: right and left orbits alternate from one "
                        "speed group to the next, so a probe lever-arm term averages out "
                        "(default: %(default)s)")
    p.add_argument("--dt-s", type=float, default=1.0, help="plan node spacing (default: 1 s)")
    p.add_argument("--max-iter", type=int, default=None, metavar="N",
                   help="IPOPT iteration limit (default: 300)")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG files")
    p.add_argument("--center", nargs=2, type=float, default=None, metavar=("LAT", "LON"),
                   help="test-area centre, degrees WGS-84: the card gives coordinates and "
                        "--export can place the mission")
    p.add_argument("--export", choices=("ardupilot", "px4"), default=None,
                   help="also write the plan as an autopilot mission beside PLAN.csv: "
                        "PLAN.waypoints (QGC WPL 110, ArduPilot/Mission Planner) or PLAN.plan "
                        "(QGroundControl, PX4); needs --center")
    p.add_argument("--altitude-ref", choices=("msl", "agl"), default=None,
                   help="what --altitude-m is measured from on the card and in the mission "
                        "(default: msl, the altitude whose ISA pressure and temperature give "
                        "the TAS)")
    p.add_argument("--magvar-deg", type=float, default=None, metavar="DEG",
                   help="magnetic variation, east positive: the card adds magnetic headings")
    _add_design_arguments(p)
    p.add_argument("--calibration", default=None, metavar="RESULT.json",
                   help="a prior `identify --json` result: the card adds the KIAS the "
                        "uncalibrated indicator shows at each KCAS target")
    p.add_argument("-o", "--output", required=True, metavar="PLAN.csv", help="plan CSV to write")
    p.set_defaults(run=run)


def run(args):
    from pitotcal.maneuvers.plan.autothrottle import autothrottle_report
    from pitotcal.maneuvers.plan.outputs import check_output_paths, write_plan_outputs
    from pitotcal.maneuvers.plan.planner import MAX_ITER, check_converged, plan_maneuver

    figures = not args.no_figures
    max_iter = MAX_ITER if args.max_iter is None else args.max_iter
    paths = check_output_paths(args.output, figures=figures)
    geo = _geo_settings(args)
    _check_outputs(args, paths)
    calibration = _calibration(args.calibration)
    design_options = _design_options(args)          # fills in --profile's default
    plan = plan_maneuver(
        args.profile, args.cas_min_kt, args.cas_max_kt, args.radius_m, args.altitude_m,
        args.duration_s, args.bank_max_deg, args.wind_speed_mps, args.wind_from_deg,
        roll_rate_max_dps=args.roll_rate_max_dps, accel_max_mps2=args.accel_max_mps2,
        levels=4 if args.levels is None else args.levels, return_leg=args.return_leg, turn=args.turn, dt_s=args.dt_s,
        max_iter=max_iter, design=args.design, design_options=design_options)
    check_converged(plan, max_iter)
    if geo or calibration:
        plan = dataclasses.replace(plan, settings={**plan.settings, **geo, **calibration})
    mission = None
    if args.export:
        # refused (the loiter's bank or heading coverage) before any file is written
        from pitotcal.maneuvers.plan.missions import build_mission

        mission = build_mission(plan, *args.center, altitude_ref=args.altitude_ref)
    paths = write_plan_outputs(plan, args.output, figures=figures)
    if mission is not None:
        from pitotcal.maneuvers.plan.missions import mission_path, write_mission

        paths["mission"] = write_mission(mission, mission_path(args.output, args.export),
                                         args.export)
    print(plan.summary())
    s = plan.settings
    if s.get("design") == "optimal":
        print(f"  design: dwells {s['dwell_order']} (low, check, high), {s['low_share']:.0%} of "
              f"the end-level time low; predicted {s['criterion']} 2σ of ΔV "
              f"{s['predicted_dv_2sigma_kt']:.2f} kt in {s['turbulence_mps']:g} m/s turbulence")
    for kind, path in paths.items():
        print(f"  {kind:12s} {path}")
    sys.stdout.flush()
    print(autothrottle_report(plan))
    if mission is not None:
        print(mission.summary())
    return 0


def _geo_settings(args):
    """The checked --center, --magvar-deg and --altitude-ref as plan settings ({} without
    --center: the plan and card are then what they always were)."""
    from pitotcal.core.errors import PitotcalError

    if args.center is None:
        if args.export:
            raise PitotcalError(f"--export {args.export} needs --center LAT LON: the "
                                f"test-area centre the mission circles")
        for flag, value in (("--magvar-deg", args.magvar_deg),
                            ("--altitude-ref", args.altitude_ref)):
            if value is not None:
                raise PitotcalError(f"{flag} is for a geo-referenced card: give --center "
                                    f"LAT LON too")
        return {}
    args.altitude_ref = args.altitude_ref or "msl"
    from pitotcal.core.checks import number
    from pitotcal.core.geo import check_lat_lon

    try:
        lat, lon = check_lat_lon(*args.center)
        magvar = None if args.magvar_deg is None else number(
            "magvar_deg", args.magvar_deg, -180.0, 180.0)
    except PitotcalError as exc:
        name = "--magvar-deg" if exc.param == "magvar_deg" else "--center"
        raise PitotcalError(f"{name}: {exc}") from None
    if args.export:
        from pathlib import Path

        from pitotcal.maneuvers.plan.missions import mission_path

        target = mission_path(args.output, args.export)
        if target.resolve() == Path(args.output).resolve():
            raise PitotcalError(f"--output {args.output}: the {args.export} mission would "
                                f"overwrite it (name the plan CSV .csv)")
    geo = {"center_lat_deg": lat, "center_lon_deg": lon, "altitude_ref": args.altitude_ref}
    if magvar is not None:
        geo["magvar_deg"] = magvar
    return geo


_DESIGN_FLAGS = {"turbulence_mps": "--turbulence-mps", "criterion": "--criterion",
                 "target_2sigma_kt": "--target-2sigma-kt", "stall_kt": "--stall-kt",
                 "stall_margin": "--stall-margin", "check_fraction": "--check-fraction"}


def _add_design_arguments(p):
    p.add_argument("--design", choices=("paper", "optimal"), default="paper",
                   help="paper: --profile's schedule; optimal: the speed schedule that "
                        "minimises the predicted 2σ of ΔV in turbulence (default: paper)")
    g = p.add_argument_group("optimal design (with --design optimal)")
    g.add_argument("--turbulence-mps", type=float, default=None, metavar="M/S",
                   help="RMS gust the design is for (default: 0.5)")
    g.add_argument("--criterion", choices=("worst", "average"), default=None,
                   help="minimise the worst or the mean 2σ of ΔV over the range "
                        "(default: worst)")
    g.add_argument("--target-2sigma-kt", type=float, default=None, metavar="KT",
                   help="plan the shortest flight whose predicted 2σ of ΔV meets this "
                        "(replaces --duration-s)")
    g.add_argument("--stall-kt", type=float, default=None, metavar="KCAS",
                   help="stall speed (default: --cas-min-kt / 1.3)")
    g.add_argument("--stall-margin", type=float, default=None, metavar="X",
                   help="cas-min must be X times the stall speed at the turn's load factor; "
                        "limits the bank (default: 1.2)")
    g.add_argument("--check-fraction", type=float, default=None, metavar="F",
                   help="dwell share of the middle speed that checks the model structure "
                        "(default: 0.1; 0: two speeds only)")


def _design_options(args):
    """The design flags as `design_options` (None with the paper design; a design flag
    without --design optimal is an error, not silently ignored)."""
    given = {name: getattr(args, name) for name in _DESIGN_FLAGS
             if getattr(args, name) is not None}
    paper_only = {"--profile": args.profile, "--levels": args.levels,
                  "--return": args.return_leg or None}
    for flag, value in paper_only.items():
        if args.design == "optimal" and value is not None:
            from pitotcal.core.errors import PitotcalError

            shown = flag if value is True else f"{flag} {value}"
            raise PitotcalError(f"{shown} is for --design paper: --design optimal chooses its "
                                f"own speed schedule")
    if args.profile is None:
        from pitotcal.core.scenario import T2_PLAN

        args.profile = T2_PLAN["profile"]
    if args.design != "optimal":
        if given:
            from pitotcal.core.errors import PitotcalError

            flag = _DESIGN_FLAGS[next(iter(given))]
            raise PitotcalError(f"{flag} is for --design optimal")
        return None
    return given


def _check_outputs(args, paths):
    """`check_outputs` of the plan's files and mission: none on --calibration, none twice."""
    from .common import check_outputs

    outputs = {"--output": paths["plan"]}
    outputs.update({f"--output ({kind})": path for kind, path in paths.items() if kind != "plan"})
    if args.export:
        from pitotcal.maneuvers.plan.missions import mission_path

        outputs["--export"] = mission_path(args.output, args.export)
    check_outputs(outputs, [(args.calibration, "the input calibration")])


def _calibration(path):
    """{"calibration": {source, model, k, air_data}} from an `identify --json` result ({} without one);
    one line naming --calibration for a file that is not one."""
    if path is None:
        return {}
    import json
    from pathlib import Path

    from pitotcal.core.errors import PitotcalError
    from pitotcal.core.models import get_model

    try:
        result = json.loads(Path(path).read_text())
        model = get_model(result["model"])
        k = [float(result["parameters"][name]["value"]) for name in model.params]
    except OSError as exc:
        raise PitotcalError(f"--calibration {path}: cannot read it ({exc.strerror})") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise PitotcalError(f"--calibration {path}: not a pitotcal identify result (model and "
                            f"parameters.k*.value needed; {type(exc).__name__}: {exc})") from None
    if not all(abs(v) < float("inf") for v in k):
        raise PitotcalError(f"--calibration {path}: coefficients must be finite, got {k}")
    air = result.get("air_data", "incompressible")   # results before issue 9: incompressible
    if air not in ("compressible", "incompressible"):
        raise PitotcalError(f"--calibration {path}: air_data {air!r} is not compressible or "
                            "incompressible")
    return {"calibration": {"source": Path(path).name, "model": model.name, "k": k,
                            "air_data": air}}
