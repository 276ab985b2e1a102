"""`pitotcal identify`: calibrate from one flight (docs/interfaces.md §3).

Exit status: 0 success (also when the solver did not converge: the summary, the JSON's
`converged: false` and a stderr warning say so); 2 unusable input, one stderr line naming
file, column and row; 3 the data cannot separate the wind from the calibration.
With `--params OUT`: 2 also when no parameter is recommended (one stderr line saying why,
after the summary; the JSON and figure are written first).
"""

from pathlib import Path

from pitotcal.core.scenario import AIR_DATA_MODES, DEFAULT_AIR_DATA, HIDES_THRESHOLD_KT

from .identify_budget import add_budget_arguments, budget_inputs, sensor_options

# the Mach-dependent static error of a jet (estimation.identification.mach_oe), not a MODELS entry
MACH_SPLINE = "mach-spline"
MODEL_CHOICES = ("inverse", "constant", "linear", "auto", MACH_SPLINE)
# the default first, as --help and the error list them
AIR_CHOICES = (DEFAULT_AIR_DATA, *(m for m in AIR_DATA_MODES if m != DEFAULT_AIR_DATA))


def add_parser(subparsers):
    from .common import add_reading_arguments

    p = subparsers.add_parser(
        "identify", help="identify the pressure error and the wind from a flight",
        description="Read a flight CSV (or a .ulg/.bin/.log/.tlog autopilot log), identify the "
                    "pressure-error model and the wind by the output-error method (a log's two or "
                    "more airspeed sensors jointly: one wind, one calibration each), print a "
                    "summary in knots and degrees with 2-sigma bounds, and optionally write the "
                    "result as JSON and the calibration figure. The input is never modified.")
    p.add_argument("flight", metavar="FLIGHT", nargs="?",
                   help="flight CSV (columns time_s, qc_pa, gps_vn_mps, gps_ve_mps, and rho_kgm3 "
                        "or ps_pa + oat_k) or a .ulg/.bin/.log/.tlog autopilot log")
    p.add_argument("--model", default="inverse", metavar="NAME",
                   help="pressure-error structure: inverse, constant, linear, or auto (choose by "
                        "information criterion and list all candidates); mach-spline: a jet's "
                        "static error as a spline in M_ic through Mach 1, with the probe's "
                        "recovery and the OAT (docs/interfaces.md 3); default %(default)s")
    # --- air data ---
    p.add_argument("--air", default=DEFAULT_AIR_DATA, metavar="MODE",
                   help="how impact pressure follows from true airspeed: compressible "
                        "(isentropic, from the flight's ps_pa static-port pressure and oat_k; "
                        "all pressure error taken in the static source, or separated with "
                        "a ps_ref_pa reference column; V_i, V_c standard CAS) or "
                        "incompressible (q_c = rho V^2/2, V = sqrt(2q/rho0): the "
                        "paper's eq. 2; needs no static port); a flight without "
                        "ps_pa/oat_k is fitted incompressible with a warning; default "
                        "%(default)s")
    p.add_argument("--json", metavar="OUT.json", default=None, help="write the result as JSON")
    p.add_argument("--plot", metavar="OUT.png", default=None,
                   help="write the calibration figure (format from the extension)")
    add_reading_arguments(p)
    p.add_argument("--oat-ground-c", type=float, default=None, metavar="DEGC",
                   help="logs only: the ground temperature at the take-off point, degC, carried "
                        "up the standard lapse (6.5 K/km above the take-off point) for the "
                        "density, when no outside air temperature is logged or given (--oat-c)")
    p.add_argument("--windows", default="auto", choices=("auto", "all"),
                   help="logs without --start-s/--end-s: auto chooses the calibration "
                        "windows from the log (steady, airborne flight whose track turns; "
                        "the JSON's windows and cut_s say which and why), all keeps every "
                        "usable sample; default %(default)s")
    p.add_argument("--columns", metavar="MAP.toml", default=None,
                   help="read FLIGHT as any CSV export through this column mapping (TOML: "
                        "which column is time, GPS velocity, total or impact pressure, static "
                        "pressure, total or static temperature, GPS height, each with its unit; "
                        "docs/interfaces.md section 1b)")
    p.add_argument("--gps-noise-mps", type=float, default=None, metavar="SIGMA",
                   help="GPS velocity noise per component, m/s, for the errors-in-variables "
                        "correction (default: estimated from the data)")
    _add_wind_arguments(p)
    p.add_argument("--hides-threshold-kt", type=float, default=HIDES_THRESHOLD_KT, metavar="KT",
                   help="say that the maneuver hides a change of scale (a leak) only when one "
                        "the consistency checks would miss moves dV by more than KT "
                        "(default %(default)s)")
    _add_params_and_live(p)
    add_budget_arguments(p, _help_constants)
    _add_gps_error_arguments(p)
    p.set_defaults(run=run)


