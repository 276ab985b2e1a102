"""The options of `simulate` (maneuvers.simulator), checked before any work.

Every number goes through pitotcal.core.checks, so an error names the parameter (and the
command line its flag); the mean wind defaults to the plan's settings; the record's size is
checked against MAX_SAMPLES and the GPS latency against the plan's length.
"""

import math
from dataclasses import asdict, dataclass

import numpy as np

from pitotcal.core.airdata import AIR_DATA_MODES
from pitotcal.core.checks import choice, number, positive
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model
from pitotcal.core.plan import Plan
from pitotcal.core.scenario import T2_PLAN, true_k

__all__ = ["MAX_SAMPLES", "SimOptions", "check_plan", "sim_options"]

# Memory grows with the samples (~1.5 kB each in the scalar loop, measured: 1.5 GB peak and
# 13 s for 10^6): 500,000 is 2.8 h at 50 Hz, or 42 min at 200 Hz.
MAX_SAMPLES = 500_000

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
    air_data: str = "incompressible"
    # Gauss-Markov GPS velocity error (issue 11): steady-state sigma (m/s; 0 none), tau (s)
    gps_gm_sigma_mps: float = 0.0
    gps_gm_tau_s: float = 30.0

    def to_dict(self):
        """As written in the truth JSON (sequences as lists)."""
        out = asdict(self)
        out["k"], out["wind_drift_mps2"] = list(self.k), list(self.wind_drift_mps2)
        if not self.gps_gm_sigma_mps:       # without it, the truth JSON stays as it was
            del out["gps_gm_sigma_mps"], out["gps_gm_tau_s"]
        return out



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
             air_data="incompressible", gps_gm_sigma_mps=0.0, gps_gm_tau_s=30.0):
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
        wind_speed_mps=number("wind_speed_mps", wind_speed_mps, 0.0),
        wind_from_deg=number("wind_from_deg", wind_from_deg, 0.0, 360.0, hi_open=True),
        # each component named like its command-line flag
        wind_drift_mps2=tuple(number(f"wind_drift_{axis}_mps2", v)
                              for axis, v in zip("ne", wind_drift_mps2)),
        turbulence_mps=number("turbulence_mps", turbulence_mps, 0.0),
        turbulence_length_m=(None if turbulence_length_m is None
                             else positive("turbulence_length_m", turbulence_length_m)),
        rate_hz=positive("rate_hz", rate_hz),
        qc_noise_pa=number("qc_noise_pa", qc_noise_pa, 0.0),
        qc_quantization_pa=number("qc_quantization_pa", qc_quantization_pa, 0.0),
        qc_bias_pa=number("qc_bias_pa", qc_bias_pa),
        qc_scale_error=number("qc_scale_error", qc_scale_error, -0.5),
        pneumatic_lag_s=number("pneumatic_lag_s", pneumatic_lag_s, 0.0),
        gps_rate_hz=number("gps_rate_hz", gps_rate_hz or 0.0, 0.0),
        gps_noise_mps=number("gps_noise_mps", gps_noise_mps, 0.0),
        gps_latency_s=number("gps_latency_s", gps_latency_s, 0.0),
        air_data=choice("air_data", air_data, AIR_DATA_MODES),
        gps_gm_sigma_mps=number("gps_gm_sigma_mps", gps_gm_sigma_mps, 0.0),
        gps_gm_tau_s=positive("gps_gm_tau_s", gps_gm_tau_s))
    span_s = float(plan.time_s[-1] - plan.time_s[0])
    samples = span_s * opts.rate_hz + 1
    if samples > MAX_SAMPLES:
        raise PitotcalError(
            f"rate_hz {opts.rate_hz:g} gives {samples:.3g} samples over the plan's {span_s:g} s; "
            f"the simulator records at most {MAX_SAMPLES:,}: use at most "
            f"{math.floor((MAX_SAMPLES - 1) / span_s):g} Hz", param="rate_hz")
    if opts.gps_latency_s >= span_s:
        raise PitotcalError(f"gps_latency_s {opts.gps_latency_s:g} must be shorter than the "
                            f"plan's {span_s:g} s (typical receivers: 0-0.5 s)",
                            param="gps_latency_s")
    return opts
