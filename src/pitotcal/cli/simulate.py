"""`pitotcal simulate PLAN.csv -o FLIGHT.csv [--seed N] [truth options]` (docs/interfaces.md)."""


def add_parser(subparsers):
    # numpy-free: the parser is built for every command (TRUE_K has one entry per model)
    from pitotcal.core.scenario import TRUE_K, true_k

    p = subparsers.add_parser(
        "simulate", help="fly a plan in simulation and write a flight CSV with its truth",
        description="Fly PLAN.csv through the point-mass dynamics with tracking controllers, "
                    "in wind and Dryden turbulence, and record the sensors. Writes FLIGHT.csv "
                    "and FLIGHT.truth.json beside it. The same seed gives the same file.")
    p.add_argument("plan", help="plan CSV (pitotcal plan)")
    p.add_argument("-o", "--output", required=True, help="flight CSV to write")
    p.add_argument("--seed", type=int, default=0, help="random seed (default %(default)s)")
    g = p.add_argument_group("truth")
    g.add_argument("--model", default="inverse",
                   help=f"pressure-error structure: {', '.join(TRUE_K)} (default %(default)s)")
    k1, k2 = true_k("inverse")
    g.add_argument("--k1", type=float, help=f"true k1 (default {k1:g})")
    g.add_argument("--k2", type=float, help=f"true k2 (default {k2:g} Pa for inverse)")
    g.add_argument("--wind-speed-mps", type=float, help="mean wind speed (default: the plan's)")
    g.add_argument("--wind-from-deg", type=float,
                   help="mean wind FROM, deg true, 0-360 (default: the plan's)")
    g.add_argument("--wind-drift-n-mps2", type=float, default=0.0, help="wind drift north, m/s^2")
    g.add_argument("--wind-drift-e-mps2", type=float, default=0.0, help="wind drift east, m/s^2")
    g.add_argument("--turbulence-mps", type=float, default=0.5,
                   help="Dryden horizontal RMS (%(default)g)")
    g.add_argument("--turbulence-length-m", type=float, help="gust scale length (MIL-F-8785C)")
    s = p.add_argument_group("sensors")
    s.add_argument("--rate-hz", type=float, default=50.0, help="sample rate (%(default)g)")
    s.add_argument("--qc-noise-pa", type=float, default=0.5,
                   help="transducer noise std (%(default)g)")
    s.add_argument("--qc-quantization-pa", type=float, default=0.0,
                   help="converter step (%(default)g)")
    s.add_argument("--qc-bias-pa", type=float, default=0.0, help="transducer bias (%(default)g)")
    s.add_argument("--qc-scale-error", type=float, default=0.0,
                   help="relative gain error (%(default)g)")
    s.add_argument("--pneumatic-lag-s", type=float, default=0.0, help="tubing lag (%(default)g)")
    s.add_argument("--gps-rate-hz", type=float, default=5.0,
                   help="GPS update rate, 0 = every sample (%(default)g)")
    s.add_argument("--gps-noise-mps", type=float, default=0.05,
                   help="GPS velocity noise std (%(default)g)")
    s.add_argument("--gps-latency-s", type=float, default=0.0,
                   help="GPS velocity latency (%(default)g)")
    s.add_argument("--gps-gm-sigma-mps", type=float, default=0.0,
                   help="time-correlated (Gauss-Markov) GPS velocity error std, m/s (0: none)")
    s.add_argument("--gps-gm-tau-s", type=float, default=30.0,
                   help="its correlation time, s (%(default)g)")
    # Dryden's vertical gust flown (plunge, altitude, GPS climb, V_t)
    s.add_argument("--vertical-gusts", action="store_true",
                   help="fly the vertical gust too: the aircraft plunges with it and the "
                        "airspeed includes the air-relative climb (own engine; JSBSim's "
                        "turbulence always has it)")
    g.add_argument("--air-data", default=None,
                   help="true impact pressure from true airspeed: compressible (isentropic, "
                        "ISA p and T; the flight gets ps_pa and oat_k) or incompressible "
                        "(1/2 rho V^2, the paper's eq. 2); default {air_data}, as identify "
                        "fits; JSBSim's is always compressible")
    e = p.add_argument_group("flight model")
    e.add_argument("--engine", default="own", choices=("own", "jsbsim"),
                   help="own: pitotcal's point-mass model (fast, default); jsbsim: the JSBSim "
                        "six-degree-of-freedom model, its atmosphere and Milspec turbulence")
    e.add_argument("--aircraft", default=None,
                   help="JSBSim aircraft (default {aircraft}); --engine jsbsim only")
    f = p.add_argument_group("fault (a sensor failure injected into the flight)")
    f.add_argument("--fault", metavar="KIND:ONSET_S:SIZE", default=None,
                   help="spoil the pitot-static record from ONSET_S on: blocked (SIZE drain "
                        "time constant s, 0 frozen), static (SIZE s, 0 sealed), leak (SIZE "
                        "fraction low), icing (SIZE kt/min), water (SIZE fraction); the truth "
                        "JSON gets \"fault\"")
    a = p.add_argument_group(
        "air-data sensors",
        "with any of these the flight also logs ps_pa, oat_k or tat_k, and rh_pct")
    a.add_argument("--tat-recovery", type=float, default=None, metavar="R",
                   help="log a total-temperature probe of recovery factor R (tat_k) instead of "
                        "the static oat_k")
    a.add_argument("--rh-percent", type=float, default=None, metavar="PCT",
                   help="relative humidity of the air: the true density uses the virtual "
                        "temperature; logged as rh_pct")
    a.add_argument("--probe-arm-m", type=float, default=None, metavar="M",
                   help="pitot probe at y = M on the wing (right +): it sees V_t - r y in turns")
    a.add_argument("--oat-bias-k", type=float, default=None, metavar="K",
                   help="bias of the logged temperature, K")
    a.add_argument("--gps-bias-mps", type=float, nargs=3, default=None, metavar=("N", "E", "D"),
                   help="constant GPS velocity bias north, east, down, m/s")
    p.help_from(_help_constants)
    p.set_defaults(run=run)