def _add_wind_arguments(p):
    """The wind model's options (`estimation.identification.wind_drift`)."""
    p.add_argument("--wind", default="auto", metavar="MODEL",
                   help="wind model: constant, drifting (a wind varying slowly in time, "
                        "piecewise linear between knots) or auto: drifting when a Wald test "
                        "of no drift rejects it at 1%% (default: auto); a log with several "
                        "airspeed sensors: chosen on the first, shared by all")
    p.add_argument("--wind-knot-s", type=float, default=None, metavar="S",
                   help="knot spacing of the drifting wind, s (default: 300 s, or two of the "
                        "flight's orbits when it turns more slowly)")


def _add_gps_error_arguments(p):
    """The GPS receiver's time-correlated velocity error, stated (a known term of the bounds)."""
    gps = p.add_argument_group("GPS velocity error (a known term of the bounds)")
    gps.add_argument("--gps-error-sigma-mps", type=float, default=None, metavar="SIGMA",
                     help="the GPS receiver's slowly varying velocity error per component, "
                          "m/s (first-order Gauss-Markov; e.g. 0.05 from its data sheet); "
                          "counted in the bounds, because the residuals cannot show it (it "
                          "looks like wind); with --gps-error-tau-s; default: none stated")
    gps.add_argument("--gps-error-tau-s", type=float, default=None, metavar="S",
                     help="its correlation time, s (e.g. 30); with --gps-error-sigma-mps")


def _add_params_and_live(p):
    """The autopilot-parameter and the live-stream option groups."""
    # the airspeed parameter an autopilot loads (estimation.reporting.autopilot_params)
    g = p.add_argument_group("autopilot parameters")
    g.add_argument("--params", metavar="OUT", default=None,
                   help="write the recommended airspeed parameter: for an ArduPilot log a "
                        "Mission Planner / MAVProxy parameter file with {ardupilot_param}, for a "
                        "PX4 log a QGroundControl parameter file with the scale parameter the log "
                        "has ({px4_params}; {px4_param} when it has neither); the current "
                        "value and the 2-sigma as comments; exit 2 with the reason when the "
                        "flight cannot support one")
    g.add_argument("--misfit-tolerance-kt", dest="misfit_tolerance_kt", type=float,
                   default=None, metavar="KT",
                   help="with --params: refuse a single value only when its structure misfit "
                        "(the largest error of one value over the flown range against the "
                        "two-coefficient fit, when that departure is beyond its 2-sigma) exceeds "
                        "KT (default {misfit_kt:.2f}, a third of the 5 kt airspeed limit)")
    live = p.add_argument_group("live (a MAVLink stream instead of FLIGHT)")
    live.add_argument("--live", metavar="CONNECTION", default=None,
                      help="re-identify the growing maneuver every second from a MAVLink "
                           "stream (udp:127.0.0.1:14550), show dV and its 2-sigma, and write "
                           "the final result when the stream stops (or on Ctrl-C)")
    live.add_argument("--idle-s", type=float, default=None, metavar="S",
                      help="live: the stream has ended after S seconds without a message "
                           "(default {idle_s:g})")
    live.add_argument("--target-2sigma-kt", type=float, default=1.0, metavar="KT",
                      help="live: say when the 2-sigma of dV at the middle airspeed is at most "
                           "KT, so the maneuver can end (default %(default)s)")


