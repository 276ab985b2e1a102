"""The options of `simulate` (maneuvers.fly.simulator): `SimulationOptions`, checked before any
work.

Every field is checked when the object is made, through pitotcal.core.checks, so an error names
the field (and the command line its flag); `SimulationOptions.resolved` fills in the mean wind
from the plan's settings and checks the record's size against MAX_SAMPLES, the GPS latency
against the plan's length and the pressure error over its q_c.
"""

from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from pitotcal.core.checks import choice, number, positive, with_overrides
from pitotcal.core.dynamics import Limits
from pitotcal.core.errors import PitotcalError
from pitotcal.core.geo import check_lat_lon
from pitotcal.core.measurement import AIR_DATA_MODES, DEFAULT_AIR_DATA
from pitotcal.core.models import MODELS, get_model
from pitotcal.core.scenario import GPS_NOISE_MAX_MPS, T2_PLAN, true_k

from .flyable import MAX_SAMPLES, MIN_SAMPLES, check_plan, check_pressure_error, check_samples

__all__ = ["ENGINES", "ENGINE_AIR_DATA", "MAX_SAMPLES", "MIN_SAMPLES", "SIM_LIMITS", "AirSensors",
           "SimOptions", "SimulationOptions", "air_sensors", "check_plan", "simulation_options"]

# Upper bounds of the options, with the reason given when one is refused (the
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
    "gps_noise_mps": (GPS_NOISE_MAX_MPS, "receivers report 0.02-0.5 m/s RMS"),
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


