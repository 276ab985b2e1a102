"""`pitotcal identify`: calibrate from one flight (docs/interfaces.md §3).

Exit status: 0 success (also when the solver did not converge: the summary, the JSON's
`converged: false` and a stderr warning say so); 2 unusable input, one stderr line naming
file, column and row; 3 the data cannot separate the wind from the calibration.
With `--params OUT`: 2 also when no parameter is recommended (one stderr line saying why,
after the summary; the JSON and figure are written first).
"""

from pathlib import Path

MODEL_CHOICES = ("inverse", "constant", "linear", "auto")
AIR_CHOICES = ("compressible", "incompressible")   # pitotcal.core.airdata.AIR_DATA_MODES


def add_parser(subparsers):
    p = subparsers.add_parser(
        "identify", help="identify the pressure error and the wind from a flight",
        description="Read a flight CSV (or a .ulg/.bin/.log autopilot log), identify the "
                    "pressure-error model and the wind by the output-error method, print a "
                    "summary in knots and degrees with 2-sigma bounds, and optionally write the "
                    "result as JSON and the calibration figure. The input is never modified.")
    p.add_argument("flight", metavar="FLIGHT",
                   help="flight CSV (columns time_s, qc_pa, gps_vn_mps, gps_ve_mps, and rho_kgm3 "
                        "or ps_pa + oat_k) or a .ulg/.bin/.log autopilot log")
    p.add_argument("--model", default="inverse", metavar="NAME",
                   help="pressure-error structure: inverse, constant, linear, or auto (choose by "
                        "information criterion and list all candidates); default %(default)s")
    # --- air data (issue 9) ---
    p.add_argument("--air", default="compressible", metavar="MODE",
                   help="how impact pressure follows from true airspeed: compressible "
                        "(isentropic, from the flight's ps_pa static-port pressure and oat_k; "
                        "all pressure error taken in the static source, or separated with "
                        "a ps_ref_pa reference column; V_i, V_c standard CAS) or "
                        "incompressible (q_c = rho V^2/2, V = sqrt(2q/rho0): the "
                        "paper's eq. 2 and the results before issue 9); a flight without "
                        "ps_pa/oat_k is fitted incompressible with a warning; default "
                        "%(default)s")
    p.add_argument("--json", metavar="OUT.json", default=None, help="write the result as JSON")
    p.add_argument("--plot", metavar="OUT.png", default=None,
                   help="write the calibration figure (format from the extension)")
    p.add_argument("--start-s", type=float, default=None, metavar="S",
                   help="use only samples with time_s >= S")
    p.add_argument("--end-s", type=float, default=None, metavar="S",
                   help="use only samples with time_s <= S")
    p.add_argument("--oat-c", type=float, default=None, metavar="DEGC",
                   help="logs only: measured outside air temperature, degC, for density "
                        "(default: the log's airspeed or baro sensor temperature, with a "
                        "warning); a flight CSV carries its own rho_kgm3 or oat_k")
    p.add_argument("--gps-noise-mps", type=float, default=None, metavar="SIGMA",
                   help="GPS velocity noise per component, m/s, for the errors-in-variables "
                        "correction (default: estimated from the data)")
    # issue 10: the airspeed parameter an autopilot loads (logic in estimation/autopilot.py)
    g = p.add_argument_group("autopilot parameters")
    g.add_argument("--params", metavar="OUT", default=None,
                   help="write the recommended airspeed parameter: for an ArduPilot log a "
                        "Mission Planner / MAVProxy parameter file with ARSPD_RATIO, for a PX4 "
                        "log a QGroundControl parameter file with ASPD_SCALE_1 (the current "
                        "value and the 2-sigma as comments); exit 2 with the reason when the "
                        "flight cannot support one")
    p.set_defaults(run=run)


