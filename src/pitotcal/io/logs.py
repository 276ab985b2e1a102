"""Autopilot flight logs as a `Flight`: PX4 ULog (`.ulg`), ArduPilot DataFlash (`.bin`, `.log`)
and MAVLink telemetry logs (`.tlog`, `pitotcal.io.tlog`).

`read_log(path)` returns the `Flight` that `identify` needs; `load_log(path)` returns it inside a
`FlightLog` with what the autopilot itself estimated (its wind, its airspeed ratio or scale) for
comparison. The format readers (`pitotcal.io.ulog`, `pitotcal.io.dataflash`) only pull the raw
streams out of a file; this module puts them on one time base (`pitotcal.io.timebase`) and
cuts what is unusable, the same way for every format. Every warning the reader gives is also
kept in `Flight.warnings`.

Time
    ``time_s`` is seconds since the start of the log (the ULog header's timestamp; the first
    data message's time-stamp in a DataFlash log), so `start_s` / `end_s` and the times in the
    messages are the numbers a log viewer shows, less the offset of the first message.

One time base
    The samples are those of the pressure stream (ArduPilot ARSP ~10 Hz, PX4
    differential_pressure 10-100 Hz): q_ci is the measured output of the output-error model,
    so its samples are kept as measured, never interpolated. The slower streams are carried onto
    those times by linear interpolation between their two neighbouring samples (the default):
    GPS velocity at 5-10 Hz held instead (zero-order hold, ``gps_resample="hold"``) lags by half
    a GPS period on average, which during the speed sweep and turns is a systematic velocity
    error, while interpolation between two fixes of a smooth flight path is unbiased. The
    analysis is post-flight, so using the next fix is legitimate. A pressure sample is given GPS
    data only when both neighbouring valid fixes are at most ``max(0.5 s, 3 GPS periods)``
    apart, so an interpolation never bridges a fix-lost gap. Static pressure and temperature
    change slowly and are interpolated the same way (held at the ends for up to 1 s).
    `gps_latency_s` shifts the GPS times earlier when the receiver's velocity is known to lag.

What is cut (an INFO log line names every cut with its sample count and time spans)
    - outside the `start_s`..`end_s` window (not counted as dropped);
    - on the ground by the autopilot's own state (ArduPilot ``STAT.isFlying``/``Armed``, PX4
      ``vehicle_land_detected.landed``/``vehicle_status.arming_state``), and the take-off and
      landing ends of each flying span below the autopilot's minimum airspeed parameter
      (`min_airspeed_mps`; see `pitotcal.io.airborne`);
    - no valid GPS: before the first / after the last 3D fix, fix lost (PX4 ``fix_type < 3``
      or ``vel_ned_valid == 0``, ArduPilot ``Status < 3``) or a gap between fixes;
    - on the ground or too slow to calibrate: GPS ground speed below `min_groundspeed_mps`
      (5 m/s) or q_ci below `min_qci_pa` (20 Pa, ~11 kt; the flight CSV reader's threshold);
    - non-finite values, and repeated time stamps of the pressure stream;
    - with ``windows="auto"`` and no window given: what is not steady flight, and what no
      calibration window holds (`pitotcal.io.windows`).
    Fewer than `MIN_SAMPLES` samples or `MIN_DURATION_S` seconds left is a `FlightDataError`.

Density
    rho = ps / (R T) with the log's static pressure and a temperature from the best source
    the log and the caller have (`pitotcal.io.oat`): `oat_k`, `oat_ground_k` with the standard
    lapse, a logged OAT sensor, else a pressure chip's own temperature with a warning giving
    its distance from ISA and what it does to ΔV (a sensor 15 K warmer than the air gives a
    density 5 % low, which the pressure-error model absorbs into k1). A log without static
    pressure uses the ISA atmosphere at the GPS altitude, with a warning.

The autopilot's own estimates
    Kept out of the `Flight`'s arrays: `FlightLog.autopilot_wind` is the wind-estimate series
    (ArduPilot EKF ``NKF2/XKF2 VWN, VWE``; PX4 ``wind_estimate``), `FlightLog.airspeed_scale`
    the airspeed ratio / scale parameters (ArduPilot ``ARSPD_RATIO``: EAS = sqrt(ratio · Δp); PX4
    ``ASPD_SCALE`` and the estimator's ``tas_scale``). Their summaries, the source, firmware and
    every conversion and cut are also short strings in `Flight.meta`, which `write_flight_csv`
    writes as ``# key: value`` comment lines.
"""

