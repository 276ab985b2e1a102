"""`pitotcal legs`: the classic GPS leg methods per point, and one global fit over every leg.

The input is a leg CSV (one row per leg) or a flight time series (a flight CSV or an autopilot
log, `pitotcal.io.read_flight`), whose legs are detected as steady segments or given by
`--windows`; a time series also gets the output-error fit of the legs' own samples.

Exit status: 0 success (a global fit the legs cannot determine is a warning, `"global": null`);
2 unusable input, one stderr line naming file, column and row; 3 a point whose legs cannot
determine TAS and wind (fewer than three legs, or ground velocities on one line).
"""

import math
from pathlib import Path

WIND_CHOICES = ("per-band", "per-point")
LOG_SUFFIXES = (".ulg", ".bin", ".log")
# Detection options: flag -> (keyword of estimation.legs.flight.detect_segments, help).
DETECT_FLAGS = {
    "--min-leg-s": ("min_leg_s", "shortest steady segment kept as a leg, s"),
    "--track-tol-deg": ("track_tol_deg", "track must stay within ± this, deg"),
    "--groundspeed-tol-kt": ("groundspeed_tol_kt", "ground speed must stay within ± this, kt"),
    "--ias-tol-kt": ("ias_tol_kt", "indicated airspeed must stay within ± this, kt"),
    "--smooth-s": ("smooth_s", "moving average applied before the bands are checked, s"),
}


def add_parser(subparsers):
    from .common import add_reading_arguments

    p = subparsers.add_parser(
        "legs", help="calibrate from GPS legs (3-leg, 4-leg) per point and globally",
        description="Read a leg CSV (one row per constant-speed leg: point, ias_kt, "
                    "pressure_alt_ft, oat_c, groundspeed_kt, track_deg) or a flight CSV/log "
                    "(legs detected as steady segments, or given by --windows), solve each "
                    "point by the classic GPS methods (3-leg closed form, 4-leg subset mean) "
                    "with bounds, fit one pressure-error model and the winds over all legs, "
                    "and print both in knots. The input is never modified.")
    p.add_argument("legs", metavar="LEGS.csv|FLIGHT.csv|LOG",
                   help="leg CSV (docs/interfaces.md, leg data), flight CSV, or .ulg/.bin/.log")
    p.add_argument("--json", metavar="OUT.json", default=None, help="write the result as JSON")
    p.add_argument("--plot", metavar="OUT.png", default=None,
                   help="write the figure: per-point ΔV with 95%% bars, global curve and band")
    p.add_argument("--model", default="inverse", metavar="NAME",
                   help="pressure-error structure of the global fit: inverse, constant, linear; "
                        "default %(default)s")
    p.add_argument("--wind", default="per-band", metavar="MODE",
                   help="global fit: one wind per {band_ft:,.0f} ft pressure-altitude band "
                        "(per-band) or per point (per-point); default %(default)s")
    p.add_argument("--temp-recovery", type=float, default=None, metavar="R",
                   help="recovery factor of the probe of a leg file's tat_c / tat_k column "
                        "(indicated total temperature), T_s = T_t / (1 + R 0.2 M^2); default "
                        "{temp_recovery:g}")
    g = p.add_argument_group("time-series input (flight CSV or log)")
    g.add_argument("--windows", metavar="T0-T1,...|WINDOWS.csv", default=None,
                   help="the legs' time windows, s ('120-180,200-260'), or a CSV with columns "
                        "start_s, end_s and optional point; default: detect steady segments")
    add_reading_arguments(g)
    for flag, (key, text) in DETECT_FLAGS.items():
        g.add_argument(flag, type=float, default=None, metavar="X",
                       help=f"{text} (default: {{{key}:g}})")
    g.add_argument("--point-tol-kt", type=float, default=None, metavar="KT",
                   help="legs whose IAS differ by at most this form one point (default "
                        "{point_tol_kt:g})")
    g.add_argument("--legs-out", metavar="LEGS.csv", default=None,
                   help="write the legs found as a leg CSV, to check by hand")
    p.help_from(_help_constants)
    p.set_defaults(run=run)


def _help_constants():
    """The library constants `legs --help` quotes."""
    from pitotcal.estimation.legs.flight import DETECT_DEFAULTS, POINT_TOL_KT
    from pitotcal.estimation.legs.global_fit import BAND_FT

    from pitotcal.io.legs_csv import DEFAULT_TEMP_RECOVERY

    return {**DETECT_DEFAULTS, "point_tol_kt": POINT_TOL_KT, "band_ft": BAND_FT,
            "temp_recovery": DEFAULT_TEMP_RECOVERY}


# A track band wider than a half turn, or a speed band of 50 kt, holds every sample: no leg.
DETECT_MAX = {"track_tol_deg": 180.0, "groundspeed_tol_kt": 50.0, "ias_tol_kt": 50.0}


def _is_flight(path, data):
    from pitotcal.io.flight_csv import csv_kind
    from pitotcal.io.read_once import log_suffix

    return (path.suffix.lower() in LOG_SUFFIXES or log_suffix(data) is not None
            or csv_kind(data) in ("flight", "plan"))


