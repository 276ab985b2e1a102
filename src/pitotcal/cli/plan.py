"""`pitotcal plan`: plan a calibration maneuver and write its CSV, pilot card and setpoints
(docs/interfaces.md). Defaults are the T-2 case of the reference paper."""

import contextlib
import dataclasses
import sys


def add_parser(subparsers):
    # numpy-free modules: the parser is built for every command
    from pitotcal.core.plan import PROFILES, TURNS
    from pitotcal.core.scenario import MIN_CLEARANCE_M, T2_PLAN

    p = subparsers.add_parser(
        "plan", help="plan a calibration maneuver (CasADi/IPOPT)",
        description="Plan a calibration maneuver: the airspeed schedule holds q uniform (or in "
                    "equal steps), the optimised ground track stays inside the radius in the "
                    "wind and turns through a full 360° of heading in each third of the q "
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
                   help="roll-rate limit (default: {roll_rate_max_dps:g})")
    p.add_argument("--accel-max-mps2", type=float, default=None, metavar="M/S2",
                   help="acceleration limit (default: {accel_max_mps2:g})")
    p.add_argument("--levels", type=int, default=None, help="step-pause levels (default: {levels})")
    p.add_argument("--return", dest="return_leg", action="store_true",
                   help="continuous profile: sweep back down to --cas-min-kt")
    p.add_argument("--turn", choices=(*TURNS, "both"), default=TURNS[0],
                   help="turn direction; both: right and left orbits alternate from one "
                        "speed group to the next, so a probe lever-arm term averages out "
                        "(default: %(default)s)")
    p.add_argument("--dt-s", type=float, default=1.0,
                   help="plan node spacing, s (default: %(default)g)")
    p.add_argument("--max-iter", type=int, default=None, metavar="N",
                   help="IPOPT iteration limit (default: {max_iter})")
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
    p.add_argument("--ground-elevation-m", type=float, default=None, metavar="M",
                   help="with --export: the ground's elevation at --center, m above mean sea "
                        f"level; a loiter less than {MIN_CLEARANCE_M:g} m above it is refused "
                        "(without it, an MSL mission is exported with a warning)")
    p.add_argument("--magvar-deg", type=float, default=None, metavar="DEG",
                   help="magnetic variation, east positive: the card adds magnetic headings")
    _add_design_arguments(p)
    p.add_argument("--calibration", default=None, metavar="RESULT.json",
                   help="a prior `identify --json` result: the card adds the KIAS the "
                        "uncalibrated indicator shows at each KCAS target")
    p.add_argument("-o", "--output", required=True, metavar="PLAN.csv", help="plan CSV to write")
    p.help_from(_help_constants)
    p.set_defaults(run=run)


def _help_constants():
    """The planner's defaults, which `plan --help` quotes."""
    from pitotcal.core.dynamics import Limits
    from pitotcal.maneuvers.plan.design import STALL_DEFAULT_RATIO
    from pitotcal.maneuvers.plan.design_request import DesignOptions
    from pitotcal.maneuvers.plan.planner import MAX_ITER
    from pitotcal.maneuvers.plan.request import PlanRequest

    defaults = {**dataclasses.asdict(Limits()), **dataclasses.asdict(DesignOptions())}
    return {**defaults, "max_iter": MAX_ITER, "stall_ratio": STALL_DEFAULT_RATIO,
            "levels": PlanRequest().levels}