import logging
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np

from pitotcal.core import checks
from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.core.flight import Flight
from pitotcal.core.units import density_kgm3, isa_pressure_pa, wind_polar

from .airborne import airspeed_gate, flight_state_cuts
from .oat import oat_on_times
from .flight_checks import QCI_MIN_FLYING_PA, check_window, implausible_samples, window_text
from .flight_csv import PLAN_NOT_FLIGHT, csv_kind
from .flightlog import AutopilotWind, FlightLog
from .read_once import log_file, naming
from .streams import LOG_EXTENSIONS
from .timebase import apply_cuts, clean, gps_onto, spans
from .windows import choose_windows, steady_cuts, windows_record, windows_text

__all__ = ["LOG_COLUMNS", "AutopilotWind", "FlightLog", "load_log", "read_log"]

# The optional flight columns a log's flight carries (`load_log`): the static pressure and its
# temperature always, the GPS climb rate and altitude when the log records them.
LOG_COLUMNS = ("ps_pa", "oat_k", "gps_vd_mps", "alt_m")

log = logging.getLogger(__name__)

MIN_SAMPLES = 50
MIN_DURATION_S = 10.0
_GPS_RESAMPLE = ("linear", "hold")
WINDOW_CHOICES = ("auto", "all")
_SLOW_HOLD_S = 1.0     # static pressure / temperature may be held this long past their ends


def read_log(path, start_s=None, end_s=None, **options):
    """Read a PX4 ULog or ArduPilot DataFlash log as a `Flight` ready for `identify`.

    Parameters
    ----------
    path : str or Path
        ``.ulg`` (PX4), ``.bin`` or ``.log`` (ArduPilot DataFlash, binary or text), ``.tlog``
        (MAVLink telemetry log).
    start_s, end_s : float, optional
        Window in seconds since the start of the log (either may be None).
    **options
        `gps_resample`, `gps_latency_s`, `min_groundspeed_mps`, `min_qci_pa`, `oat_k`,
        `oat_ground_k`, `min_airspeed_mps`, `windows`: see `load_log`.

    Returns
    -------
    Flight
        Samples on the pressure stream's time base; ``time_s`` in seconds since log start.

    Raises
    ------
    FlightDataError
        Unknown extension, unreadable/truncated/corrupt file, no airspeed data, or too little
        usable airborne data; one line naming the file and the cause.

    Examples
    --------
    >>> flight = read_log("flight.bin", start_s=300, end_s=600)     # doctest: +SKIP
    """
    return load_log(path, start_s, end_s, **options).flight