@dataclass(frozen=True)
class SimulationOptions:
    """The options of one simulation (`simulate(plan, options)`): each field checked when the
    object is made, a `PitotcalError` naming the field (the command line shows its flag).

    Fields left at None take their value from the plan or the model when the plan is flown
    (`resolved`); the resolved options are the `options` of the flight's `Truth`.

    Attributes
    ----------
    model : str
        True pressure-error structure (pitotcal.core.models.MODELS); ``--model``.
    k : sequence of float, dict or None
        Its true coefficients (the first as many as the model has are used), or a dict of some
        of them by name (``{"k2": -20.0}``; the others the model's defaults); None: all
        `pitotcal.core.scenario.true_k(model)` (k1 = 0.02, k2 = -15 Pa for inverse); ``--k1``,
        ``--k2``.
    wind_speed_mps, wind_from_deg : float or None
        Mean wind (FROM, deg true, in [0, 360)); None: the plan's settings (else calm).
    wind_drift_mps2 : (float, float)
        Linear drift of the air-mass velocity (north, east), m/s², about the record's middle;
        ``--wind-drift-n-mps2``, ``--wind-drift-e-mps2``.
    turbulence_mps, turbulence_length_m : float, float or None
        RMS of the horizontal Dryden gusts, m/s (0: none); their scale length (None:
        MIL-F-8785C's at the plan's altitude; own engine only).
    rate_hz : float
        Sample rate, Hz (the dynamics step at `DYNAMICS_RATE_HZ` or faster whatever it is).
    qc_noise_pa, qc_quantization_pa, qc_bias_pa, qc_scale_error, pneumatic_lag_s : float
        Impact-pressure transducer: white noise std (Pa), converter step (Pa), zero offset (Pa),
        relative gain error, first-order tubing lag (s).
    gps_rate_hz, gps_noise_mps, gps_latency_s : float
        GPS velocity: update rate (Hz; 0 = every sample), white noise std per component and
        update (m/s), age of the reported velocity (s).
    air_data : {"incompressible", "compressible"} or None
        True impact pressure: ½ρV_t² (the paper's eq. 2) or isentropic with the ISA p_s and T;
        None: the engine's own (for "own" the shared default `DEFAULT_AIR_DATA`, which
        `identify` fits; "jsbsim" has only compressible).
    air_sensors : AirSensors, dict or None
        Temperature, humidity, probe-arm and GPS-bias effects (own engine only).
    gps_gm_sigma_mps, gps_gm_tau_s : float
        Gauss-Markov GPS velocity error on top of the white: std (m/s; 0 none), tau (s).
    vertical_gusts : bool
        Fly Dryden's vertical gust too (recorded as flown: False without turbulence).
    engine : {"own", "jsbsim"}
        pitotcal's point-mass model, or JSBSim's six-degree-of-freedom one
        (maneuvers.fly.jsbsim_flight); ``--engine``.
    aircraft : str or None
        JSBSim aircraft (None: c172x); engine "jsbsim" only; ``--aircraft``.
    center_deg : (float, float) or None
        Where JSBSim flies the test area (lat, lon; None: the plan's centre, else a default);
        engine "jsbsim" only.
    limits : pitotcal.core.dynamics.Limits or None
        Guidance limits (None: Limits with the plan's bank_max_deg).
    speed_loop : maneuvers.plan.autothrottle.SpeedLoop or None
        Own engine's auto-throttle (None: tuned at the plan's mid-range true airspeed).
    keep_history : bool
        Also keep the true time histories in ``truth.history`` (not written to the truth JSON).
    """

    model: str = "inverse"
    k: tuple | dict | None = None
    wind_speed_mps: float | None = None
    wind_from_deg: float | None = None
    wind_drift_mps2: tuple = (0.0, 0.0)
    turbulence_mps: float = 0.5
    turbulence_length_m: float | None = None
    rate_hz: float = 50.0
    qc_noise_pa: float = 0.5
    qc_quantization_pa: float = 0.0
    qc_bias_pa: float = 0.0
    qc_scale_error: float = 0.0
    pneumatic_lag_s: float = 0.0
    gps_rate_hz: float = 5.0
    gps_noise_mps: float = 0.05
    gps_latency_s: float = 0.0
    air_data: str | None = None
    air_sensors: "AirSensors | None" = None
    gps_gm_sigma_mps: float = 0.0
    gps_gm_tau_s: float = 30.0
    vertical_gusts: bool = False
    engine: str = "own"
    aircraft: str | None = None
    center_deg: tuple | None = None
    limits: object = None
    speed_loop: object = None
    keep_history: bool = False

    def __post_init__(self):
        for name, value in _checked_fields(self).items():
            object.__setattr__(self, name, value)

    def resolved(self, plan):
        """These options for flying `plan`: the wind from its settings, the coefficients and
        air data filled in, the sizes checked against it (the record's samples, the GPS
        latency, the pressure error over its q_c)."""
        settings = plan.settings or {}
        opts = replace(
            self,
            k=_true_k(self.model, self.k),
            wind_speed_mps=(settings.get("wind_speed_mps", 0.0) if self.wind_speed_mps is None
                            else self.wind_speed_mps),
            wind_from_deg=(settings.get("wind_from_deg", T2_PLAN["wind_from_deg"])
                           if self.wind_from_deg is None else self.wind_from_deg),
            air_data=self.air_data or ENGINE_AIR_DATA[self.engine],
            vertical_gusts=self.vertical_gusts and self.turbulence_mps > 0)
        span_s = float(plan.time_s[-1] - plan.time_s[0])
        check_samples(opts.rate_hz, span_s)
        check_pressure_error(opts, plan)
        if opts.gps_latency_s >= span_s:
            raise PitotcalError(f"gps_latency_s {opts.gps_latency_s:g} must be shorter than the "
                                f"plan's {span_s:g} s (typical receivers: 0-0.5 s)",
                                param="gps_latency_s")
        return opts

    def to_dict(self):
        """As written in the truth JSON, of resolved options (sequences as lists; the engine's
        and the run's own fields left to the engine; `air_sensors`, the Gauss-Markov error and
        vertical gusts only when set, so the default's truth JSON keeps its keys)."""
        out = {f.name: getattr(self, f.name) for f in fields(self) if f.name not in _RUN_FIELDS}
        out["k"], out["wind_drift_mps2"] = list(self.k), list(self.wind_drift_mps2)
        if self.air_sensors is None:
            del out["air_sensors"]
        else:
            out["air_sensors"] = {**asdict(self.air_sensors),
                                  "gps_bias_mps": list(self.air_sensors.gps_bias_mps)}
        if not self.gps_gm_sigma_mps:
            del out["gps_gm_sigma_mps"], out["gps_gm_tau_s"]
        if not self.vertical_gusts:
            del out["vertical_gusts"]
        return out


