"""`pitotcal report`: the calibration report, one self-contained HTML file.

Exit status: 0 written; 2 unusable input (result JSON, flight, aircraft TOML, options), one
stderr line naming the file or flag.
"""

from pathlib import Path

REGULATION_CHOICES = ("23.1323", "25.1323", "none")
# the configurations the compliance verdict knows (flaps retracted for cruise)
CONFIGURATIONS = ("cruise", "takeoff", "approach", "landing")


def add_parser(subparsers):
    from .common import add_reading_arguments

    p = subparsers.add_parser(
        "report", help="write the calibration report (HTML, optionally PDF) from a result JSON",
        description="Render a self-contained HTML calibration report from the JSON of "
                    "`pitotcal identify --json`: title block, test conditions, method, the "
                    "KIAS->KCAS and altimeter correction tables with 2-sigma and U, figures, "
                    "warnings, a compliance verdict per speed, provenance and signatures.")
    p.add_argument("result", metavar="RESULT.json", help="result JSON of `pitotcal identify`")
    p.add_argument("-o", "--output", required=True, metavar="REPORT.html",
                   help="the HTML report to write")
    p.add_argument("--flight", metavar="FLIGHT", default=None,
                   help="the flight the result came from (CSV or log, read with its defaults): "
                        "adds test conditions, the calibration figure with residuals and the "
                        "ground track (the fit is re-run on it and checked against the result)")
    add_reading_arguments(p, "with --flight: ")
    p.add_argument("--temp-recovery", type=float, default=None, metavar="R",
                   help="with --flight: the total-temperature recovery factor identify used")
    p.add_argument("--rh-percent", type=float, default=None, metavar="PCT",
                   help="with --flight: the relative humidity identify used, %%")
    p.add_argument("--aircraft", metavar="AIRCRAFT.toml", default=None,
                   help="title block: [aircraft] type, registration, configuration, weight, cg; "
                        "[test] date, location, pilot, engineer, notes; the stall and limit "
                        "speeds vs0_kcas, vs1_kcas (Part 23), vsr0_kcas, vsr1_kcas (Part 25), "
                        "vfe_kcas, vmo_kcas, vne_kcas set the verdict's speed ranges")
    p.add_argument("--configuration", default=None, choices=CONFIGURATIONS,
                   help="the configuration flown (overrides the aircraft file's): picks the "
                        "airspeed paragraph's speed range (cruise: flaps retracted)")
    p.add_argument("--regulation", default=REGULATION_CHOICES[0], metavar="R",
                   help=f"{', '.join(REGULATION_CHOICES[:-1])} or {REGULATION_CHOICES[-1]} "
                        "(default %(default)s)")
    p.add_argument("--speed-range-kt", nargs=2, type=float, default=None, metavar=("LO", "HI"),
                   help="calibrated-airspeed range for the verdict, KCAS (default: the flown "
                        "range, and the report says so; speeds not flown are not demonstrated)")
    p.add_argument("--json", metavar="OUT.json", default=None,
                   help="also write the result with the report's \"compliance\" block added")
    p.add_argument("--pdf", metavar="REPORT.pdf", default=None,
                   help="also print the report to PDF with headless Chromium")
    p.set_defaults(run=run)


def run(args):
    from .common import check_outputs, oat_k_from_c
    from pitotcal.core.checks import choice, number
    from pitotcal.core.errors import PitotcalError
    from pitotcal.estimation.reporting.calibration_report import make_report
    from pitotcal.io.flight_checks import check_window

    choice("regulation", args.regulation, REGULATION_CHOICES)
    source = Path(args.result)
    # every output against every input: none is ever written over
    check_outputs({"-o": args.output, "--json": args.json, "--pdf": args.pdf},
                  [(source, "the input result JSON"), (args.flight, "the input flight"),
                   (args.aircraft, "the input aircraft file")])
    options = {k: v for k, v in vars(args).items() if k not in ("run", "command")}
    check_window(args.start_s, args.end_s)
    if args.flight is None:
        given = [f for f, v in (("--start-s", args.start_s), ("--end-s", args.end_s),
                                ("--oat-c", args.oat_c)) if v is not None]
        if given:
            raise PitotcalError(f"{given[0]}: only with --flight (it says how to read the "
                                "flight the fit is re-run on)")
    if args.temp_recovery is not None:
        number("temp_recovery", args.temp_recovery, 0.0, 1.0)
    if args.rh_percent is not None:
        number("rh_percent", args.rh_percent, 0.0, 100.0)
    read = {"start_s": args.start_s, "end_s": args.end_s, "oat_k": oat_k_from_c(args.oat_c),
            "temp_recovery": args.temp_recovery, "rh_pct": args.rh_percent}
    done = make_report(source, args.output, flight_path=args.flight, flight_options=read,
                       aircraft_path=args.aircraft, regulation=args.regulation,
                       speed_range_kt=args.speed_range_kt, json_path=args.json,
                       pdf_path=args.pdf, options=options, configuration=args.configuration)
    block = done["compliance"]
    if block.get("verdict"):
        print(f"Compliance ({args.regulation}): {block['verdict']}, "
              f"{_range(block['airspeed'])} "
              f"({block['speed_range_source']} range; {block['uncertainty']} uncertainty): "
              f"airspeed {block['airspeed']['verdict']}, "
              f"altimeter {block['altimeter']['verdict']} over {_range(block['altimeter'])}; "
              f"configuration {block['configuration'] or 'not stated'}")
    for path in done["written"]:
        print(f"Wrote {path}")
    return 0


def _range(check):
    """The speed range a check was judged over, in words."""
    w = check.get("window") or {}
    if w.get("lo_kt") is None:
        return "no speed range"
    return f"{w['lo_kt']:.1f}-{w['hi_kt']:.1f} KCAS"
