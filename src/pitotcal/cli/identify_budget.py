"""`identify`'s temperature, humidity and uncertainty-budget options: the flags, their ranges,
and the budget's inputs made from them and the aircraft file's [sensors] table."""

__all__ = ["BUDGET_INPUT_RANGES", "add_budget_arguments", "budget_inputs", "sensor_options"]


def add_budget_arguments(p, help_constants):
    """Temperature/humidity inputs and the uncertainty budget's overrides."""
    air = p.add_argument_group("temperature and humidity")
    air.add_argument("--temp-recovery", type=float, default=1.0, metavar="R",
                     help="recovery factor of the total-temperature probe of a tat_k column, "
                          "T_s = T_t / (1 + R 0.2 M^2); default %(default)s")
    air.add_argument("--rh-percent", type=float, default=None, metavar="PCT",
                     help="relative humidity, %%, for the density through the virtual "
                          "temperature (overrides an rh_pct column; default: the column, else "
                          "dry air)")
    bud = p.add_argument_group(
        "uncertainty budget",
        "GUM budget of the airspeed correction: the statistical 2-sigma plus Type B inputs, "
        "each given as a standard uncertainty and propagated through the fit's sensitivities "
        "to the perturbed flight; reported as the expanded uncertainty U (k = 2). The defaults quoted are the "
        "flight-test class's; --sensor-class takes another class's (docs/interfaces.md)")
    bud.add_argument("--no-budget", action="store_true",
                     help="skip the budget (by the fit's sensitivities: no extra solve unless a "
                          "term is not linear, then up to {budget_solves} extra solves)")
    bud.add_argument("--sensor-class", default=None, metavar="CLASS",
                     help="the sensors' class, whose defaults fill every input not given: "
                          "{sensor_classes} (default {default_class}, or the aircraft file's "
                          "[sensors] class)")
    bud.add_argument("--aircraft", metavar="AIRCRAFT.toml", default=None,
                     help="the aircraft file (as report --aircraft): its [sensors] table "
                          "gives the class and any input below by the same name (class, "
                          "oat_source, u_oat_k, u_ps_pa, probe_arm_m, ...); a flag overrides it")
    bud.add_argument("--oat-source", default=None, metavar="SOURCE",
                     help="where the temperature came from, which sets u(OAT): {oat_sources} "
                          "(default: what the flight says: a logged OAT is a probe, --oat-c "
                          "user, a tat_k column total-temperature, no temperature isa, a "
                          "pressure chip's sensor-chip)")
    for flag, metavar, text in _BUDGET_FLAGS:
        bud.add_argument(flag, type=float, default=None, metavar=metavar, help=text)
    p.help_from(help_constants)


# (flag, metavar, help); the default None leaves BudgetInputs' own, which the help quotes
_BUDGET_FLAGS = (
    ("--u-oat-k", "K", ("static air temperature, K; default by its source: a probe "
                        "{u_oat_k:g} (flight-test), {u_oat_sources}")),
    ("--u-rh-percent", "PCT", ("relative humidity, %%RH; default {rh_given:g} with a humidity, "
                               "else {rh_unknown:.0f} (dry assumed, 0-100 %% rectangular)")),
    ("--u-gps-velocity-mps", "MPS", "GPS velocity bias per axis, m/s; default "
                                    "{u_gps_velocity_mps:g}"),
    ("--u-gps-latency-s", "S", "GPS-pressure time alignment, s; default {u_gps_latency_s:g}"),
    ("--probe-arm-m", "M", ("lateral offset of the pitot probe from the centre line, m "
                            "(right wing +), corrected in the data: turns make it see "
                            "V_t - r y; default {probe_arm_m:g}")),
    ("--u-probe-arm-m", "M", ("the lever arm's own uncertainty, m; default {arm_fraction:g} %% "
                              "of --probe-arm-m")),
    ("--u-qc-scale-percent", "PCT", "differential transducer gain, %% of reading; default "
                                    "{u_qc_scale_percent:g}"),
    ("--u-qc-offset-pa", "PA", "differential transducer zero offset, Pa; default "
                               "{u_qc_offset_pa:g}"),
    ("--u-ps-pa", "PA", "static-pressure transducer, Pa; default {u_ps_pa:g}"),
)


# What a stated uncertainty or lever arm can be: beyond these it is no measurement (a
# thermometer 50 K off, a GPS velocity 5 m/s off, a clock 2 s off, a zero offset of 1 kPa, the
# q_c of 80 kt) and the budget would be all of it, or overflow.
BUDGET_INPUT_RANGES = {"u_oat_k": (0.0, 50.0), "u_gps_velocity_mps": (0.0, 5.0),
                       "u_gps_latency_s": (0.0, 2.0), "u_qc_offset_pa": (0.0, 1000.0),
                       "probe_arm_m": (-50.0, 50.0), "u_probe_arm_m": (0.0, 50.0),
                       "u_ps_pa": (0.0, 5000.0)}
# BudgetInputs field -> the flag's dest, for the flags whose names differ
_FIELD_FLAG = {"u_rh_pct": "u_rh_percent", "u_qc_scale": "u_qc_scale_percent"}


def sensor_options(args):
    """(BudgetInputs options, their origins) from the aircraft file's [sensors] and the flags
    (a flag wins); `probe_arm_m` among them is the arm corrected in the data."""
    from pitotcal.core.checks import choice, number
    from pitotcal.estimation.identification import sensor_inputs as si

    options, origins = {}, {}
    if args.aircraft is not None:
        import tomllib

        from pitotcal.estimation.reporting.aircraft_file import read_aircraft
        read_aircraft(args.aircraft)            # refuses a bad file, naming the key
        with open(args.aircraft, "rb") as f:
            table = tomllib.load(f).get("sensors", {})
        if isinstance(table, dict):
            options, origins = si.inputs_from_table(table, args.aircraft)
    if args.sensor_class is not None:
        options["sensor_class"] = choice("sensor_class", args.sensor_class, si.SENSOR_CLASSES)
        origins["sensor_class"] = "flag --sensor-class"
    if args.oat_source is not None:
        options["oat_source"] = choice("oat_source", args.oat_source, tuple(si.OAT_SOURCES))
        origins["oat_source"] = "flag --oat-source"
    if args.u_rh_percent is not None:
        number("u_rh_percent", args.u_rh_percent, 0.0, 100.0)
    for name, (lo, hi) in BUDGET_INPUT_RANGES.items():
        if getattr(args, name) is not None:
            number(name, getattr(args, name), lo, hi)
    for _, field, _, _ in si.SENSOR_TOML_KEYS:
        dest = _FIELD_FLAG.get(field, field)
        value = getattr(args, dest, None)
        if value is None or field in ("sensor_class", "oat_source"):
            continue
        if field == "u_qc_scale":
            value = number("u_qc_scale_percent", value, 0.0, 100.0) / 100.0
        options[field] = value
        origins[field] = f"flag --{dest.replace('_', '-')}"
    return options, origins


def budget_inputs(args, options=None):
    """The budget's inputs (`BudgetInputs`, each given value's origin in it), the corrected
    lever arm left out: identify takes that itself."""
    from pitotcal.estimation.identification.budget import inputs_from_options

    options, origins = options or sensor_options(args)
    given = {k: v for k, v in options.items() if k != "probe_arm_m"}
    origins = {k: v for k, v in origins.items() if k in given}
    return inputs_from_options(**given, origins=origins)
