"""`pitotcal identify` of a log with two or more airspeed sensors: one shared wind, one
calibration per sensor (`pitotcal.estimation.identification.multi_sensor`), a `sensors` list in
the JSON, each sensor's summary, and each sensor's parameter in one --params file
(docs/interfaces.md §3). A log with one sensor never comes here.
"""

import warnings


def other_sensor_flights(args, source, flight, arm_m=0.0):
    """The flights of the log's airspeed sensors beyond the first; [] for one sensor, a CSV or
    a stream, and (with a warning) where an option applies to one sensor's fit only."""
    from pitotcal.io.sensors import read_other_sensors, sensor_count

    from .common import oat_k_from_c

    n = sensor_count(flight)
    if n < 2 or getattr(args, "columns", None) is not None:
        return []
    single_only = [flag for flag, given in (("--gps-error-sigma-mps", args.gps_error_sigma_mps),
                                            ("probe_arm_m", arm_m)) if given]
    if single_only:
        warnings.warn(f"{source}: the log has {n} airspeed sensors; {', '.join(single_only)} "
                      "applies to one sensor's fit: the first sensor alone is calibrated",
                      stacklevel=2)
        return []
    return read_other_sensors(source, args.start_s, args.end_s, oat_k=oat_k_from_c(args.oat_c),
                              temp_recovery=args.temp_recovery, rh_pct=args.rh_percent)


def fit_sensors(args, flights, inputs):
    """Every sensor's `IdentificationResult` of the joint fit, the first sensor's first."""
    from pitotcal.estimation.identification.multi_sensor import identify_sensors

    return identify_sensors(flights, model=args.model, air=args.air,
                            gps_noise_std_mps=args.gps_noise_mps, budget=inputs)


def sensor_params(args, flights, autopilot, current):
    """[(ParameterRecommendation or None, PitotcalError or None)] per sensor, each from the
    joint fits (constant, inverse, linear) sharing the wind; the recommended ones written to
    --params as one file."""
    from pitotcal.core.errors import ObservabilityError, PitotcalError
    from pitotcal.estimation.identification.multi_sensor import identify_sensors
    from pitotcal.estimation.reporting import autopilot_params as ap

    fits = {}
    for model in ("constant", "inverse", "linear"):
        try:
            fits[model] = identify_sensors(flights, model=model, air=args.air,
                                           gps_noise_std_mps=args.gps_noise_mps)
        except ObservabilityError:
            if model == "constant":
                raise
    out = []
    for i, flight in enumerate(flights):
        # PX4 has one scale per sensor only under the names ASPD_SCALE_1, _2, ...
        name = ap.sensor_parameter(autopilot, i)
        if name is None:
            out.append((None, PitotcalError(f"no parameter recommended for airspeed sensor "
                                            f"{i + 1}: {autopilot} has none for it")))
            continue
        try:
            out.append((ap.recommend(flight, autopilot, current.get(name), name=name,
                                     air=args.air, misfit_tolerance_kt=args.misfit_tolerance_kt,
                                     log_parameters=current,
                                     fits={m: r[i] for m, r in fits.items()},
                                     gps_noise_std_mps=args.gps_noise_mps), None))
        except PitotcalError as exc:
            out.append((None, exc))
    recs = [rec for rec, _ in out if rec is not None]
    if recs:
        ap.write_parameter_set(recs, args.params)
    return out


def sensors_record(results, flights, per_sensor=None):
    """The JSON's ``sensors`` list: each sensor's record (the usual keys) with its number and
    pressure source, and its ``autopilot_parameter`` with --params."""
    out = []
    for i, (res, flight) in enumerate(zip(results, flights)):
        item = {"sensor": i + 1, "qc_source": flight.meta.get("qc_source"), **res.to_dict()}
        if per_sensor is not None:
            rec, refused = per_sensor[i]
            item["autopilot_parameter"] = rec.to_dict() if rec is not None else {
                "refused": str(refused), "structure_misfit": getattr(refused, "misfit", None)}
        out.append(item)
    return {"sensors": out}


def print_sensors(results, flights):
    """The summaries of the sensors beyond the first (the first is printed as for one)."""
    for i, (res, flight) in enumerate(zip(results[1:], flights[1:]), start=2):
        print(f"\nAirspeed sensor {i} ({flight.meta.get('qc_source')}, {flight.n} samples; "
              "the wind shared with sensor 1):")
        print(res.summary())


def print_sensor_params(per_sensor, path):
    """Each sensor's recommended parameter (or why none) after the summaries."""
    import sys

    for i, (rec, refused) in enumerate(per_sensor, start=1):
        if rec is None:
            print(f"\nAirspeed sensor {i}: {refused}", file=sys.stderr)
            continue
        print(f"\nAirspeed sensor {i}: recommended {rec.name} = {rec.value:.4f} ± "
              f"{rec.two_sigma:.4f} (2σ)"
              + ("" if rec.current is None else f", now {rec.current:.6g}") + f"; wrote {path}")
        print(f"  {rec.misfit_line()}")
        for note in rec.notes:
            print(f"  note: {note}")
