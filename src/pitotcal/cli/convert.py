"""`pitotcal convert`: a PX4 ULog or ArduPilot DataFlash log to the flight CSV
(docs/interfaces.md §8)."""

from pathlib import Path


def add_parser(subparsers):
    from .common import add_reading_arguments

    p = subparsers.add_parser(
        "convert", help="convert a PX4 .ulg, ArduPilot .bin/.log or MAVLink .tlog to a flight CSV",
        description="Read a PX4 ULog (.ulg), an ArduPilot DataFlash log (.bin binary, .log text) "
                    "or a MAVLink telemetry log (.tlog), "
                    "put GPS velocity, static pressure and temperature on the airspeed sensor's "
                    "time base, cut the GPS-invalid parts and what the autopilot did not fly "
                    "(its landed/armed state, take-off and landing rolls), and write the flight "
                    "CSV ({columns}; gps_vd_mps and alt_m when the log has them). "
                    "Comment lines name the source, the firmware, every conversion and cut, and "
                    "the autopilot's own wind and airspeed ratio/scale.")
    p.add_argument("log", metavar="LOG", help="log file: .ulg, .bin, .log or .tlog")
    p.add_argument("-o", "--output", required=True, metavar="FLIGHT.csv",
                   help="flight CSV to write")
    add_reading_arguments(p)
    p.add_argument("--oat-ground-c", type=float, default=None, metavar="DEGC",
                   help="the ground temperature at the take-off point, degC, carried up the "
                        "standard lapse (6.5 K/km) for the density, when no outside air "
                        "temperature is logged or given (--oat-c)")
    p.add_argument("--gps-resample", choices=("linear", "hold"), default="linear",
                   help="GPS onto the pressure times: interpolate between fixes, or hold the "
                        "last fix (default: %(default)s)")
    p.help_from(_help_constants)
    p.set_defaults(run=run)


def _help_constants():
    """The columns `convert --help` lists: those the flight CSV writer writes of a log's flight."""
    from pitotcal.io.flight_csv import WRITTEN_COLUMNS, WRITTEN_IF_PRESENT
    from pitotcal.io.logs import LOG_COLUMNS

    columns = [*WRITTEN_COLUMNS, *(c for c in WRITTEN_IF_PRESENT if c in LOG_COLUMNS)]
    return {"columns": ", ".join(columns)}


def run(args):
    from .common import check_outputs, oat_k_from_c
    from pitotcal.io import write_flight_csv
    from pitotcal.io.logs import load_log

    src, out = Path(args.log), Path(args.output)
    check_outputs({"-o": out}, [(src, "the input log")])    # said before reading a large log
    ground = (None if args.oat_ground_c is None
              else oat_k_from_c(args.oat_ground_c, "--oat-ground-c"))
    flog = load_log(src, args.start_s, args.end_s, gps_resample=args.gps_resample,
                    oat_k=oat_k_from_c(args.oat_c), oat_ground_k=ground)
    flight = flog.flight
    write_flight_csv(flight, out, comments={"converted_by": "pitotcal convert"})
    print(f"pitotcal convert: {src.name} ({flog.autopilot}, {flog.log_format}) -> {out}: "
          f"{flight.n} samples, {flight.time_s[0]:.1f}-{flight.time_s[-1]:.1f} s since log "
          f"start; cut {flight.n_dropped} samples"
          + (f" ({'; '.join(f'{k}: {v}' for k, v in flog.excluded.items())})"
             if flog.excluded else ""))
    return 0
