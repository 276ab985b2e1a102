"""`pitotcal demo`: plan, fly (simulate), identify and report the T-2 case (docs/interfaces.md);
the files it writes end with the calibration report, report.html."""

from pitotcal.core.scenario import T2_PLAN


def _case(t2=T2_PLAN):
    """The T-2 case in words, from the one place it is defined."""
    return (f"{t2['profile']} {t2['cas_min_kt']:g}-{t2['cas_max_kt']:g} KCAS, "
            f"{t2['radius_m']:g} m radius, {t2['altitude_m']:g} m")


def add_parser(subparsers):
    t2 = T2_PLAN
    p = subparsers.add_parser(
        "demo", help="the whole job on the paper's T-2 case, with known truth",
        description=f"Plan the T-2 maneuver ({_case()}, {t2['wind_speed_mps']:g} m/s wind), "
                    "fly it in the simulator (light turbulence, realistic sensors), identify the "
                    "calibration and the wind, print the calibration table next to the truth, and "
                    "write the calibration report (report.html).")
    p.add_argument("--out", dest="out_dir", default="pitotcal-demo", metavar="DIR",
                   help="folder for plan, flight, result and figures (default: ./%(default)s)")
    p.add_argument("--seed", type=int, default=0, help="simulator seed (default %(default)s)")
    p.add_argument("--duration-s", type=float, default=T2_PLAN["duration_s"],
                   help="maneuver length, s (default %(default)g; shorter only for quick checks)")
    p.add_argument("--rate-hz", type=float, default=None,
                   help="data rate, Hz (default: the demo's {rate_hz:g})")
    p.help_from(_help_constants)
    p.set_defaults(run=run)


def _help_constants():
    """The demo's simulation settings, which `demo --help` quotes."""
    from pitotcal.studies.demo import DEMO_SIM

    return dict(DEMO_SIM)


def run(args):
    from pitotcal.core.units import mps_to_kt
    from pitotcal.studies.demo import format_table, run_demo

    rate = {} if args.rate_hz is None else {"rate_hz": args.rate_hz}
    demo = run_demo(args.out_dir, seed=args.seed, duration_s=args.duration_s, **rate)
    res, truth = demo.result, demo.truth.parameters
    print(f"pitotcal demo: T-2 case, {_case()}, {args.duration_s:g} s, "
          f"{T2_PLAN['wind_speed_mps']:g} m/s wind from {T2_PLAN['wind_from_deg']:g}°, "
          f"seed {args.seed}")
    print(f"identified {res.model} model from {res.n_samples} samples "
          f"({'converged' if res.success else 'NOT converged: ' + res.message})")
    print(f"  {'parameter':15s} {'value':>10s}   {'±2σ':>6s}   {'truth':>10s}")
    for name in res.param_names:
        value, two = res.value(name), 2 * res.stddev(name)
        print(f"  {name:15s} {value:+10.4f} ± {two:<8.4g} {truth.get(name, float('nan')):+10.4f}")
    wind_kt = mps_to_kt(res.value("wind_speed_mps"))
    print(f"  wind: {wind_kt:.1f} kt from {res.value('wind_from_deg'):.0f}° "
          f"(truth {mps_to_kt(truth['wind_speed_mps']):.1f} kt from {truth['wind_from_deg']:.0f}°)")
    print()
    print("Airspeed correction ΔV = V_c - V_i (KCAS = V_i + ΔV):")
    print(format_table(demo.table))
    print()
    times = ", ".join(f"{k} {v:.2f} s" for k, v in demo.timing_s.items())
    print(f"time: {times}")
    print(f"wrote into {demo.out_dir}/:")
    for role, path in demo.files.items():
        print(f"  {path.name:22s} ({role})")
    return 0