def _help_constants():
    """The library constants `identify --help` quotes (the budget re-solves each source twice)."""
    import dataclasses

    from pitotcal.estimation.identification import budget
    from pitotcal.estimation.reporting.autopilot_params import MISFIT_TOLERANCE_KT
    from pitotcal.io.mavlink_live import IDLE_TIMEOUT_S
    from pitotcal.io.param_files import ARDUPILOT_RATIO, PX4_SCALES

    from pitotcal.estimation.identification import sensor_inputs as si

    defaults = {**dataclasses.asdict(budget.BudgetInputs()),
                **si.CLASS_DEFAULTS[si.DEFAULT_SENSOR_CLASS]}
    defaults["u_oat_k"] = defaults["u_oat_probe_k"]
    return {**defaults, "u_qc_scale_percent": 100.0 * defaults["u_qc_scale"],
            "sensor_classes": ", ".join(si.SENSOR_CLASSES),
            "default_class": si.DEFAULT_SENSOR_CLASS, "oat_sources": ", ".join(si.OAT_SOURCES),
            "u_oat_sources": ", ".join(f"{name} {u:.3g}" for name, (_, u)
                                       in si.OAT_SOURCES.items() if u is not None),
            "arm_fraction": 100.0 * si.ARM_U_FRACTION,
            "rh_given": budget.RH_U_GIVEN_PCT, "rh_unknown": budget.RH_U_UNKNOWN_PCT,
            "budget_solves": 2 * len(budget.SOURCES), "ardupilot_param": ARDUPILOT_RATIO,
            "px4_params": " or ".join(PX4_SCALES), "px4_param": PX4_SCALES[0],
            "misfit_kt": MISFIT_TOLERANCE_KT,
            "idle_s": IDLE_TIMEOUT_S}


def run(args):
    from pitotcal.core.checks import positive

    from .common import idle_timeout_s

    # the live options are checked with a file too: a NaN is no option anywhere
    idle_timeout_s(args.idle_s)
    positive("target_2sigma_kt", args.target_2sigma_kt)
    from pitotcal.estimation.robustness.consistency import hides_threshold

    hides_threshold(args.hides_threshold_kt)
    if args.misfit_tolerance_kt is not None:
        from pitotcal.estimation.reporting.autopilot_params import check_misfit_tolerance

        check_misfit_tolerance(args.misfit_tolerance_kt)
    if args.live is not None or args.flight is None:
        return _run_live(args)
    import warnings

    from pitotcal.core.checks import choice
    from pitotcal.core.models import MODELS
    from pitotcal.estimation.identification.multi_sensor import sensors_record, sensors_summary
    from pitotcal.estimation.reporting.budget_tables import budget_summary
    from pitotcal.io import is_log_file
    from pitotcal.io.jsonfile import write_json

    choice("model", args.model, [*MODELS, "auto", MACH_SPLINE])
    choice("air", args.air, AIR_CHOICES)
    source = Path(args.flight)
    if args.model == MACH_SPLINE:
        return _run_mach_spline(args, source)
    plot_path = _checked_outputs(args, source)
    sensors = sensor_options(args)
    inputs = None if args.no_budget else budget_inputs(args, sensors)
    flight, autopilot, current, flights, results = _identify_all(args, source, sensors, inputs)
    result, budget = results[0], results[0].budget

    # every file is written before anything is printed, so a reader that goes away early
    # (`| head`) never costs a file
    params, refused, per_sensor = (None, None, None) if args.params is None else \
        _recommend(args, flights, result, sensors, autopilot, current)
    if args.json is not None:       # the record, with the path as given (a log's names the file)
        write_json(args.json, {**result.to_dict(), "source": str(source),
                               **_params_record(args, params, refused),
                               **sensors_record(results, flights, per_sensor)})
    if plot_path is not None:
        _write_plot(plot_path, result, budget)

    cut = "samples cut" if is_log_file(source) else "rows dropped"
    print(f"Flight: {source} ({flight.n} samples, {flight.time_s[0]:.1f}-{flight.time_s[-1]:.1f} s"
          + (f", {flight.n_dropped} {cut}" if flight.n_dropped else "") + ")")
    _print_windows(flight)
    print(result.summary())
    if budget is not None:
        print("\n" + budget_summary(result, budget))
    print(sensors_summary(results, flights), end="")      # a log's other airspeed sensors
    if not result.converged:
        warnings.warn(f"{source}: the solver did not converge ({result.message}); the numbers "
                      "are not a calibration", stacklevel=2)
    if args.json is not None:
        print(f"\nWrote {args.json}")
    if plot_path is not None:
        print(f"{'' if args.json else chr(10)}Wrote {plot_path}")
    if per_sensor is not None:      # several sensors: each one's, then any refusal
        from pitotcal.estimation.reporting.autopilot_params import sensor_params_text
        print(sensor_params_text(per_sensor, args.params))
    if refused is not None:
        raise refused
    if params is not None and per_sensor is None:
        _print_params(params, args.params)
    return 0