# The name the simulator's internals and older code use for the same object.
SimOptions = SimulationOptions

ENGINES = ("own", "jsbsim")
# The true impact pressure each engine flies when `air_data` is None.
ENGINE_AIR_DATA = {"own": DEFAULT_AIR_DATA, "jsbsim": "compressible"}
# Fields that say how to run, not what the sensors record: not in the truth's `options`
# (the JSBSim engine adds `engine`, `aircraft` and `center_deg` itself).
_RUN_FIELDS = ("engine", "aircraft", "center_deg", "limits", "speed_loop", "keep_history")


@dataclass(frozen=True)
class AirSensors:
    """Air-data sensors and the effects the uncertainty budget counts (sensors.air_records).

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


def _checked_fields(o):
    """{field: checked value} of `SimulationOptions` `o` (PitotcalError naming the field)."""
    choice("model", o.model, tuple(MODELS))
    if not isinstance(o.wind_drift_mps2, (tuple, list, np.ndarray)) or len(o.wind_drift_mps2) != 2:
        raise PitotcalError(f"wind_drift_mps2 must be (north, east), got {o.wind_drift_mps2!r}",
                            param="wind_drift_mps2")
    out = dict(
        k=_checked_k(o.model, o.k),
        wind_speed_mps=(None if o.wind_speed_mps is None
                        else _limited("wind_speed_mps", o.wind_speed_mps)),
        wind_from_deg=(None if o.wind_from_deg is None
                       else number("wind_from_deg", o.wind_from_deg, 0.0, 360.0, hi_open=True)),
        # each component named like its command-line flag
        wind_drift_mps2=tuple(_limited(f"wind_drift_{axis}_mps2", v, None, key="wind_drift_mps2")
                              for axis, v in zip("ne", o.wind_drift_mps2)),
        turbulence_mps=_limited("turbulence_mps", o.turbulence_mps),
        turbulence_length_m=(None if o.turbulence_length_m is None
                             else _limited("turbulence_length_m", o.turbulence_length_m,
                                           lo_open=True)),
        rate_hz=number("rate_hz", o.rate_hz, 0.0, lo_open=True),   # bounded by MAX_SAMPLES
        qc_noise_pa=_limited("qc_noise_pa", o.qc_noise_pa),
        qc_quantization_pa=_limited("qc_quantization_pa", o.qc_quantization_pa),
        qc_bias_pa=_limited("qc_bias_pa", o.qc_bias_pa, None),
        qc_scale_error=_limited("qc_scale_error", o.qc_scale_error, -0.5),
        pneumatic_lag_s=_limited("pneumatic_lag_s", o.pneumatic_lag_s),
        gps_rate_hz=_limited("gps_rate_hz", o.gps_rate_hz or 0.0),
        gps_noise_mps=_limited("gps_noise_mps", o.gps_noise_mps),
        gps_latency_s=number("gps_latency_s", o.gps_latency_s, 0.0),   # bounded by the plan
        air_data=None if o.air_data is None else choice("air_data", o.air_data, AIR_DATA_MODES),
        air_sensors=_checked_air_sensors(o.air_sensors),
        gps_gm_sigma_mps=_limited("gps_gm_sigma_mps", o.gps_gm_sigma_mps),
        gps_gm_tau_s=positive("gps_gm_tau_s", o.gps_gm_tau_s),
        vertical_gusts=_flag("vertical_gusts", o.vertical_gusts),
        keep_history=_flag("keep_history", o.keep_history),
        limits=_instance("limits", o.limits, Limits, "pitotcal.core.dynamics.Limits"))
    if o.speed_loop is not None:
        from ..plan.autothrottle import SpeedLoop

        _instance("speed_loop", o.speed_loop, SpeedLoop, "maneuvers.plan.autothrottle.SpeedLoop")
    out.update(_checked_engine(o, out))
    return out


def _checked_engine(o, checked):
    """The engine's fields, and what only the own engine flies refused with JSBSim."""
    engine = choice("engine", o.engine, ENGINES)
    if engine == "own":
        if o.aircraft is not None:
            raise PitotcalError("aircraft: only engine jsbsim flies a six-degree-of-freedom "
                                "model", param="aircraft", mentions=("engine",))
        if o.center_deg is not None:
            raise PitotcalError("center_deg: only engine jsbsim places the flight on the earth",
                                param="center_deg", mentions=("engine",))
        return {"engine": engine}
    if checked["air_data"] not in (None, "compressible"):
        raise PitotcalError(f"air_data {checked['air_data']}: JSBSim's impact pressure is its "
                            "own isentropic total pressure minus static (compressible)",
                            param="air_data")
    if checked["turbulence_length_m"] is not None:
        raise PitotcalError("turbulence_length_m: JSBSim's Milspec turbulence sets its own "
                            "scale lengths (MIL-F-8785C)", param="turbulence_length_m")
    if checked["air_sensors"] is not None:
        raise PitotcalError(
            "the air-data sensors (tat_recovery, rh_percent, probe_arm_m, oat_bias_k, "
            "gps_bias_mps) apply to engine own only", param="air_sensors",
            mentions=("tat_recovery", "rh_percent", "probe_arm_m", "oat_bias_k", "gps_bias_mps",
                      "engine"))
    if o.aircraft is not None and not isinstance(o.aircraft, str):
        raise PitotcalError(f"aircraft must be a JSBSim aircraft name, got {o.aircraft!r}",
                            param="aircraft")
    center = None
    if o.center_deg is not None:
        if len(o.center_deg) != 2:
            raise PitotcalError(f"center_deg must be (lat, lon), got {o.center_deg!r}",
                                param="center_deg")
        center = check_lat_lon(*o.center_deg)
    return {"engine": engine, "center_deg": center}