def load_log(path, start_s=None, end_s=None, *, gps_resample="linear", gps_latency_s=0.0,
             min_groundspeed_mps=5.0, min_qci_pa=QCI_MIN_FLYING_PA, oat_k=None,
             min_airspeed_mps=None, oat_ground_k=None, windows="all"):
    """Read a log as a `FlightLog`: the `Flight` and the autopilot's own estimates.

    Parameters
    ----------
    path : str or Path
        ``.ulg``, ``.bin`` or ``.log``; or ``-`` (standard input), a FIFO or a pipe, read once
        (a log there is known by its name's extension or its first bytes).
    start_s, end_s : float, optional
        Window, seconds since log start.
    gps_resample : {"linear", "hold"}
        GPS onto the pressure times: linear interpolation between the neighbouring fixes, or
        the last fix at or before each sample (never future data).
    gps_latency_s : float
        The GPS velocity refers to this long before its log time stamp, s (>= 0).
    min_groundspeed_mps : float
        Samples with a lower GPS ground speed are cut as on the ground, m/s.
    min_qci_pa : float
        Samples with a lower impact pressure are cut, Pa.
    oat_k : float, optional
        Measured outside air temperature, K, used for density instead of a sensor temperature.
    min_airspeed_mps : float, optional
        The take-off and landing gate, indicated airspeed, m/s (`pitotcal.io.airborne`);
        default the autopilot's minimum airspeed parameter where the log has it; 0: no gate.
    oat_ground_k : float, optional
        The ground temperature at the take-off point, K, carried up the standard lapse
        (`pitotcal.io.oat`); with `oat_k` the latter wins.
    windows : {"all", "auto"}
        "all" (default) keeps every usable sample as one window; "auto", without `start_s`
        and `end_s`, keeps the steady flight and chooses the calibration windows from the log
        (`pitotcal.io.windows`; several windows set `Flight.segment`, and `Flight.reading`
        gets ``windows`` and ``cut_s``), as `pitotcal identify` does. A given window is always
        used as it is.

    Returns
    -------
    FlightLog
    """
    options = _check_options(gps_resample, gps_latency_s, min_groundspeed_mps, min_qci_pa, oat_k,
                             min_airspeed_mps, oat_ground_k, windows)
    start_s, end_s = check_window(start_s, end_s)
    with naming(path), log_file(path, LOG_EXTENSIONS) as file:   # "-" or a FIFO: read once
        streams = _read_streams(Path(file))
    return _assemble(streams, Path(file).name, start_s, end_s, options)


class _Options(NamedTuple):
    gps_resample: str
    gps_latency_s: float
    min_gs: float
    min_q: float
    oat_k: float | None
    min_airspeed: float | None
    oat_ground_k: float | None
    windows: str


def _check_options(gps_resample, gps_latency_s, min_groundspeed_mps, min_qci_pa, oat_k,
                   min_airspeed_mps, oat_ground_k=None, windows="all"):
    """The reader's options, checked (a `PitotcalError` naming the parameter)."""
    if gps_resample not in _GPS_RESAMPLE:
        raise PitotcalError(f"gps_resample {gps_resample!r} is not one of "
                            f"{', '.join(_GPS_RESAMPLE)}", param="gps_resample")
    windows = checks.choice("windows", windows, WINDOW_CHOICES)
    oat_k, oat_ground_k = (_kelvin(name, value) for name, value
                           in (("oat_k", oat_k), ("oat_ground_k", oat_ground_k)))
    if min_airspeed_mps is not None:
        min_airspeed_mps = checks.number("min_airspeed_mps", min_airspeed_mps, 0.0)
    return _Options(gps_resample, checks.number("gps_latency_s", gps_latency_s, 0.0),
                    checks.number("min_groundspeed_mps", min_groundspeed_mps, 0.0),
                    checks.number("min_qci_pa", min_qci_pa, 0.0), oat_k, min_airspeed_mps,
                    oat_ground_k, windows)


def _kelvin(name, value):
    """A temperature option checked as kelvin (None stays None)."""
    if value is None:
        return None
    try:
        return checks.number(name, value, 150.0, 350.0)
    except PitotcalError as exc:
        raise PitotcalError(f"{exc} (an outside air temperature in kelvin)",
                            param=name) from None


