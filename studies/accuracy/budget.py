"""`budget`: each Type B term of the uncertainty budget next to the statistical 2σ.

The T-2 maneuver (planner defaults: 70-100 KCAS, 244 m, 5 m/s wind) is flown with
compressible truth (the static error in the logged ps_pa) in calm air, light and moderate
turbulence; each flight is identified (the default compressible fit) and its uncertainty budget computed
with the documented default inputs (estimation.identification.budget.BudgetInputs) and a wingtip probe 1 m
out that the data were not corrected for (`probe_arm_m` = 1, counted wholly; 0 for a probe on the
centre line). The table has,
per flight, the largest standard uncertainty of ΔV over the flown range for each source; the
figure sets them beside each other per turbulence level. The calm-air statistical part is what
a Monte Carlo of our own simulator shows; the Type B terms are what it cannot.
"""

import numpy as np

from ..engine.common import get_flight, group, identify_flight, score, truth_for
from ..engine.figures import new_figure, save
from ..engine.study import MonteCarloStudy

__all__ = ["PROBE_ARM_M", "STUDY", "TURBULENCE_MPS"]

TURBULENCE_MPS = (0.0, 0.5, 1.5)
QUICK_TURBULENCE_MPS = (0.0,)
PROBE_ARM_M = 1.0
_FLOOR_KT = 1e-4          # bars below this (the GPS bias, taken by the wind) drawn at it


def task(seed, turbulence_mps):
    """One flight: its score against truth, and the budget's terms (max over V_i), kt."""
    from pitotcal.estimation.identification.budget import BudgetInputs, uncertainty_budget

    flight, truth = get_flight(None, {"turbulence_mps": turbulence_mps, "air_data": "compressible"},
                        seed)
    result = identify_flight(flight)
    budget = uncertainty_budget(flight, result, BudgetInputs(probe_arm_m=PROBE_ARM_M))
    row = {**score(result, truth_for(truth, flight), flight),
           "two_sigma_kt": float(2.0 * np.max(budget.statistical_kt)),
           "U_kt": float(np.max(budget.expanded_kt))}
    for item in budget.to_list():
        row[f"u_{item['source']}_kt"] = item["u_dv_kt"]
    row["U_over_2sigma"] = row["U_kt"] / row["two_sigma_kt"]
    return row


def cases(runs, quick):
    levels = QUICK_TURBULENCE_MPS if quick else TURBULENCE_MPS
    return [{"turbulence_mps": t, "seed_offset": r} for r in range(runs) for t in levels]


def _sources(rows):
    return [k[2:-3] for k in rows[0] if k.startswith("u_") and k.endswith("_kt")] if rows else []


def summarize(rows, cases=None):
    """Median over the flights of each term, per turbulence level."""
    good = [r for r in rows if not r.get("error")]
    out = {}
    for (level,), rs in group(good, "turbulence_mps").items():
        entry = {"n_runs": len(rs)}
        for name in ("two_sigma_kt", "U_kt", "U_over_2sigma"):
            entry[name] = float(np.median([r[name] for r in rs]))
        entry["u_dv_kt"] = {s: float(np.median([r[f"u_{s}_kt"] for r in rs]))
                            for s in _sources(rs)}
        out[f"{level:g}"] = entry
    return {"by_turbulence_mps": out, "probe_arm_m": PROBE_ARM_M}


def headline(summary):
    by = summary["by_turbulence_mps"]
    if not by:
        return "no flight identified"
    calm = by[min(by, key=float)]
    type_b = {k: v for k, v in calm["u_dv_kt"].items() if k != "statistical"}
    big = max(type_b, key=type_b.get)
    return (f"turbulence {min(by, key=float)} m/s: statistical 2σ {calm['two_sigma_kt']:.2f} kt, "
            f"U (k = 2) {calm['U_kt']:.2f} kt ({calm['U_over_2sigma']:.1f}x); largest Type B "
            f"term {big} u = {type_b[big]:.2f} kt")


def plot(rows, summary, out_dir):
    """Bars: each source's standard uncertainty of ΔV (max over the flown range), per
    turbulence level, on a log axis; the statistical part first."""
    by = summary["by_turbulence_mps"]
    if not by:
        return []
    fig, ax = new_figure(1, 1, size=(9.0, 4.2))
    ax = ax[0, 0]
    levels = sorted(by, key=float)
    sources = list(by[levels[0]]["u_dv_kt"])
    width = 0.8 / len(levels)
    x = np.arange(len(sources))
    for i, level in enumerate(levels):
        u = [max(by[level]["u_dv_kt"][s], _FLOOR_KT) for s in sources]
        at = x + (i - (len(levels) - 1) / 2) * width
        ax.bar(at, u, width, label=f"turbulence {level} m/s (U = {by[level]['U_kt']:.2f} kt)")
        for xi, ui in zip(at, u):
            if ui <= _FLOOR_KT:                 # nothing to draw on a log axis: say so
                ax.text(xi, _FLOOR_KT * 1.2, "≈0", ha="center", fontsize=7)
    ax.set_yscale("log")
    ax.set_xticks(x, [s.replace("_", "\n") for s in sources], fontsize=8)
    ax.set_ylabel("standard uncertainty of ΔV, kt (max over V_i)")
    ax.set_title(f"Uncertainty budget of the T-2 calibration (defaults; probe arm "
                 f"{summary['probe_arm_m']:g} m; statistical = 2σ/2)")
    ax.legend(fontsize=8)
    return [save(fig, out_dir, "budget.png")]


STUDY = MonteCarloStudy("budget", "each Type B term of the uncertainty budget next to the "
                                  "statistical 2σ, per turbulence level",
                        task, cases, summarize, plot, headline, default_runs=3, quick_runs=1)