def _run_mach_spline(args, source):
    """`--model mach-spline`: `identify_mach` on the flight (the attitude when --columns maps
    it); --json writes its record. No figure, budget or autopilot parameter."""
    from pitotcal.core.errors import PitotcalError
    from pitotcal.estimation.identification.mach_oe import identify_mach
    from pitotcal.io.jsonfile import write_json
    from pitotcal.io.mapped_csv import mapped_attitude

    bad = [o for o, v in (("--plot", args.plot), ("--params", args.params)) if v is not None]
    if bad:
        raise PitotcalError(f"{bad[0]} is not made by --model {MACH_SPLINE} (`pitotcal study "
                            "jets` draws its curve)", param="model")
    _checked_outputs(args, source)
    flight = _read(args, source)[0]
    result = identify_mach(flight, attitude=args.columns and mapped_attitude(source, args.columns))
    if args.json is not None:
        write_json(args.json, {**result.to_dict(), "source": str(source)})
    print(f"Flight: {source} ({flight.n} samples)\n{result.summary()}"
          + ("" if args.json is None else f"\n\nWrote {args.json}"))
    return 0


def _print_windows(flight):
    """The windows chosen from a whole-flight log, and what was cut, one line each."""
    from pitotcal.io.windows import windows_text

    text = windows_text(flight.reading)
    if text:
        print("\n".join(f"  {line}" for line in text.splitlines()))


def _identify_all(args, source, sensors, inputs):
    """(flight, autopilot, current parameters, every sensor's flight, their results): one
    sensor as `identify`; a log with two or more airspeed sensors fitted jointly, one wind."""
    from pitotcal.estimation import identify, identify_sensors
    from pitotcal.estimation.robustness.consistency import hides_threshold, with_hides_threshold
    from pitotcal.io.sensors import other_sensor_flights

    flight, autopilot, current = _read(args, source)
    arm_m = sensors[0].get("probe_arm_m", 0.0)
    flights = [flight, *other_sensor_flights(source, flight, csv_columns=args.columns, single_only={
        "--gps-error-sigma-mps": args.gps_error_sigma_mps, "--probe-arm-m": arm_m})]
    fit = ([with_hides_threshold(r, hides_threshold(args.hides_threshold_kt)) for r in
            identify_sensors(flights, model=args.model, air=args.air, budget=inputs,
                             gps_noise_std_mps=args.gps_noise_mps, wind=args.wind,
                             wind_knot_s=args.wind_knot_s)] if len(flights) > 1 else
           [identify(flight, model=args.model, air=args.air, budget=inputs, probe_arm_m=arm_m,
                     gps_noise_std_mps=args.gps_noise_mps, wind=args.wind,
                     wind_knot_s=args.wind_knot_s, hides_threshold_kt=args.hides_threshold_kt,
                     **_gps_error(args))])
    return flight, autopilot, current, flights, fit


def _recommend(args, flights, result, sensors, autopilot, current):
    """(recommendation, refusal, per sensor) with --params: the first sensor's, and with
    several sensors each one's (`recommend_sensors`, written to one file)."""
    from pitotcal.core.errors import PitotcalError
    from pitotcal.estimation.reporting.autopilot_params import recommend_sensors

    if len(flights) > 1:
        per = recommend_sensors(flights, autopilot, current, air=args.air, path=args.params,
                                misfit_tolerance_kt=args.misfit_tolerance_kt,
                                gps_noise_std_mps=args.gps_noise_mps, wind=args.wind,
                                wind_knot_s=args.wind_knot_s)
        return per[0][0], next((exc for _, exc in per if exc is not None), None), per
    flight, arm_m = flights[0], sensors[0].get("probe_arm_m", 0.0)
    if arm_m:           # the recommendation refits: the data corrected as the result was
        from pitotcal.estimation.identification.budget import lever_arm_corrected
        flight = lever_arm_corrected(flight, result, arm_m)
    try:
        return _write_params(args, flight, autopilot, current), None, None
    except PitotcalError as exc:        # said after the summary
        return None, exc, None