def _read_streams(path):
    """The raw `LogStreams` of a log file, by its extension."""
    name, suffix = path.name, path.suffix.lower()
    if suffix not in LOG_EXTENSIONS:
        kind = csv_kind(path) if path.is_file() else None
        if kind == "flight":
            raise FlightDataError(f"{name}: already a flight CSV, nothing to convert: "
                                  "read_flight and pitotcal identify read it as it is")
        if kind == "plan":
            raise FlightDataError(f"{name}: {PLAN_NOT_FLIGHT}")
        raise FlightDataError(f"{name}: unknown log extension {path.suffix!r}; expected "
                              f"{', '.join(LOG_EXTENSIONS)} (or a flight CSV)")
    if not path.is_file():
        raise FlightDataError(f"{name}: no such file")
    if path.stat().st_size == 0:
        raise FlightDataError(f"{name}: empty file")
    if suffix == ".ulg":
        from .ulog import read_ulog_streams
        return read_ulog_streams(path)
    if suffix == ".tlog":
        from .tlog import read_tlog_streams
        return read_tlog_streams(path)
    from .dataflash import read_dataflash_streams
    return read_dataflash_streams(path)


# --- one time base, cuts ------------------------------------------------------------------

def _assemble(s, name, start_s, end_s, opt):
    """The `FlightLog` of raw streams `s`: one time base, the cuts, the checks, the metadata."""
    t, q, n_bad_rows, state = _pressure_in_window(s, name, start_s, end_s, opt.min_airspeed)
    gps = gps_onto(t, s, name, opt.gps_resample, opt.gps_latency_s)
    cuts = {**state, "no valid GPS fix": ~gps.ok}
    rho, static_ok, temp_source, ps, oat = _density(s, t, q, gps.alt, opt)
    if static_ok is not None:
        cuts["no static pressure"] = ~static_ok
    slow = {**state,
            f"ground speed < {opt.min_gs:g} m/s": gps.ok & (np.hypot(gps.vn, gps.ve) < opt.min_gs),
            f"q_ci < {opt.min_q:g} Pa": q < opt.min_q}
    cuts.update(slow)
    cuts["non-finite density"] = ~np.isfinite(rho) | (rho <= 0)
    # a logger glitch (1e200 in a GPS velocity) is cut, never fitted
    cuts["implausible value"], glitch = implausible_samples(
        name, t, qc_pa=q, gps_vn_mps=gps.vn, gps_ve_mps=gps.ve, rho_kgm3=rho,
        gps_vd_mps=gps.vd if s.gps_vd is not None else None)

    auto = opt.windows == "auto" and start_s is None and end_s is None
    if auto:
        cuts.update(steady_cuts(t, q, gps, s, airspeed_gate(s, opt.min_airspeed)[0]))
    keep, excluded, attributed = apply_cuts(name, t, cuts)
    windows = _choose(name, t, keep, gps, excluded, attributed, s) if auto else None
    if n_bad_rows:
        excluded["non-finite or repeated time"] = int(n_bad_rows)
        log.info("%s: dropped %d non-finite or repeated pressure samples", name, n_bad_rows)
    warned = _warn_all(name, s) + ((glitch,) if glitch else ())
    _require_enough(name, t, keep, cuts, slow)

    wind = _autopilot_wind(s, start_s, end_s)
    kt = t[keep]
    excluded_text = "; ".join(
        f"{reason}: {n} samples ({spans(t, attributed[reason], 3)})" if reason in attributed
        else f"{reason}: {n}" for reason, n in excluded.items()) or "none"
    meta = _meta(s, name, kt, (start_s, end_s), temp_source, opt, excluded_text, wind)
    if windows is not None:
        meta["windows"] = windows_text(windows_record(t, windows, attributed)).replace("\n", "; ")
    flight = Flight(time_s=kt, qci_pa=q[keep], gps_vn_mps=gps.vn[keep], gps_ve_mps=gps.ve[keep],
                    rho_kgm3=rho[keep], ps_pa=ps[keep], oat_k=oat[keep],
                    gps_vd_mps=gps.vd[keep] if s.gps_vd is not None else None,
                    alt_m=gps.alt[keep] if s.gps_alt_m is not None else None,
                    source=name, meta=meta, n_dropped=int(t.size - keep.sum() + n_bad_rows),
                    warnings=warned, **_segments(windows, t, keep, attributed))
    log.info("%s: %d samples over %.1f s kept (%s)", name, flight.n, kt[-1] - kt[0], s.autopilot)
    return FlightLog(flight=flight, autopilot=s.autopilot, log_format=s.log_format,
                     autopilot_wind=wind, airspeed_scale=dict(s.airspeed_scale),
                     excluded=excluded, conversions=tuple(s.conversions))


