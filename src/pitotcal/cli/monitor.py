"""`pitotcal monitor SOURCE --calibration RESULT.json`: airspeed health monitoring
(docs/interfaces.md, "pitotcal monitor").

Exit status: 0 no alarm; 1 one or more alarms (like grep: a script can test it); 2 unusable
input (flight, calibration or option), one stderr line naming it.
"""

from pathlib import Path


def add_parser(subparsers):
    from .common import add_reading_arguments

    p = subparsers.add_parser(
        "monitor", help="test a flight's airspeed against a calibration (health monitoring)",
        description="Predict the pitot's q_ci from GPS velocity, the calibration's wind, model "
                    "and air data, and test the measured q_ci with sequential tests (CUSUM) "
                    "whose thresholds follow from the calibration's residual noise model and a "
                    "designed false-alarm rate. The monitor learns the flight's turbulence and "
                    "wind during a warm-up and tracks them slowly. Alarms are classified "
                    "(frozen, drain, step, drift, erratic). Prints a summary and, as the last "
                    "line, the alarms as JSON. Exit 1 when there are alarms.")
    p.add_argument("source", metavar="SOURCE",
                   help="flight CSV, autopilot log (.ulg, .bin, .log), or a live MAVLink "
                        "connection (udp:127.0.0.1:14550; SCALED_PRESSURE and "
                        "GLOBAL_POSITION_INT; ends when nothing arrives for --idle-s)")
    p.add_argument("--calibration", required=True, metavar="RESULT.json",
                   help="result of pitotcal identify --json")
    p.add_argument("--json", metavar="OUT.json", default=None, help="write the result as JSON")
    p.add_argument("--plot", metavar="OUT.png", default=None,
                   help="write the figure (paper Fig. 15 style)")
    add_reading_arguments(p)
    p.add_argument("--idle-s", type=float, default=None, metavar="S",
                   help="live: the stream has ended after S seconds without a message "
                        "(default {idle_s:g})")
    t = p.add_argument_group("test design")
    t.add_argument("--false-alarms-per-hour", type=float, default=None, metavar="RATE",
                   help="designed false-alarm rate per flight hour (default "
                        "{false_alarms_per_hour:g})")
    t.add_argument("--warmup-s", type=float, default=None, metavar="S",
                   help="seconds at the start to learn turbulence and wind, without alarms "
                        "(default {warmup_s:g})")
    t.add_argument("--drift-kt-per-min", type=float, default=None, metavar="RATE",
                   help="indicated-airspeed drift the ramp test is tuned to, kt/min "
                        "(default {drift_kt_per_min:g})")
    p.help_from(_help_constants)
    p.set_defaults(run=run)


# the test-design flags; a flag not given leaves MonitorOptions' own default
_DESIGN_FLAGS = ("false_alarms_per_hour", "warmup_s", "drift_kt_per_min")
# Beyond these the test design means nothing: a false alarm a minute is all the alarms there
# are, and 60 kt a minute is a failure, not a drift. (The warm-up is bounded by the flight.)
DESIGN_MAX = {"false_alarms_per_hour": 60.0, "drift_kt_per_min": 60.0}


def _help_constants():
    """The monitor's defaults, which `monitor --help` quotes."""
    import dataclasses

    from pitotcal.estimation.monitor.cusum import MonitorOptions
    from pitotcal.io.mavlink_live import IDLE_TIMEOUT_S

    return {**dataclasses.asdict(MonitorOptions()), "idle_s": IDLE_TIMEOUT_S}


def _read_calibration(path):
    """The `Calibration` of the record at `path` (`pitotcal.io.result_record.read_result`)."""
    from pitotcal.estimation.monitor.model import Calibration
    from pitotcal.io.result_record import read_result

    record = read_result(path, name=f"--calibration {path}", table=False)
    return Calibration.from_dict(record, source=str(path))


def _check_warmup(flight, warmup_s):
    """Refuse a warm-up that leaves nothing to monitor (it printed "0 alarm(s)", exit 0)."""
    from pitotcal.core.errors import PitotcalError

    t0, t1 = float(flight.time_s[0]), float(flight.time_s[-1])
    if t1 - t0 <= warmup_s:
        raise PitotcalError(f"--warmup-s {warmup_s:g}: the flight has {t1 - t0:.0f} s "
                            f"({t0:.1f}-{t1:.1f} s), nothing left to monitor after the warm-up; "
                            "give a shorter --warmup-s", param="warmup_s")


def run(args):
    import json
    import sys
    import warnings

    from .common import announce_stream, check_outputs, idle_timeout_s, oat_k_from_c
    from pitotcal.core.checks import number
    from pitotcal.estimation.live import monitor_stream
    from pitotcal.estimation.monitor.monitoring import monitor
    from pitotcal.estimation.monitor.cusum import MonitorOptions
    from pitotcal.io import read_flight
    from pitotcal.io.jsonfile import write_json
    from pitotcal.io.mavlink_live import is_connection

    source = Path(args.source)
    plot_path = check_outputs({"--json": args.json, "--plot": args.plot},
                              [(source, "the input flight file"),
                               (args.calibration, "the input calibration")],
                              figures=["--plot"])["--plot"]
    cal = _read_calibration(args.calibration)
    opts = MonitorOptions(**{name: getattr(args, name) for name in _DESIGN_FLAGS
                             if getattr(args, name) is not None}).checked()
    for name, hi in DESIGN_MAX.items():
        number(name, getattr(opts, name), hi=hi)
    idle_s = idle_timeout_s(args.idle_s)        # checked for a file too: NaN is no option
    if is_connection(args.source):
        oat_k = oat_k_from_c(args.oat_c)
        announce_stream("monitor", args.source, idle_s)
        result, buf = monitor_stream(args.source, cal, opts, oat_k=oat_k, idle_timeout_s=idle_s,
                                     on_status=lambda text: print(text, file=sys.stderr))
        flight = buf.flight()
        _check_warmup(flight, opts.warmup_s)
    else:
        flight = read_flight(source, start_s=args.start_s, end_s=args.end_s,
                             oat_k=oat_k_from_c(args.oat_c))
        result = monitor(flight, cal, opts)      # a flight too short for it is said there
        _check_warmup(flight, opts.warmup_s)
    for message in result.warnings:
        warnings.warn(message, stacklevel=2)
    out = result.to_dict()
    out["warnings"] = list(out["warnings"]) + [w for w in flight.warnings
                                               if w not in out["warnings"]]
    # files first, then the summary: a reader that goes away early never costs a file
    if args.json is not None:
        write_json(args.json, out)
    if plot_path is not None:
        result.plot(plot_path)
    print(f"Flight: {source} ({flight.n} samples, {flight.time_s[0]:.1f}-"
          f"{flight.time_s[-1]:.1f} s); calibration {args.calibration} ({cal.model}, "
          f"{cal.air_data})")
    print(result.summary())
    for path in (args.json, plot_path):
        if path is not None:
            print(f"Wrote {path}")
    print(json.dumps({"alarms": out["alarms"]}))
    return 1 if result.alarms else 0
