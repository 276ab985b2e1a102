"""The options of `simulate` (maneuvers.fly.simulator), checked before any work.

Every number goes through pitotcal.core.checks, so an error names the parameter (and the
command line its flag); the mean wind defaults to the plan's settings; the record's size is
checked against MAX_SAMPLES and the GPS latency against the plan's length.
"""

from dataclasses import asdict, dataclass

import numpy as np

from pitotcal.core.measurement import AIR_DATA_MODES, DEFAULT_AIR_DATA
from pitotcal.core.checks import choice, exact, number, positive, round_to_limit
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model
from pitotcal.core.plan import Plan
from pitotcal.core.scenario import T2_PLAN, true_k

__all__ = ["MAX_SAMPLES", "MIN_SAMPLES", "SIM_LIMITS", "AirSensors", "SimOptions", "air_sensors",
           "check_plan", "sim_options"]

# Memory grows with the samples (~1.5 kB each in the scalar loop, measured: 1.5 GB peak and
# 13 s for 10^6): 500,000 is 2.8 h at 50 Hz, or 42 min at 200 Hz.
MAX_SAMPLES = 500_000
MIN_SAMPLES = 10          # the flight CSV reader's MIN_ROWS: fewer is no flight

# Issue 15: upper bounds of the options, with the reason given when one is refused (the
# simulator would run, overflow or fill memory beyond them; nothing real lies there).
# rate_hz is bounded by MAX_SAMPLES over the plan, gps_latency_s by the plan's length.
SIM_LIMITS = {
    "wind_speed_mps": (50.0, "nobody flies a calibration in a wind above 97 kt"),
    "wind_drift_mps2": (0.1, "6 m/s a minute is a gust front, not a drift"),
    "turbulence_mps": (10.0, "MIL-F-8785C's severe turbulence is 3-7 m/s RMS"),
    "turbulence_length_m": (10000.0, "MIL-F-8785C's longest scale length is 533 m"),
    "qc_noise_pa": (100.0, "100 Pa RMS is 4 kt at 70 kt: no airspeed sensor"),
    "qc_quantization_pa": (100.0, "100 Pa steps are 4 kt at 70 kt: no airspeed sensor"),
    "qc_bias_pa": (1000.0, "a 1000 Pa offset is 35 kt at 70 kt: no airspeed sensor"),
    "qc_scale_error": (0.5, "a gain error beyond 50 % is a broken sensor"),
    "pneumatic_lag_s": (5.0, "pitot tubing lags 0.01-0.5 s; seconds is a blocked line"),
    "gps_rate_hz": (100.0, "GNSS receivers update at 1-50 Hz"),
    "gps_noise_mps": (10.0, "receivers report 0.02-0.5 m/s RMS"),
    "gps_gm_sigma_mps": (5.0, "a receiver's slowly drifting velocity error is cm/s to dm/s"),
}


def _flag(name, value):
    """A yes/no option: a bool (numpy's included), else PitotcalError naming it."""
    if not isinstance(value, (bool, np.bool_)):
        raise PitotcalError(f"{name} must be true or false, got {value!r}", param=name)
    return bool(value)


def _limited(name, value, lo=0.0, *, lo_open=False, key=None):
    """`checks.number` with the `SIM_LIMITS` bound (on |value| when `lo` is None), the reason
    added to the message."""
    hi, why = SIM_LIMITS[key or name]
    try:
        return number(name, value, -hi if lo is None else lo, hi, lo_open=lo_open)
    except PitotcalError as exc:
        if "<=" in str(exc):
            raise PitotcalError(f"{exc} ({why})", param=name) from None
        raise


_PLAN_COLUMNS_FLOWN = ("north_m", "east_m", "alt_m", "heading_deg", "bank_deg", "tas_mps",
                       "cas_mps")