def _choose(name, t, keep, gps, excluded, attributed, s):
    """The calibration windows (`pitotcal.io.windows.choose_windows`): `keep`, `excluded` and
    `attributed` updated in place with what they leave out; the windows, in time order."""
    cuts, windows, fallback = choose_windows(t, keep, gps.vn, gps.ve)
    for reason, mask in cuts.items():
        new = mask & keep
        if new.any():
            excluded[reason], attributed[reason] = int(new.sum()), new
            log.info("%s: cut %d samples for %s (%s)", name, new.sum(), reason, spans(t, new))
            keep &= ~new
    if fallback:
        s.conversions.append(f"no steady window alone is long enough and turns enough: "
                             f"{windows[0]['reason'].split(': ', 1)[1]}; all steady flight "
                             "is fitted as one window")
    for w in windows:
        w["mask"] = w["mask"] & keep
    return windows


def _segments(windows, t, keep, attributed):
    """The Flight's `segment` (several windows) and `reading` (windows, cut_s), or nothing."""
    if windows is None:
        return {}
    reading = windows_record(t, windows, attributed)
    if len(windows) < 2:
        return {"reading": reading}
    segment = np.zeros(t.size, int)
    for i, w in enumerate(windows):
        segment[w["mask"]] = i
    return {"reading": reading, "segment": segment[keep]}


def _pressure_in_window(s, name, start_s, end_s, min_airspeed_mps):
    """(t, q_ci, n_bad, state cuts): the clean pressure samples inside the window, how many
    were not clean, and the autopilot-state cuts (computed over the whole log) on them."""
    t_all, q_all = clean(np.asarray(s.pressure_t, float), np.asarray(s.qci_pa, float))
    n_bad = np.asarray(s.pressure_t).size - t_all.size
    if t_all.size == 0:
        raise FlightDataError(f"{name}: no finite airspeed samples in the log")
    in_win = _inside(t_all, start_s, end_s)
    if not in_win.any():
        raise FlightDataError(f"{name}: no airspeed samples in the window "
                              f"{window_text(start_s, end_s)}; the log's airspeed spans "
                              f"{t_all[0]:.1f}-{t_all[-1]:.1f} s since log start")
    state = flight_state_cuts(s, t_all, q_all, min_airspeed_mps)
    return (t_all[in_win], q_all[in_win], n_bad,
            {reason: mask[in_win] for reason, mask in state.items()})


def _inside(t, start_s, end_s):
    lo = -np.inf if start_s is None else start_s
    hi = np.inf if end_s is None else end_s
    return (t >= lo) & (t <= hi)


def _density(s, t, q, alt, opt):
    """(rho, static_ok or None, temperature source, ps, T): ps / (R T) on the times `t`.

    ps (the static source's pressure) and T (`pitotcal.io.oat`) also go into the Flight for
    the compressible calibration, with the same substitutions as the density.

    Records every substitution in `s.conversions` (warned later).
    """
    static_ok, ts = None, np.empty(0)
    if s.ps_pa is not None and s.static_t is not None:
        ts, ps_s = clean(np.asarray(s.static_t, float), np.asarray(s.ps_pa, float))
    if ts.size >= 2:            # finite samples to interpolate between
        ps = np.interp(t, ts, ps_s)
        static_ok = (t >= ts[0] - _SLOW_HOLD_S) & (t <= ts[-1] + _SLOW_HOLD_S)
    else:
        ps = isa_pressure_pa(alt)
        s.static_source = "ISA at GPS altitude (no static pressure in the log)"
        s.conversions.append("no static pressure in the log: ISA pressure at the GPS altitude")
    temp, temp_source = oat_on_times(s, t, q, ps, alt, opt.oat_k, opt.oat_ground_k)
    return density_kgm3(ps, temp), static_ok, temp_source, ps, temp


