"""`pitotcal legs`: the classic GPS leg methods per point, and one global fit over every leg.

Exit status: 0 success (a global fit the legs cannot determine is a warning, `"global": null`);
2 unusable input, one stderr line naming file, column and row; 3 a point whose legs cannot
determine TAS and wind (fewer than three legs, or ground velocities on one line).
"""

from pathlib import Path

WIND_CHOICES = ("per-band", "per-point")


def add_parser(subparsers):
    p = subparsers.add_parser(
        "legs", help="calibrate from GPS legs (3-leg, 4-leg) per point and globally",
        description="Read a leg CSV (one row per constant-speed leg: point, ias_kt, "
                    "pressure_alt_ft, oat_c, groundspeed_kt, track_deg), solve each point by the "
                    "classic GPS methods (3-leg closed form, 4-leg subset mean) with bounds, fit "
                    "one pressure-error model and the winds over all legs, and print both in "
                    "knots. The input is never modified.")
    p.add_argument("legs", metavar="LEGS.csv", help="leg CSV (docs/interfaces.md, leg data)")
    p.add_argument("--json", metavar="OUT.json", default=None, help="write the result as JSON")
    p.add_argument("--plot", metavar="OUT.png", default=None,
                   help="write the figure: per-point ΔV with 95%% bars, global curve and band")
    p.add_argument("--model", default="inverse", metavar="NAME",
                   help="pressure-error structure of the global fit: inverse, constant, linear; "
                        "default %(default)s")
    p.add_argument("--wind", default="per-band", metavar="MODE",
                   help="global fit: one wind per 1,000 ft pressure-altitude band (per-band) or "
                        "per point (per-point); default %(default)s")
    p.set_defaults(run=run)


def run(args):
    from pitotcal.cli.common import check_distinct, check_output
    from pitotcal.core.checks import choice
    from pitotcal.core.models import MODELS
    from pitotcal.estimation.legs_report import (
        analyze_legs,
        legs_json,
        legs_summary,
        plot_legs,
    )
    from pitotcal.io.jsonfile import write_json
    from pitotcal.io.legs_csv import read_legs

    choice("model", args.model, list(MODELS))
    choice("wind", args.wind, WIND_CHOICES)
    source = Path(args.legs)
    for option, out in (("--json", args.json), ("--plot", args.plot)):
        if out is not None:
            check_output(option, out, source, "leg file")
    plot_path = None if args.plot is None else \
        args.plot if Path(args.plot).suffix else f"{args.plot}.png"
    check_distinct({"--json": args.json, "--plot": plot_path})
    legs = read_legs(source)
    points, fit, notes = analyze_legs(legs, model=args.model, wind=args.wind)
    # files first, then the summary: a reader that goes away early never costs a file
    if args.json is not None:
        write_json(args.json, legs_json(legs, points, fit, notes))
    if plot_path is not None:
        plot_legs(points, fit, plot_path)
    print(legs_summary(legs, points, fit, notes))
    if args.json is not None:
        print(f"\nWrote {args.json}")
    if plot_path is not None:
        print(f"{'' if args.json else chr(10)}Wrote {plot_path}")
    return 0