@dataclass(frozen=True)
class SimOptions:
    """The checked options of one simulation (the `options` of its `Truth`), SI."""

    model: str
    k: tuple
    wind_speed_mps: float
    wind_from_deg: float
    wind_drift_mps2: tuple
    turbulence_mps: float
    turbulence_length_m: float | None
    rate_hz: float
    qc_noise_pa: float
    qc_quantization_pa: float
    qc_bias_pa: float
    qc_scale_error: float
    pneumatic_lag_s: float
    gps_rate_hz: float
    gps_noise_mps: float
    gps_latency_s: float
    air_data: str = DEFAULT_AIR_DATA
    air_sensors: "AirSensors | None" = None
    # Gauss-Markov GPS velocity error (issue 11): steady-state sigma (m/s; 0 none), tau (s)
    gps_gm_sigma_mps: float = 0.0
    gps_gm_tau_s: float = 30.0
    # Dryden's vertical gust flown (issue 11): plunge, altitude, GPS climb and V_t
    vertical_gusts: bool = False

    def to_dict(self):
        """As written in the truth JSON (sequences as lists; `air_sensors` only when set)."""
        out = asdict(self)
        out["k"], out["wind_drift_mps2"] = list(self.k), list(self.wind_drift_mps2)
        if self.air_sensors is None:
            del out["air_sensors"]                 # the default's truth JSON stays as it was
        else:
            out["air_sensors"]["gps_bias_mps"] = list(self.air_sensors.gps_bias_mps)
        if not self.gps_gm_sigma_mps:       # without it, the truth JSON stays as it was
            del out["gps_gm_sigma_mps"], out["gps_gm_tau_s"]
        if not self.vertical_gusts:         # likewise
            del out["vertical_gusts"]
        return out


@dataclass(frozen=True)
class AirSensors:
    """Air-data sensors and effects of the issue 9 budget (maneuvers.fly.sensors.air_records).

    Attributes
    ----------
    tat_recovery : float or None
        A total-temperature probe with this recovery factor logs `tat_k` = T_s (1 + r 0.2 M²)
        instead of a static `oat_k`; None: a static OAT sensor.
    rh_pct : float
        Relative humidity of the air mass, %: the true density and speed of sound use the
        virtual temperature; logged as `rh_pct` when > 0.
    probe_arm_m : float
        Lateral position of the pitot probe, m (right wing +): in a turn at yaw rate r it sees
        V_t − r y (ω × r), and q_c follows.
    oat_bias_k : float
        Bias of the logged temperature (static or total), K.
    gps_bias_mps : (float, float, float)
        Constant bias of the GPS velocity north, east, down, m/s.
    """

    tat_recovery: float | None = None
    rh_pct: float = 0.0
    probe_arm_m: float = 0.0
    oat_bias_k: float = 0.0
    gps_bias_mps: tuple = (0.0, 0.0, 0.0)


def air_sensors(tat_recovery=None, rh_pct=0.0, probe_arm_m=0.0, oat_bias_k=0.0,
                gps_bias_mps=(0.0, 0.0, 0.0)):
    """Checked `AirSensors` (each value named like its parameter and flag)."""
    if len(gps_bias_mps) != 3:
        raise PitotcalError(f"gps_bias_mps must be (north, east, down), got {gps_bias_mps!r}",
                            param="gps_bias_mps")
    return AirSensors(
        tat_recovery=(None if tat_recovery is None
                      else number("tat_recovery", tat_recovery, 0.0, 1.0)),
        rh_pct=number("rh_percent", rh_pct, 0.0, 100.0),
        probe_arm_m=number("probe_arm_m", probe_arm_m, -50.0, 50.0),
        oat_bias_k=number("oat_bias_k", oat_bias_k, -50.0, 50.0),
        gps_bias_mps=tuple(number("gps_bias_mps", v, -10.0, 10.0) for v in gps_bias_mps))