def _warn_all(name, s):
    """Warn each conversion; every warning about the log (the format reader's too), as a tuple."""
    texts = [f"{name}: {text}" for text in s.conversions]
    for text in texts:
        warnings.warn(text, stacklevel=4)
    return tuple(s.warnings) + tuple(texts)


def _require_enough(name, t, keep, cuts, slow):
    """A `FlightDataError` when fewer than MIN_SAMPLES or MIN_DURATION_S are left."""
    n_keep = int(keep.sum())
    duration = float(t[keep][-1] - t[keep][0]) if n_keep else 0.0
    if n_keep >= MIN_SAMPLES and duration >= MIN_DURATION_S:
        return
    why = "; ".join(f"{reason}: {int(m.sum())}" for reason, m in cuts.items()
                    if m.any()) or "none"
    on_ground = np.logical_or.reduce(list(slow.values()))
    ground = " (on the ground throughout?)" if on_ground.mean() > 0.9 else ""
    raise FlightDataError(
        f"{name}: too little usable airborne data{ground} ({n_keep} samples over "
        f"{duration:.1f} s, need {MIN_SAMPLES} over {MIN_DURATION_S:g} s) of {t.size} airspeed "
        f"samples in {t[0]:.1f}-{t[-1]:.1f} s; failing: {why}")


def _autopilot_wind(s, start_s, end_s):
    """The autopilot's wind estimate inside the window, or None when the log has none."""
    if s.wind_t is None or not s.wind_t.size:
        return None
    w = _inside(s.wind_t, start_s, end_s)
    return AutopilotWind(np.asarray(s.wind_t[w], float), np.asarray(s.wind_n[w], float),
                         np.asarray(s.wind_e[w], float), s.wind_source)


def _meta(s, name, kt, window, temp_source, opt, excluded_text, wind):
    """The `Flight.meta` strings: source, firmware, window, every source, conversion and cut."""
    (start_s, end_s), (gps_resample, gps_latency_s) = window, opt[:2]
    asked = "" if start_s is None and end_s is None else f" (asked {start_s}-{end_s})"
    meta = {
        "source": name,
        "log_format": s.log_format,
        "autopilot": s.autopilot,
        "time": "seconds since log start; samples at the pressure stream's times",
        "window_s": f"{kt[0]:.1f}-{kt[-1]:.1f}{asked}",
        "qc_source": s.pressure_source,
        "static_source": s.static_source,
        "temperature_source": temp_source,
        "gps_source": f"{s.gps_source}, {gps_resample} onto the pressure times"
                      + (f", latency {gps_latency_s:g} s" if gps_latency_s else ""),
    }
    if s.airborne_source:
        meta["flight_state_source"] = s.airborne_source
    gate, gate_source = airspeed_gate(s, opt.min_airspeed)
    if gate:
        meta["min_airspeed_mps"] = f"{gate:g} ({gate_source}): take-off and landing gate"
    meta["excluded"] = excluded_text
    if s.other_sensors:      # the others are read by pitotcal.io.sensors
        meta["airspeed_sensors"] = "; ".join([s.pressure_source]
                                             + [src for _, _, src in s.other_sensors])
    for key, value in s.airspeed_scale.items():
        meta[f"autopilot_{key}"] = f"{value:.6g}"
    if wind is not None and wind.time_s.size:
        inside = (wind.time_s >= kt[0]) & (wind.time_s <= kt[-1])
        if inside.any():
            wn, we = wind.wind_n_mps[inside].mean(), wind.wind_e_mps[inside].mean()
            meta["autopilot_wind"] = (f"{wind.source}, mean {np.hypot(wn, we):.2f} m/s from "
                                      f"{wind_polar(wn, we)[1]:.0f} deg")
    return meta