def run(args):
    import warnings

    from pitotcal.cli.common import check_distinct, check_output, oat_k_from_c
    from pitotcal.core.checks import choice, number
    from pitotcal.core.errors import PitotcalError
    from pitotcal.core.models import MODELS
    from pitotcal.estimation import identify
    from pitotcal.io import is_log_file, read_flight

    choice("model", args.model, [*MODELS, "auto"])
    choice("air", args.air, AIR_CHOICES)
    if args.gps_noise_mps is not None:
        number("gps_noise_mps", args.gps_noise_mps, 0.0, 10.0, hi_open=True)
    source = Path(args.flight)
    # an output on top of the input, or one that cannot be written, is said before the work
    for option, out in (("--json", args.json), ("--plot", args.plot), ("--params", args.params)):
        if out is not None:
            check_output(option, out, source, "flight file")
    # matplotlib would append ".png" to a figure name without extension: write that name
    plot_path = None if args.plot is None else \
        args.plot if Path(args.plot).suffix else f"{args.plot}.png"
    check_distinct({"--json": args.json, "--plot": plot_path, "--params": args.params})
    if args.plot is not None:
        _check_plot_format(args.plot)

    if args.params is None:
        flight = read_flight(source, start_s=args.start_s, end_s=args.end_s,
                             oat_k=oat_k_from_c(args.oat_c))
    else:
        from pitotcal.io.param_files import read_flight_and_parameters
        flight, autopilot, current = read_flight_and_parameters(
            source, args.start_s, args.end_s, oat_k=oat_k_from_c(args.oat_c))
        if autopilot is None:
            raise PitotcalError(f"--params: {source.name} names no autopilot; give the "
                                "ArduPilot or PX4 log (or the CSV `pitotcal convert` made of it)")
    result = identify(flight, model=args.model, air=args.air,
                      gps_noise_std_mps=args.gps_noise_mps)

    # issue 15: every file is written before anything is printed, so a reader that goes
    # away early (`| head`) never costs a file
    if args.json is not None:
        _write_json(args.json, result, flight, source)
    if plot_path is not None:
        result.plot(plot_path)
    params, refused = None, None
    if args.params is not None:
        try:
            params = _write_params(args, flight, autopilot, current)
        except PitotcalError as exc:        # said after the summary, as before
            refused = exc

    cut = "samples cut" if is_log_file(source) else "rows dropped"
    print(f"Flight: {source} ({flight.n} samples, {flight.time_s[0]:.1f}-{flight.time_s[-1]:.1f} s"
          + (f", {flight.n_dropped} {cut}" if flight.n_dropped else "") + ")")
    print(result.summary())
    if not result.converged:
        warnings.warn(f"{source}: the solver did not converge ({result.message}); the numbers "
                      "are not a calibration", stacklevel=2)
    if args.json is not None:
        print(f"\nWrote {args.json}")
    if plot_path is not None:
        print(f"{'' if args.json else chr(10)}Wrote {plot_path}")
    if refused is not None:
        raise refused
    if params is not None:
        _print_params(params, args.params)
    return 0


def _write_params(args, flight, autopilot, current):
    """The recommended airspeed parameter, or a PitotcalError (exit 2) saying why not."""
    from pitotcal.estimation.autopilot import PARAMETER, recommend, write_parameter_file

    name = next((n for n in ("ASPD_SCALE_1", "ASPD_SCALE") if n in current), None) \
        if autopilot == "PX4" else None
    rec = recommend(flight, autopilot, current.get(name or PARAMETER.get(autopilot, "")),
                    gps_noise_std_mps=args.gps_noise_mps, name=name, air=args.air)
    write_parameter_file(rec, args.params)
    return rec


def _print_params(rec, path):
    print(f"\nRecommended {rec.name} = {rec.value:.4f} ± {rec.two_sigma:.4f} (2σ)"
          + ("" if rec.current is None else f", now {rec.current:.6g}")
          + f"; wrote {path}")
    for note in rec.notes:
        print(f"  note: {note}")


def _write_json(path, result, flight, source):
    """The result JSON, with every warning the reader gave in its "warnings"."""
    from pitotcal.io.jsonfile import write_json

    out = {**result.to_dict(), "source": str(source), "n_dropped": int(flight.n_dropped)}
    # `identify` may carry the reader's warnings already: add only those it does not have
    given = list(out.get("warnings", []))
    out["warnings"] = given + [w for w in flight.warnings if w not in given]
    write_json(path, out)


def _check_plot_format(path):
    """Refuse a figure extension matplotlib cannot write (no extension: PNG)."""
    from matplotlib.backend_bases import FigureCanvasBase

    from pitotcal.core.errors import PitotcalError

    ext = Path(path).suffix.lower().lstrip(".")
    formats = FigureCanvasBase.get_supported_filetypes()
    if ext and ext not in formats:
        raise PitotcalError(f"--plot {path}: unknown figure format {ext!r}; use one of "
                            f"{', '.join(sorted(formats))}")