def _help_constants():
    """The simulator's defaults, which `simulate --help` quotes."""
    from pitotcal.maneuvers.fly.jsbsim_engine import DEFAULT_AIRCRAFT
    from pitotcal.maneuvers.fly.options import ENGINE_AIR_DATA

    return {"air_data": ENGINE_AIR_DATA["own"], "aircraft": DEFAULT_AIRCRAFT}


def _air_sensors(args):
    """The `air_sensors` dict of the options given, or None (no air-data sensors simulated)."""
    given = {"tat_recovery": args.tat_recovery, "rh_pct": args.rh_percent,
             "probe_arm_m": args.probe_arm_m, "oat_bias_k": args.oat_bias_k,
             "gps_bias_mps": None if args.gps_bias_mps is None else tuple(args.gps_bias_mps)}
    given = {k: v for k, v in given.items() if v is not None}
    return given or None


def _options(args):
    """The flags as the library's `SimulationOptions`: it checks each value, naming the field,
    which `pitotcal.cli.flag_message` shows as its flag; --k1 / --k2 replace the model's
    default coefficients by name."""
    from pitotcal.maneuvers.fly.options import SimulationOptions

    k = {name: value for name, value in (("k1", args.k1), ("k2", args.k2)) if value is not None}
    return SimulationOptions(
        model=args.model, k=k or None, wind_speed_mps=args.wind_speed_mps,
        wind_from_deg=args.wind_from_deg,
        wind_drift_mps2=(args.wind_drift_n_mps2, args.wind_drift_e_mps2),
        turbulence_mps=args.turbulence_mps, turbulence_length_m=args.turbulence_length_m,
        rate_hz=args.rate_hz, qc_noise_pa=args.qc_noise_pa,
        qc_quantization_pa=args.qc_quantization_pa, qc_bias_pa=args.qc_bias_pa,
        qc_scale_error=args.qc_scale_error, pneumatic_lag_s=args.pneumatic_lag_s,
        gps_rate_hz=args.gps_rate_hz, gps_noise_mps=args.gps_noise_mps,
        gps_latency_s=args.gps_latency_s, air_data=args.air_data,
        air_sensors=_air_sensors(args), gps_gm_sigma_mps=args.gps_gm_sigma_mps,
        gps_gm_tau_s=args.gps_gm_tau_s, vertical_gusts=args.vertical_gusts,
        engine=args.engine, aircraft=args.aircraft, keep_history=args.fault is not None)


