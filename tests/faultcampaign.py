"""Late pitot faults on simulated return-sweep flights: warned, or within 3 sigma.

A flight of the default plan flown up and back down the speeds (`plan --return`), a fault with
its onset drawn in the last quarter of the record, identified; the outcome is "warned" (a
warning naming a change of calibration or a collapsed q_ci), "within" (every correction-table
row within 3 sigma of the truth) or "missed" (neither: a confident wrong answer).
"""

import functools

import numpy as np

import pitotcal
from pitotcal.core.models import delta_v_kt, get_model
from pitotcal.maneuvers.fly.faults import Fault, apply_fault

# what names a late or gradual fault (consistency.step_test, jumps.jump_test, the collapse,
# consistency.tail_warning)
NAMED = ("changes during the flight", "q_ci collapses", "jumps at", "q_ci drifts low")


@functools.lru_cache(maxsize=None)
def return_plan(return_leg=True):
    """The default plan, flown up and back down the speeds (or one way)."""
    return pitotcal.plan_maneuver(return_leg=return_leg)


def late_fault(kind, seed, duration_s):
    """A fault of `kind` with its onset uniform over the last quarter of the record:
    ``blocked`` with a drain time constant of 0 (sealed) or 10-60 s, ``icing`` at 2-10
    kt/min."""
    rng = np.random.default_rng(1000 + seed)
    onset = float(rng.uniform(0.75, 0.98) * duration_s)
    if kind == "blocked":
        size = 0.0 if rng.random() < 0.25 else float(rng.uniform(10.0, 60.0))
    else:
        size = float(rng.uniform(2.0, 10.0))
    return Fault(kind, onset, size)


def outcome(kind, seed, turbulence_mps=0.5, return_leg=True):
    """(outcome, details) of one flight: "warned", "within" or "missed"; `kind` None: clean."""
    flight, truth = pitotcal.simulate(return_plan(return_leg), seed=seed,
                                      turbulence_mps=turbulence_mps, keep_history=True)
    fault = None
    if kind is not None:
        fault = late_fault(kind, seed, float(flight.time_s[-1]))
        flight = apply_fault(flight, truth, fault)
    result = pitotcal.identify(flight)
    named = [w for w in result.warnings if any(key in w for key in NAMED)]
    rows = result.correction_table()
    vi = np.array([row["vi_kt"] for row in rows])
    band = np.array([row["dv_2sigma_kt"] for row in rows])
    dv = np.array([row["dv_kt"] for row in rows])
    true = delta_v_kt(get_model(truth.model), truth.k, vi, result.air_data)
    worst = float(np.max(np.abs(dv - true) / (band / 2.0)))
    details = {"fault": None if fault is None else fault.to_dict(), "worst_sigma": worst,
               "lowest_vi_kt": float(vi[0]), "named": named,
               "collapse": result.consistency.get("collapse"),
               "z": result.consistency.get("z"), "threshold": result.consistency.get("threshold"),
               "kind": result.consistency.get("kind"),
               "end_ratio": result.consistency.get("end_ratio"),
               "ratio_spread": result.consistency.get("ratio_spread"),
               "tail_sigmas": (result.consistency.get("tail_drift") or {}).get("sigmas")}
    if named:
        return "warned", details
    return ("within" if worst <= 3.0 else "missed"), details