def run(args):
    from pitotcal.maneuvers.plan.outputs import (check_output_paths, start_figures,
                                                 write_plan_outputs)

    figures = not args.no_figures
    paths = check_output_paths(args.output, figures=figures)
    geo = _geo_settings(args)
    _check_outputs(args, paths)
    calibration = _calibration(args.calibration)
    # the PNGs' process imports matplotlib while CasADi is imported and the plan solved here
    with start_figures(args.output) if figures else contextlib.nullcontext() as early:
        from pitotcal.maneuvers.plan.autothrottle import autothrottle_report
        from pitotcal.maneuvers.plan.planner import MAX_ITER, check_converged, plan_maneuver

        max_iter = MAX_ITER if args.max_iter is None else args.max_iter
        plan = plan_maneuver(_request(args, max_iter))
        check_converged(plan, max_iter)
        if geo or calibration:
            plan = dataclasses.replace(plan, settings={**plan.settings, **geo, **calibration})
        mission = None
        if args.export:
            # refused (the loiter's bank or heading coverage) before any file is written
            from pitotcal.maneuvers.plan.missions import build_mission

            mission = build_mission(plan, *args.center, altitude_ref=args.altitude_ref,
                                    ground_elevation_m=args.ground_elevation_m)
        if early is not None:
            early.send(plan)                 # the PNGs are drawn from here on
        check = autothrottle_report(plan)    # meanwhile
        paths = write_plan_outputs(plan, args.output, figures=figures, early=early)
    if mission is not None:
        from pitotcal.maneuvers.plan.missions import mission_path, write_mission

        paths["mission"] = write_mission(mission, mission_path(args.output, args.export),
                                         args.export)
    print(plan.summary())
    s = plan.settings
    if s.get("design") == "optimal":
        met = s.get("target_2sigma_kt") is not None and \
            s["predicted_dv_2sigma_kt"] <= s["target_2sigma_kt"]
        print(f"  design: dwells {s['dwell_order']} (low, check, high), {s['low_share']:.0%} of "
              f"the end-level time low; predicted {s['criterion']} 2σ of ΔV "
              f"{s['predicted_dv_2sigma_kt']:.2f} kt in {s['turbulence_mps']:g} m/s turbulence"
              + ("" if s.get("target_2sigma_kt") is None else
                 f" (target {s['target_2sigma_kt']:g} kt: "
                 f"{'met' if met else 'NOT met'})"))
    for kind, path in paths.items():
        print(f"  {kind:12s} {path}")
    sys.stdout.flush()
    print(check)
    if mission is not None:
        print(mission.summary())
    return 0


def _geo_settings(args):
    """The checked --center, --magvar-deg and --altitude-ref as plan settings ({} without
    --center: the plan and card are then what they always were)."""
    from pitotcal.core.errors import PitotcalError

    if args.export:
        from pitotcal.maneuvers.plan.export_checks import check_exportable_turn

        check_exportable_turn(args.turn)        # before planning: no radius advice first
    elif args.ground_elevation_m is not None and args.altitude_ref != "agl":
        raise PitotcalError("--ground-elevation-m is for --export or --altitude-ref agl: the "
                            "mission's loiters are checked against it")
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
    _check_clear_of_the_poles(lat, lon)
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


# The design flags' fields (maneuvers.plan.design_request.DesignOptions).
_DESIGN_FIELDS = ("turbulence_mps", "criterion", "target_2sigma_kt", "stall_kt", "stall_margin",
                  "check_fraction")


def _add_design_arguments(p):
    p.add_argument("--design", choices=("paper", "optimal"), default="paper",
                   help="paper: --profile's schedule; optimal: the speed schedule that "
                        "minimises the predicted 2σ of ΔV in turbulence (default: %(default)s)")
    g = p.add_argument_group("optimal design (with --design optimal)")
    g.add_argument("--turbulence-mps", type=float, default=None, metavar="M/S",
                   help="RMS gust the design is for, m/s (default: {turbulence_mps:g})")
    g.add_argument("--criterion", choices=("worst", "average"), default=None,
                   help="minimise the worst or the mean 2σ of ΔV over the range "
                        "(default: {criterion})")
    g.add_argument("--target-2sigma-kt", type=float, default=None, metavar="KT",
                   help="plan the shortest flight whose predicted 2σ of ΔV meets this "
                        "(replaces --duration-s)")
    g.add_argument("--stall-kt", type=float, default=None, metavar="KCAS",
                   help="stall speed (default: --cas-min-kt / {stall_ratio:g})")
    g.add_argument("--stall-margin", type=float, default=None, metavar="X",
                   help="cas-min must be X times the stall speed at the turn's load factor; "
                        "limits the bank (default: {stall_margin:g})")
    g.add_argument("--check-fraction", type=float, default=None, metavar="F",
                   help="dwell share of the middle speed that checks the model structure "
                        "(default: {check_fraction:g}; 0: two speeds only)")