def _checked_outputs(args, source):
    """`check_outputs` of --json, --plot and --params; the figure's path as written."""
    from .common import check_outputs

    outputs = {"--json": args.json, "--plot": args.plot, "--params": args.params}
    return check_outputs(outputs, [(source, "the input flight file")], figures=["--plot"])["--plot"]


def _read(args, source):
    """(Flight with its air data made from the user's temperature source, recovery factor and
    humidity, autopilot, current parameters): the autopilot and its parameters only with
    --params (None, {} otherwise)."""
    from .common import oat_k_from_c
    from pitotcal.core.errors import PitotcalError
    from pitotcal.io import read_flight

    air = {"oat_k": oat_k_from_c(args.oat_c), "temp_recovery": args.temp_recovery,
           "rh_pct": args.rh_percent, "windows": args.windows}
    if args.oat_ground_c is not None:
        air["oat_ground_k"] = oat_k_from_c(args.oat_ground_c, "--oat-ground-c")
    if args.params is None:
        return read_flight(source, start_s=args.start_s, end_s=args.end_s,
                           columns=getattr(args, "columns", None), **air), None, {}
    if getattr(args, "columns", None) is not None:
        raise PitotcalError("--params reads an autopilot log; --columns maps a CSV export: "
                            "give one of them", param="columns")
    from pitotcal.io.param_files import read_flight_and_parameters
    flight, autopilot, current = read_flight_and_parameters(source, args.start_s, args.end_s,
                                                            **air)
    if autopilot is None:
        raise PitotcalError(f"--params: {source.name} names no autopilot; give the "
                            "ArduPilot or PX4 log (or the CSV `pitotcal convert` made of it)")
    _check_params_temperature(flight, args.oat_c)
    return flight, autopilot, current


def _check_params_temperature(flight, oat_c):
    """Refuse to recommend a parameter from a density made of a sensor temperature: a sensor
    15 K warmer than the air moves ARSPD_RATIO by ~5 %, far outside the fit's 2σ."""
    from pitotcal.core.errors import PitotcalError

    source = str(flight.meta.get("temperature_source", ""))
    if oat_c is None and "sensor temperature, not OAT" in source:
        raise PitotcalError(f"--params: {flight.source} has no outside air temperature (density "
                            f"from {source.split(':')[0]}, a sensor's); a sensor 15 K warm moves "
                            "the recommended value by ~5 %: give the OAT with --oat-c")


def _write_plot(path, result, budget):
    """The calibration figure, with the expanded-uncertainty band when there is a budget."""
    if budget is None:
        result.plot(path)
        return
    from pitotcal.estimation.reporting.budget_tables import plot_budget_band
    from pitotcal.io.atomic import save_figure

    fig = result.plot()
    plot_budget_band(fig.axes[0], result, budget)      # the ΔV axes
    save_figure(fig, path, dpi=110)


def _write_params(args, flight, autopilot, current):
    """The recommended airspeed parameter, or a PitotcalError (exit 2) saying why not."""
    from pitotcal.estimation.reporting import autopilot_params
    from pitotcal.io.param_files import PX4_SCALES

    # PX4: the scale parameter the log has (its name changed between releases)
    name = next((n for n in PX4_SCALES if n in current), None) if autopilot == "PX4" else None
    default = autopilot_params.PARAMETER.get(autopilot, "")
    rec = autopilot_params.recommend(flight, autopilot, current.get(name or default),
                                     gps_noise_std_mps=args.gps_noise_mps, name=name,
                                     air=args.air, misfit_tolerance_kt=args.misfit_tolerance_kt,
                                     log_parameters=current, **_gps_error(args))
    autopilot_params.write_parameter_file(rec, args.params)
    return rec


def _params_record(args, rec, refused):
    """The JSON's ``autopilot_parameter`` (docs/interfaces.md §13): the recommendation, or why
    none, with the structure misfit; nothing without --params."""
    if args.params is None:
        return {}
    if rec is not None:
        return {"autopilot_parameter": rec.to_dict()}
    return {"autopilot_parameter": {"refused": str(refused),
                                    "structure_misfit": getattr(refused, "misfit", None)}}