def _series_options(args):
    """{keyword: value} of the time-series options given."""
    opts = {key: getattr(args, flag[2:].replace("-", "_")) for flag, (key, _) in DETECT_FLAGS.items()}
    return {k: v for k, v in opts.items() if v is not None}


def _plot_path(args):
    """--plot as written: a name without extension gets ".png" (matplotlib's default)."""
    if args.plot is None:
        return None
    return args.plot if Path(args.plot).suffix else f"{args.plot}.png"


def run(args):
    from .common import check_outputs
    from pitotcal.core.checks import choice
    from pitotcal.core.errors import PitotcalError
    from pitotcal.core.models import MODELS

    choice("model", args.model, list(MODELS))
    choice("wind", args.wind, WIND_CHOICES)
    from pitotcal.io.read_once import is_stream, read_once

    source = Path(args.legs)
    if not source.is_file() and not is_stream(source):
        raise PitotcalError(f"{source}: no such file", param="legs")
    data = read_once(source)        # a stream is read here once; each reader gets its bytes
    flight = _is_flight(source, data)
    check_outputs({"--json": args.json, "--plot": args.plot, "--legs-out": args.legs_out},
                  [(source, f"the input {'flight file' if flight else 'leg file'}")],
                  figures=["--plot"])
    if flight:
        if args.temp_recovery is not None:
            raise PitotcalError(f"--temp-recovery: only for a leg file's tat_c / tat_k column; "
                                f"{source} is a flight time series", param="temp_recovery")
        return _run_flight(args, source, data)
    given = [f for f in ("--windows", *DETECT_FLAGS, "--point-tol-kt", "--legs-out",
                         "--start-s", "--end-s", "--oat-c")
             if getattr(args, f[2:].replace("-", "_")) is not None]
    if given:
        raise PitotcalError(f"{given[0]}: only for a flight time series; {source} is a leg "
                            f"file", param=given[0])
    return _run_legs(args, source, data)


def _run_legs(args, source, data):
    from pitotcal.estimation.legs.report import analyze_legs, legs_json, legs_summary, plot_legs
    from pitotcal.io.jsonfile import write_json
    from pitotcal.io.legs_csv import read_legs

    plot_path = _plot_path(args)
    from pitotcal.io.legs_csv import DEFAULT_TEMP_RECOVERY

    recovery = DEFAULT_TEMP_RECOVERY if args.temp_recovery is None else args.temp_recovery
    legs = read_legs(data, temp_recovery=recovery)
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


def _windows(text):
    from pitotcal.core.errors import PitotcalError
    from pitotcal.estimation.legs.flight import parse_windows, read_windows

    if text is None:
        return None
    if Path(text).is_file():
        from pitotcal.io.read_once import naming

        with naming(text):
            return read_windows(text)
    if text.lower().endswith(".csv"):
        raise PitotcalError(f"--windows {text}: no such file", param="windows")
    return parse_windows(text)


def _run_flight(args, source, data):
    from .common import oat_k_from_c
    from pitotcal.core.checks import number
    from pitotcal.core.errors import PitotcalError
    from pitotcal.estimation.legs.flight import analyze_leg_flight
    from pitotcal.estimation.legs.report import (
        flight_legs_json,
        flight_legs_text,
        legs_summary,
        plot_legs,
    )
    from pitotcal.io import read_flight
    from pitotcal.io.jsonfile import write_json
    from pitotcal.io.legs_csv import write_legs

    detect = {k: number(k, v, 0.0, DETECT_MAX.get(k, math.inf), lo_open=True)
              for k, v in _series_options(args).items()}
    tol = 3.0 if args.point_tol_kt is None else number("--point-tol-kt", args.point_tol_kt,
                                                        0.0, 50.0, lo_open=True)
    windows = _windows(args.windows)
    flight = read_flight(data, start_s=args.start_s, end_s=args.end_s,
                         oat_k=oat_k_from_c(args.oat_c))
    span_s = float(flight.time_s[-1] - flight.time_s[0])
    for key in ("min_leg_s", "smooth_s"):          # a window longer than the data holds nothing
        if detect.get(key, 0.0) > span_s:
            raise PitotcalError(f"{key} {detect[key]:g} s is longer than the flight "
                                f"({span_s:.0f} s of {source})", param=key)
    res = analyze_leg_flight(flight, windows, model=args.model, wind=args.wind,
                             point_tol_kt=tol, **detect)
    wrote = []          # files first, then the summary: a reader that goes away early
    if args.legs_out is not None:
        write_legs(res["legs"], args.legs_out,
                   comments=[f"legs found in {source} by pitotcal legs"])
        wrote.append(args.legs_out)
    if args.json is not None:
        write_json(args.json, flight_legs_json(res, source))
        wrote.append(args.json)
    if args.plot is not None:
        plot_legs(res["points"], res["fit"], _plot_path(args), series=res["series"])
        wrote.append(_plot_path(args))
    print(legs_summary(res["legs"], res["points"], res["fit"], res["notes"]))
    print("\n" + flight_legs_text(res))
    if wrote:
        print("\n" + "\n".join(f"Wrote {w}" for w in wrote))
    return 0
