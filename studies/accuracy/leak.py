"""`leak`: is a leak from mid-flight flagged, and does a clean flight stay quiet?

Every run flies a maneuver (the T-2 one-way speed sweep, or the same flown up and back down
the speeds, `plan --return`) in calm air or in turbulence, with or without a leak in the total
line from mid-flight (q_ci 3 % low from t = 120 s, `maneuvers.fly.faults`), and identifies the
inverse model. Per case it reports how often the consistency checks act (the change-of-scale
test, the abrupt-jump test, either) and how often the result says that the maneuver hides a
change of scale; and against truth how often ΔV leaves its 2σ band somewhere in the flown
range, and how often it does so with no warning from the checks (a tight wrong answer).
"""

import numpy as np

from ..engine.common import column, get_flight, identify_flight, ok_rows, percent, score, truth_for
from .coverage import wilson_interval
from ..engine.figures import new_figure, save
from ..engine.study import MonteCarloStudy

__all__ = ["LEAK", "ONSET_S", "PLANS", "STUDY", "TURBULENCE_MPS"]

PLANS = {"one-way": {}, "up-and-down": {"return_leg": True}}
TURBULENCE_MPS = (0.0, 0.5, 1.0)
LEAK = 0.03          # q_ci this fraction low from ONSET_S on
ONSET_S = 120.0      # the middle of the T-2 plan's 240 s


def task(seed, plan, turbulence_mps, leak):
    """Fly, spoil (a leak when `leak` > 0), identify, score; with the checks' verdicts."""
    from pitotcal.maneuvers.fly.faults import apply_fault, check_fault

    flight, truth = get_flight(PLANS[plan], {"turbulence_mps": turbulence_mps}, seed)
    if leak > 0:
        flight = apply_fault(flight, truth, check_fault("leak", ONSET_S, leak, seed))
    result = identify_flight(flight)
    row = score(result, truth_for(truth, flight), flight)
    check = result.consistency or {}
    jump = check.get("jump", {})
    step = bool(check.get("flagged", False))
    jumped = bool(jump.get("flagged", False))
    hidden = any("hides in the calibration" in w for w in result.warnings)
    outside = bool(row["dv_inside_2sigma"] < 1.0)
    row.update(step_flagged=step, jump_flagged=jumped, flagged=step or jumped, hidden=hidden,
               dv_outside_2sigma=outside, silent_wrong=outside and not (step or jumped or hidden),
               step_z=check.get("z"), jump_z=jump.get("z"), jump_time_s=jump.get("time_s"),
               undetected_step=check.get("undetected", {}).get("step"))
    return row


def cases(runs, quick):
    grid = [(p, t, s) for p in PLANS for t in TURBULENCE_MPS for s in (0.0, LEAK)]
    if quick:
        grid = [("one-way", 0.5, LEAK)]
    return [{"plan": p, "turbulence_mps": t, "leak": s, "seed_offset": r}
            for r in range(runs) for p, t, s in grid]


def summarize(rows, cases=None):
    out = {"cases": []}
    keys = []
    for r in rows:
        key = (r.get("plan"), float(r.get("turbulence_mps")), float(r.get("leak")))
        if key not in keys:
            keys.append(key)
    for plan, turb, leak in keys:
        good = ok_rows([r for r in rows if r.get("plan") == plan
                        and float(r.get("turbulence_mps")) == turb and float(r.get("leak")) == leak])
        if good:
            out["cases"].append({"plan": plan, "turbulence_mps": turb, "leak": leak,
                                 **case_summary(good)})
    return out


def case_summary(good):
    """Rates (with Wilson 95 % intervals) of each verdict over the converged runs of a case."""
    out = {"n_runs_used": len(good)}
    for name in ("flagged", "step_flagged", "jump_flagged", "hidden", "dv_outside_2sigma",
                 "silent_wrong"):
        x = column(good, name) > 0.5
        out[name] = float(np.mean(x))
        out[f"{name}_interval95"] = wilson_interval(x)
    out["median_undetected_step"] = float(np.nanmedian(column(good, "undetected_step")))
    return out


def headline(summary):
    parts = []
    for c in summary.get("cases", []):
        what = "leak flagged" if c["leak"] > 0 else "clean flagged"
        parts.append(f"{c['plan']} {c['turbulence_mps']:g} m/s: {what} {percent(c['flagged'])}, "
                     f"hides {percent(c['hidden'])}, silent wrong {percent(c['silent_wrong'])}")
    if not parts:
        return f"no run of {summary.get('n_runs', 0)} converged"
    return "; ".join(parts)


def plot(rows, summary, out_dir):
    return [save(figure(summary), out_dir, "leak.png")]


def figure(summary):
    """Per case: flagged, hides, and a wrong ΔV with no warning, clean and with the leak."""
    fig, ax = new_figure(1, 2, size=(5.5, 4.0))
    for a, leak in zip(ax[0], (0.0, LEAK)):
        sel = [c for c in summary.get("cases", []) if (c["leak"] > 0) == (leak > 0)]
        labels = [f"{c['plan']}\n{c['turbulence_mps']:g} m/s" for c in sel]
        pos = np.arange(len(sel))
        for i, (name, text, color) in enumerate((
                ("flagged", "flagged (step or jump)", "tab:blue"),
                ("hidden", "'maneuver hides a change'", "tab:orange"),
                ("silent_wrong", "ΔV outside 2σ, no warning", "tab:red"))):
            a.bar(pos + (i - 1) * 0.27, [c[name] for c in sel], 0.27, label=text, color=color)
        a.axhline(0.05, color="k", ls=":", lw=0.8)
        if leak > 0:
            a.axhline(0.95, color="k", ls="--", lw=0.8)
        a.set_xticks(pos, labels, fontsize=8)
        a.set_ylim(0, 1.05)
        a.set_title(f"leak {100 * leak:g}% from t = {ONSET_S:g} s" if leak else "clean flights")
        a.set_ylabel("fraction of flights")
    handles, labels = ax[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, loc="outside lower center", ncols=3)
    return fig


STUDY = MonteCarloStudy(
    "leak", "a leak from mid-flight: flagged, hidden or silently wrong, per maneuver and air",
    task, cases, summarize, plot, headline, default_runs=50, quick_runs=1)