def _print_params(rec, path):
    print(f"\nRecommended {rec.name} = {rec.value:.4f} ± {rec.two_sigma:.4f} (2σ)"
          + ("" if rec.current is None else f", now {rec.current:.6g}")
          + f"; wrote {path}")
    print(f"  {rec.misfit_line()}")
    for note in rec.notes:
        print(f"  note: {note}")


def _gps_error(args):
    """identify's stated GPS error keywords (the record's "gps_error", docs/interfaces.md §19)."""
    return {"gps_error_sigma_mps": args.gps_error_sigma_mps,
            "gps_error_tau_s": args.gps_error_tau_s}


def _run_live(args):
    """`--live CONNECTION`: estimation.live.identify_stream, its updates on stderr."""
    import sys

    from .common import announce_stream, check_outputs, idle_timeout_s, oat_k_from_c
    from pitotcal.core.checks import choice, positive
    from pitotcal.core.errors import PitotcalError
    from pitotcal.core.models import MODELS
    from pitotcal.estimation.live import identify_stream

    if args.live is None and args.flight is None:
        raise PitotcalError("give the FLIGHT to identify (a flight CSV or a ULog/DataFlash log), "
                            "or --live CONNECTION")
    if args.live is not None and args.flight is not None:
        raise PitotcalError("give either FLIGHT (a file) or --live CONNECTION, not both")
    choice("model", args.model, list(MODELS))
    positive("target_2sigma_kt", args.target_2sigma_kt)
    if sensor_options(args)[0].get("probe_arm_m"):
        raise PitotcalError("`probe_arm_m`: a live stream is not corrected for the probe's lever "
                            "arm; identify the flight's log instead")
    plot_path = check_outputs({"--json": args.json, "--plot": args.plot},
                              [(args.live, "the input stream")], figures=["--plot"])["--plot"]
    met = []

    def show(fix, message):
        if fix is None:
            print(f"waiting: {message}", file=sys.stderr)
            return
        flag = ""
        if fix.target_met and not met:
            met.append(fix.time_s)
            flag = f"  <- 2-sigma target {args.target_2sigma_kt:g} kt met: the maneuver can end"
        print(f"{fix.time_s:8.1f} s {fix.n_samples:7d} samples  dV at {fix.vi_kt:5.1f} kt: "
              f"{fix.dv_kt:+6.2f} +/- {fix.dv_2sigma_kt:5.2f} kt (2 sigma)  "
              f"[{fix.update_s * 1000:4.0f} ms]{flag}", file=sys.stderr)

    oat_k, idle_s = oat_k_from_c(args.oat_c), idle_timeout_s(args.idle_s)
    announce_stream("identify", args.live, idle_s)
    result, flight, fixes, buf = identify_stream(
        args.live, model=args.model, target_2sigma_kt=args.target_2sigma_kt,
        oat_k=oat_k, idle_timeout_s=idle_s,
        on_fix=show, air=args.air, gps_error=_gps_error(args), temp_recovery=args.temp_recovery,
        rh_pct=args.rh_percent, budget=None if args.no_budget else budget_inputs(args),
        record_options={"wind": args.wind, "wind_knot_s": args.wind_knot_s,
                        "hides_threshold_kt": args.hides_threshold_kt})
    # the record is the offline one (the library's), plus how the stream went
    if args.json is not None:
        from pitotcal.io.jsonfile import write_json
        write_json(args.json, {**result.to_dict(), "source": args.live, "live": {
            "updates": len(fixes), "target_2sigma_kt": args.target_2sigma_kt,
            "target_met_at_s": met[0] if met else None, "stream_ended": buf.stopped,
            "max_update_s": max((f.update_s for f in fixes), default=None)}})
    if plot_path is not None:
        _write_plot(plot_path, result, result.budget)
    print(f"Stream: {args.live} ({flight.n} samples, {flight.time_s[0]:.1f}-"
          f"{flight.time_s[-1]:.1f} s, ended: {buf.stopped}; {len(fixes)} live updates)")
    print(result.summary())
    if result.budget is not None:
        from pitotcal.estimation.reporting.budget_tables import budget_summary
        print("\n" + budget_summary(result, result.budget))
    for path in (args.json, plot_path):
        if path is not None:
            print(f"Wrote {path}")
    return 0
