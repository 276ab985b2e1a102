"""What the simulator can fly: a plan it can follow, a record of a size it can hold, a true
pressure error that leaves the sensor an impact pressure (maneuvers.fly.options checks a
`SimulationOptions` against the plan with these)."""

import numpy as np

from pitotcal.core.checks import exact, round_to_limit
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import MAX_PRESSURE_ERROR, get_model
from pitotcal.core.plan import Plan

__all__ = ["MAX_PRESSURE_ERROR", "MAX_SAMPLES", "MIN_SAMPLES", "check_plan", "check_pressure_error",
           "check_samples"]

# Memory grows with the samples (~1.5 kB each in the scalar loop, measured: 1.5 GB peak and
# 13 s for 10^6): 500,000 is 2.8 h at 50 Hz, or 42 min at 200 Hz.
MAX_SAMPLES = 500_000
MIN_SAMPLES = 10          # the flight CSV reader's MIN_ROWS: fewer is no flight
_PLAN_COLUMNS_FLOWN = ("north_m", "east_m", "alt_m", "heading_deg", "bank_deg", "tas_mps",
                       "cas_mps")


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




def check_pressure_error(opts, plan):
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


def check_samples(rate_hz, span_s):
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
