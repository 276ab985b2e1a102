"""The report's re-run of the fit on the flight the result came from (`report --flight`): the
same reading, air data, noise statements and wind model as the result records, the joint fit
of every airspeed sensor when the result has several, and a warning when it does not
reproduce the result."""

from pitotcal.io import read_flight

__all__ = ["READING_OPTIONS", "refit", "reproduces", "wind_options"]

# The reading options identify records (`reading`) that `read_flight` takes again
READING_OPTIONS = ("start_s", "end_s", "oat_k", "temp_recovery", "rh_pct", "oat_ground_k")


def refit(result, flight_path, flight_options=None):
    """(flight, IdentificationResult): the flight at `flight_path` read as the result's
    `reading` says (overridden by `flight_options` not None) and fitted as the result was; with
    several sensors in the result, all of them jointly (the first sensor's result returned, as
    the record's top level is)."""
    from ..identification.identify import identify
    from ..identification.multi_sensor import identify_sensors

    opts = {k: v for src in (result.get("reading") or {}, flight_options or {})
            for k, v in src.items() if v is not None and k in READING_OPTIONS}
    if result.get("windows") and opts.get("start_s") is None and opts.get("end_s") is None:
        opts["windows"] = "auto"        # the windows identify chose from the log, again
    flight = read_flight(flight_path, **opts)
    stated = result.get("gps_error") or {}
    common = {"model": result.get("model", "inverse"),
              "air": result.get("air_data", "incompressible"),
              "gps_noise_std_mps": result.get("gps_noise_std_mps"), **wind_options(result)}
    others = _other_sensors(result, flight_path, flight)
    if others:
        return flight, identify_sensors([flight, *others], **common)[0]
    return flight, identify(flight, gps_error_sigma_mps=stated.get("sigma_mps"),
                            gps_error_tau_s=stated.get("tau_s"),
                            probe_arm_m=(result.get("reading") or {}).get("probe_arm_m") or 0.0,
                            **common)


def _other_sensors(result, flight_path, flight):
    """The further sensors' flights when the result was a joint fit of several, else []."""
    if len(result.get("sensors") or []) < 2:
        return []
    from pitotcal.io.sensors import other_sensor_flights

    return other_sensor_flights(flight_path, flight)


def wind_options(result):
    """identify's `wind` and `wind_knot_s` that refit the result's wind model: a drifting wind
    with its knots; a constant wind (one per window with several) as it was; {} for a record
    without a wind model (the default, as identify had then)."""
    kind = (result.get("wind_model") or {}).get("kind")
    if kind == "drifting":
        return {"wind": "drifting", "wind_knot_s": result["wind_model"].get("knot_s")}
    return {"wind": "constant"} if kind in ("constant", "constant per window") else {}


def reproduces(result, ident):
    """A warning when the fit re-run on the given flight is not the result's."""
    out = []
    for name, entry in (result.get("parameters") or {}).items():
        if name not in ident.param_names or not isinstance(entry, dict):
            continue
        value, std = entry.get("value"), entry.get("std")
        if value is None or not std:
            continue
        if abs(ident.value(name) - value) > 0.1 * std:
            out.append(f"the flight given does not reproduce the result ({name} "
                       f"{ident.value(name):.5g} vs {value:.5g}): the figures of the fit are "
                       "of the flight as read, check window, OAT and file")
            break
    return out