def _checked_air_sensors(value):
    """None, an `AirSensors` (checked again), or a dict of `air_sensors` arguments."""
    if value is None:
        return None
    if isinstance(value, AirSensors):
        value = asdict(value)
    if not isinstance(value, dict):
        raise PitotcalError(f"air_sensors must be an AirSensors or a dict, got {value!r}",
                            param="air_sensors")
    return air_sensors(**value)


def check_plan(plan):
    """A `Plan` the simulator can fly: >= 2 rows, time increasing, finite, airspeeds > 0."""
    if not isinstance(plan, Plan):
        raise PitotcalError(f"plan must be a pitotcal.core.plan.Plan (pitotcal.read_plan reads "
                            f"one), got {type(plan).__name__}")
    if plan.n < 2 or not np.all(np.diff(plan.time_s) > 0):
        raise PitotcalError("plan must have >= 2 rows with strictly increasing time_s")
    for name in _PLAN_COLUMNS_FLOWN:
        if not np.all(np.isfinite(plan.column(name))):
            raise PitotcalError(f"plan column {name} has a non-finite value")
    if np.any(plan.tas_mps <= 0) or np.any(plan.cas_mps <= 0):
        raise PitotcalError("plan airspeeds must be > 0")


# Issue 15: the largest pressure error simulated, |dp/q_c| (beyond it the sensor would read
# zero or negative impact pressure: no pitot-static system).
MAX_PRESSURE_ERROR = 0.5


def _check_pressure_error(opts, plan):
    """The true coefficients keep |dp/q_c| <= MAX_PRESSURE_ERROR over the plan's q_c."""
    model = get_model(opts.model)
    qc = np.asarray(plan.qc_pa, dtype=float)
    qc = qc[np.isfinite(qc) & (qc > 0)]
    with np.errstate(all="ignore"):
        ratio = np.asarray(model(opts.k, qc), dtype=float)
    worst = float(np.max(np.abs(ratio))) if ratio.size else 0.0
    if not worst <= MAX_PRESSURE_ERROR:
        names = ", ".join(f"{n} {v:g}" for n, v in zip(model.params, opts.k))
        raise PitotcalError(
            f"{names}: the {model.name} pressure error dp/qc reaches {worst:.3g} on the "
            f"plan's q_c {qc.min():.0f}-{qc.max():.0f} Pa; at most {MAX_PRESSURE_ERROR:g} "
            "(beyond it the sensor reads no impact pressure)", param=model.params[0],
            mentions=model.params[1:])


def _check_samples(rate_hz, span_s):
    """At least `MIN_SAMPLES` and at most `MAX_SAMPLES` over the plan; the rate suggested is
    computed from those limits and passes them."""
    samples = span_s * rate_hz + 1
    if MIN_SAMPLES <= samples <= MAX_SAMPLES:
        return
    lo = round_to_limit((MIN_SAMPLES - 1) / span_s, lo=True)
    hi = (MAX_SAMPLES - 1) / span_s
    hi = float(np.floor(hi)) if hi >= 100 else round_to_limit(hi, lo=False)
    if samples > MAX_SAMPLES:
        raise PitotcalError(
            f"rate_hz {exact(rate_hz)} gives {samples:.3g} samples over the plan's {span_s:g} "
            f"s; the simulator records at most {MAX_SAMPLES:,}: use at most {exact(hi)} Hz",
            param="rate_hz")
    raise PitotcalError(
        f"rate_hz {exact(rate_hz)} gives {samples:.3g} samples over the plan's {span_s:g} s; "
        f"a flight needs at least {MIN_SAMPLES}: use at least {exact(lo)} Hz", param="rate_hz")


def _true_k(model, k):
    pe_model = get_model(model)
    if k is None:
        k = true_k(model)
    try:
        k = tuple(number(f"k{i + 1}", v) for i, v in enumerate(k))
    except TypeError:
        raise PitotcalError(f"k must be a sequence of numbers, got {k!r}", param="k") from None
    if len(k) < len(pe_model.params):
        raise PitotcalError(f"k needs {len(pe_model.params)} coefficients for model "
                            f"{model!r}, got {len(k)}", param="k")
    return k[:len(pe_model.params)]