def _check_clear_of_the_poles(lat, lon):
    """Refuse a centre whose test area (a loiter up to the largest radius a plan may have)
    could reach a pole: there north and east have no meaning (a card centred at 90 deg N would
    start beyond it)."""
    from pitotcal.core.errors import PitotcalError
    from pitotcal.maneuvers.plan.request import MAX_RADIUS_M

    limit = 90.0 - MAX_RADIUS_M / 111_000.0            # 111 km per degree of latitude
    if abs(lat) > limit:
        raise PitotcalError(f"--center {lat:g} {lon:g}: a loiter of up to {MAX_RADIUS_M / 1e3:g} "
                            f"km there could cross the pole, where the card's north and east "
                            f"have no meaning; centre the test area within {limit:.1f} deg of "
                            "the equator")


def _check_duration_holds_steps(args):
    """--duration-s shorter than two --dt-s steps, named as the duration (the library's
    rule is on the step: a default --dt-s the user did not give)."""
    import math

    from pitotcal.core.errors import PitotcalError

    d, dt = args.duration_s, args.dt_s
    if d is not None and dt is not None and math.isfinite(d) and math.isfinite(dt) \
            and 0.0 < dt and 0.0 < d < 2.0 * dt:
        raise PitotcalError(f"--duration-s {d:g} holds fewer than two time steps of --dt-s "
                            f"{dt:g}: give at least {2.0 * dt:g} s (a calibration maneuver is "
                            "minutes long)")


def _request(args, max_iter):
    """The flags as the library's `PlanRequest`: it checks each value, naming the field, which
    `pitotcal.cli.flag_message` shows as its flag (a design flag without --design optimal
    included). Only what the command line alone has is checked here: --profile, --levels and
    --return given with --design optimal, which chooses its own speed schedule (the library
    cannot tell them from their defaults)."""
    from pitotcal.maneuvers.plan.request import PlanRequest

    paper_only = {"--profile": args.profile, "--levels": args.levels,
                  "--return": args.return_leg or None}
    for flag, value in paper_only.items():
        if args.design == "optimal" and value is not None:
            from pitotcal.core.errors import PitotcalError

            shown = flag if value is True else f"{flag} {value}"
            raise PitotcalError(f"{shown} is for --design paper: --design optimal chooses its "
                                f"own speed schedule")
    _check_duration_holds_steps(args)
    given = {name: getattr(args, name) for name in _DESIGN_FIELDS
             if getattr(args, name) is not None}
    # --profile and --levels when given, else the library's defaults
    schedule = {name: value for name, value in (("profile", args.profile),
                                                ("levels", args.levels)) if value is not None}
    return PlanRequest(
        cas_min_kt=args.cas_min_kt, cas_max_kt=args.cas_max_kt, radius_m=args.radius_m,
        altitude_m=_msl_altitude_m(args), duration_s=args.duration_s,
        bank_max_deg=args.bank_max_deg,
        wind_speed_mps=args.wind_speed_mps, wind_from_deg=args.wind_from_deg,
        roll_rate_max_dps=args.roll_rate_max_dps, accel_max_mps2=args.accel_max_mps2,
        return_leg=args.return_leg, turn=args.turn, dt_s=args.dt_s, max_iter=max_iter,
        design=args.design, design_options=given or None, **schedule)


def _msl_altitude_m(args):
    """The altitude the plan's true airspeeds are computed at, m above mean sea level: with
    --altitude-ref agl, --altitude-m is above home, so the ground's elevation is added (a
    warning when it is not given: the ground is then taken at sea level)."""
    if args.altitude_ref != "agl":
        return args.altitude_m
    if args.ground_elevation_m is None:
        import warnings

        warnings.warn("--altitude-ref agl without --ground-elevation-m: the plan's true "
                      "airspeeds take the ground at mean sea level (about 2.5 % too low per "
                      "500 m of ground elevation); give --ground-elevation-m", stacklevel=2)
        return args.altitude_m
    return args.altitude_m + args.ground_elevation_m


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
    one line naming --calibration and the key for a file that is not one
    (`pitotcal.io.result_record`)."""
    if path is None:
        return {}
    from pathlib import Path

    from pitotcal.io.result_record import read_result, record_calibration

    name = f"--calibration {path}"
    model, k, _, _, air = record_calibration(
        read_result(path, name=name, table=False), name, wind=False)
    return {"calibration": {"source": Path(path).name, "model": model, "k": list(k),
                            "air_data": air}}