def _outputs(args):
    """The flight and truth paths; the input is never overwritten, and the truth stays beside
    the flight even when the flight's name ends in .json."""
    from pathlib import Path

    from .common import check_outputs
    from pitotcal.core.errors import PitotcalError
    from pitotcal.maneuvers.fly.truth import truth_path_for

    out, truth_out = Path(args.output), truth_path_for(args.output)
    if out.suffix.lower() == ".json":
        raise PitotcalError(f"-o {args.output}: the flight is a CSV; name it FLIGHT.csv "
                            f"(the truth goes to {truth_out.name})")
    check_outputs({"-o": out, "-o (its truth file)": truth_out},
                  [(args.plan, f"the plan {args.plan}")])
    return out, truth_out


# The simulator's options a plan's comment lines supply when their flag is not given.
_FROM_PLAN = ("wind_speed_mps", "wind_from_deg")


def _plan_comment_error(exc, args, plan):
    """`exc` about a value the plan's comment line gave (its wind, no flag given) as an error
    naming that line, not the flag the user did not give; else `exc` itself."""
    from pitotcal.core.errors import PitotcalError

    param = getattr(exc, "param", None)
    if param not in _FROM_PLAN or getattr(args, param) is not None \
            or param not in plan.settings:
        return exc
    rule = str(exc).removeprefix(param).strip()
    flag = "--" + param.replace("_", "-")
    return PitotcalError(f"{args.plan}: comment line '# {param}: {plan.settings[param]}': "
                         f"{rule} (the plan's wind, flown when {flag} is not given)")


def run(args):
    import warnings

    from pitotcal.core.errors import PitotcalError
    from pitotcal.core.models import get_model
    from pitotcal.io import write_flight_csv
    from pitotcal.io.plan_csv import read_plan
    from pitotcal.maneuvers.fly.simulator import simulate
    from pitotcal.maneuvers.fly.truth import tracking_warnings, write_truth_json

    options = _options(args)
    out, truth_out = _outputs(args)
    fault = None
    if args.fault is not None:
        from pitotcal.maneuvers.fly.faults import parse_fault
        fault = parse_fault(args.fault, seed=args.seed)
    plan = read_plan(args.plan)
    try:
        flight, truth = simulate(plan, options, seed=args.seed)
    except PitotcalError as exc:
        raise _plan_comment_error(exc, args, plan) from None
    if fault is not None:
        from pitotcal.maneuvers.fly.faults import apply_fault
        flight = apply_fault(flight, truth, fault)
    write_flight_csv(flight, out, comments={"plan": str(args.plan)})
    truth_path = write_truth_json(truth, truth_out)
    if fault is not None:
        from pitotcal.io.jsonfile import write_json
        from pitotcal.maneuvers.fly.faults import truth_with_fault
        write_json(truth_path, truth_with_fault(truth, fault))
    print(f"wrote {args.output} ({flight.n} samples, {flight.time_s[-1] - flight.time_s[0]:.0f} s)"
          f" and {truth_path}")
    for message in tracking_warnings(truth):
        warnings.warn(message, stacklevel=2)
    tr, par = truth.tracking, truth.parameters
    model = get_model(truth.model)
    coeffs = ", ".join(f"{name} {par[name]:g}" for name in model.params)
    print(f"truth: {model.name} {coeffs}; wind {par['wind_speed_mps']:.2f} m/s from "
          f"{par['wind_from_deg']:.1f} deg; tracking: CAS within {tr.max_cas_error_kt:.1f} kt, "
          f"radius <= {tr.max_radius_m:.0f} m")
    return 0