def _instance(name, value, cls, shown):
    """None or an instance of `cls` (PitotcalError naming `name` and the class otherwise)."""
    if value is not None and not isinstance(value, cls):
        raise PitotcalError(f"{name} must be a {shown} or None, got {type(value).__name__}",
                            param=name)
    return value


def _checked_k(model, k):
    """None, a dict of some of the model's coefficients by name, or a tuple of >= as many
    numbers as it has (each named k1, k2, ...)."""
    names = get_model(model).params
    if k is None:
        return None
    if isinstance(k, dict):
        for name in k:
            if name not in names:
                raise PitotcalError(f"{name}: model {model!r} has only {len(names)} "
                                    f"coefficient(s), {', '.join(names)}", param=str(name))
        return {name: number(name, value) for name, value in k.items()}
    try:
        k = tuple(number(f"k{i + 1}", v) for i, v in enumerate(k))
    except TypeError:
        raise PitotcalError(f"k must be a sequence of numbers, got {k!r}", param="k") from None
    if len(k) < len(names):
        raise PitotcalError(f"k needs {len(names)} coefficients for model "
                            f"{model!r}, got {len(k)}", param="k")
    return k


def _true_k(model, k):
    """The checked `k` of `model` as the tuple flown (None and a dict filled from the model's
    defaults, a longer sequence cut to the model's coefficients)."""
    names = get_model(model).params
    if k is None or isinstance(k, dict):
        given = k or {}
        return tuple(given.get(name, default) for name, default in zip(names, true_k(model)))
    return tuple(k[:len(names)])


def simulation_options(options=None, overrides=None, *, caller="simulate"):
    """`options` (a SimulationOptions, or None for the defaults) with `overrides` (a dict of
    its fields) put in: the overrides win. An unknown name is a TypeError naming `caller`."""
    return with_overrides(SimulationOptions, options, overrides or {}, name="options",
                          caller=caller)