def sim_options(plan, model, k, wind_speed_mps, wind_from_deg, wind_drift_mps2, turbulence_mps,
             turbulence_length_m, rate_hz, qc_noise_pa, qc_quantization_pa, qc_bias_pa,
             qc_scale_error, pneumatic_lag_s, gps_rate_hz, gps_noise_mps, gps_latency_s,
             air_data=DEFAULT_AIR_DATA, sensors=None, gps_gm_sigma_mps=0.0, gps_gm_tau_s=30.0,
             vertical_gusts=False):
    """`SimOptions` from `simulate`'s arguments (see there): each checked, naming the parameter,
    the wind's defaults filled from the plan's settings, sizes checked against the plan."""
    settings = plan.settings or {}
    if wind_speed_mps is None:
        wind_speed_mps = settings.get("wind_speed_mps", 0.0)
    if wind_from_deg is None:
        wind_from_deg = settings.get("wind_from_deg", T2_PLAN["wind_from_deg"])
    if len(wind_drift_mps2) != 2:
        raise PitotcalError(f"wind_drift_mps2 must be (north, east), got {wind_drift_mps2!r}",
                            param="wind_drift_mps2")
    opts = SimOptions(
        model=model, k=_true_k(model, k),
        wind_speed_mps=_limited("wind_speed_mps", wind_speed_mps),
        wind_from_deg=number("wind_from_deg", wind_from_deg, 0.0, 360.0, hi_open=True),
        # each component named like its command-line flag
        wind_drift_mps2=tuple(_limited(f"wind_drift_{axis}_mps2", v, None,
                                       key="wind_drift_mps2")
                              for axis, v in zip("ne", wind_drift_mps2)),
        turbulence_mps=_limited("turbulence_mps", turbulence_mps),
        turbulence_length_m=(None if turbulence_length_m is None
                             else _limited("turbulence_length_m", turbulence_length_m,
                                           lo_open=True)),
        rate_hz=number("rate_hz", rate_hz, 0.0, lo_open=True),   # bounded by MAX_SAMPLES
        qc_noise_pa=_limited("qc_noise_pa", qc_noise_pa),
        qc_quantization_pa=_limited("qc_quantization_pa", qc_quantization_pa),
        qc_bias_pa=_limited("qc_bias_pa", qc_bias_pa, None),
        qc_scale_error=_limited("qc_scale_error", qc_scale_error, -0.5),
        pneumatic_lag_s=_limited("pneumatic_lag_s", pneumatic_lag_s),
        gps_rate_hz=_limited("gps_rate_hz", gps_rate_hz or 0.0),
        gps_noise_mps=_limited("gps_noise_mps", gps_noise_mps),
        gps_latency_s=number("gps_latency_s", gps_latency_s, 0.0),   # bounded by the plan
        air_data=choice("air_data", air_data, AIR_DATA_MODES),
        air_sensors=_checked_air_sensors(sensors),
        gps_gm_sigma_mps=_limited("gps_gm_sigma_mps", gps_gm_sigma_mps),
        gps_gm_tau_s=positive("gps_gm_tau_s", gps_gm_tau_s),
        # recorded as flown: no turbulence, no vertical gust (turbulence_mps checked above)
        vertical_gusts=_flag("vertical_gusts", vertical_gusts) and float(turbulence_mps) > 0)
    span_s = float(plan.time_s[-1] - plan.time_s[0])
    _check_samples(opts.rate_hz, span_s)
    _check_pressure_error(opts, plan)
    if opts.gps_latency_s >= span_s:
        raise PitotcalError(f"gps_latency_s {opts.gps_latency_s:g} must be shorter than the "
                            f"plan's {span_s:g} s (typical receivers: 0-0.5 s)",
                            param="gps_latency_s")
    return opts
