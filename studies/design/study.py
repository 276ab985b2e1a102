"""`design`: the information-optimal speed schedule against the best paper profile.

Two-speed (the best of the paper's profiles in the `maneuvers` study) is flown for 240 s; the
optimal design (`plan --design optimal`, with its check level, and without it) at several
flight times. Every flight: T-2 case, 0.5 m/s Dryden turbulence, identified with the inverse
model; the score is the worst 2σ of ΔV that `identify` reports over 72-98 KIAS and whether the
truth lies inside ±2σ there (coverage). A replicate uses the same seed for every design and
time (common random numbers).

Beside the flights: the design's prediction of the reported bound of each case
(`maneuvers.plan.design.predict_plan_band_kt`), identify's own covariance run on residuals drawn
from the same noise model (`design_reported`), for continuous and step-pause too; and the
information bound: the best two-level schedule of this flight time (any dwell order, any share
of time at each end) under the noise model, with speed changes at the acceleration limit and
without ramps - what no schedule can beat.
"""

import numpy as np

from ..engine.common import (
    column,
    get_flight,
    group,
    identify_flight,
    ok_rows,
    score,
    truth_delta_v_kt,
)
from ..engine.figures import new_figure, save
from ..engine.study import MonteCarloStudy

__all__ = ["DESIGNS", "STUDY", "plan_kwargs"]

RANGE_KT = (72.0, 98.0)
TURBULENCE_MPS = 0.5
REFERENCE = ("two-speed", 240.0)
# design -> the plan's keyword arguments besides the duration
DESIGNS = {
    "two-speed": {"profile": "two-speed"},
    "optimal": {"design": "optimal"},
    "optimal-2-level": {"design": "optimal", "design_options": {"check_fraction": 0.0}},
    "continuous": {"profile": "continuous"},
    "step-pause": {"profile": "step-pause"},
}
# flown at 240 s only: the check of the prediction on the paper's other profiles
CHECK_PROFILES = ("continuous", "step-pause")
# residual draws of the emulated reported bound; cases flown fewer times than EMULATE_MIN_RUNS
# (lean runs) skip it
EMULATED_DRAWS = 100
EMULATE_MIN_RUNS = 5
DURATIONS_S = (150.0, 180.0, 210.0, 240.0)
# the information bound also below the times flown: without ramps it reaches two-speed's 240-s
# value sooner
BOUND_DURATIONS_S = (90.0, 120.0) + DURATIONS_S
QUICK_DURATIONS_S = (240.0,)
_GRID = np.linspace(*RANGE_KT, 7)


def plan_kwargs(design, duration_s):
    return {**DESIGNS[design], "duration_s": float(duration_s)}


def task(seed, design, duration_s):
    """Fly and identify one flight of the design; the common score plus the 72-98 KIAS ones."""
    kwargs = plan_kwargs(design, duration_s)
    flight, truth = get_flight(kwargs, {"turbulence_mps": TURBULENCE_MPS}, seed)
    result = identify_flight(flight)
    row = score(result, truth, flight)
    dv, two_sigma = result.delta_v_kt(_GRID)
    inside = np.abs(dv - truth_delta_v_kt(truth, _GRID)) <= two_sigma
    row.update({"dv_2sigma_range_kt": float(two_sigma.max()),
                "dv_inside_range": float(inside.mean())})
    return row


def cases(runs, quick):
    durations = QUICK_DURATIONS_S if quick else DURATIONS_S
    designs = ("optimal",) if quick else [d for d in DESIGNS
                                          if d != REFERENCE[0] and d not in CHECK_PROFILES]
    out = []
    for r in range(runs):
        out.append({"design": REFERENCE[0], "duration_s": REFERENCE[1], "seed_offset": r})
        out += [{"design": d, "duration_s": t, "seed_offset": r}
                for d in designs for t in durations]
        if not quick:
            out += [{"design": d, "duration_s": REFERENCE[1], "seed_offset": r}
                    for d in CHECK_PROFILES]
    return out


def predicted_kt(design, duration_s):
    """The predicted worst-row 2σ of ΔV over 72-98 KIAS (what identify reports) of a case."""
    from pitotcal.maneuvers.plan.design import predict_plan_band_kt

    from ..engine.common import get_plan

    plan = get_plan(**plan_kwargs(design, duration_s))
    return float(predict_plan_band_kt(plan, TURBULENCE_MPS, _GRID)[0].max())


def emulated_kt(design, duration_s, draws=EMULATED_DRAWS):
    """(median, mean) worst-row 2σ of ΔV that identify's covariance reports on residuals drawn
    from the design's noise model on the case's planned path (`design_reported`)."""
    from ..engine.common import get_plan
    from .reported import emulated_reported_kt

    plan = get_plan(**plan_kwargs(design, duration_s))
    return emulated_reported_kt(plan, TURBULENCE_MPS, _GRID, draws=draws)


def information_bound_kt(duration_s, accel_max_mps2=None):
    """The information bound: the least predicted worst-row 2σ of ΔV over 72-98 KIAS of any
    two-level schedule (`maneuvers.plan.design.design_schedule` without a check level: 2 to
    MAX_DWELLS dwells at 70 and 100 KCAS, any share of time at each end) on the T-2 circle,
    speed changes at `accel_max_mps2` (default: the T-2 limit, 1 m/s²; 1e3: without ramps), kt,
    and the design (order, share at the low end); Nones when no schedule turns 360° at each
    end in this time."""
    from pitotcal.maneuvers.plan.design import (
        ORDERS,
        alternating_orders,
        default_noise,
        design_schedule,
    )

    from pitotcal.core.errors import PlanInfeasibleError
    from pitotcal.core.scenario import T2_PLAN as p
    from pitotcal.core.units import kt_to_mps, wind_vector_mps

    noise = default_noise(TURBULENCE_MPS, p["altitude_m"],
                          [kt_to_mps(0.5 * (p["cas_min_kt"] + p["cas_max_kt"]))])
    try:
        d = design_schedule(
            p["cas_min_kt"], p["cas_max_kt"], float(duration_s), altitude_m=p["altitude_m"],
            accel_max_mps2=accel_max_mps2 or 1.0, dt_s=1.0,
            bank_max_rad=np.radians(p["bank_max_deg"]), radius_m=p["radius_m"],
            wind_ne_mps=wind_vector_mps(p["wind_speed_mps"], p["wind_from_deg"]), noise=noise,
            coverage_rad=2 * np.pi + np.radians(15.0), range_kt=RANGE_KT, check_fraction=0.0,
            orders=ORDERS + alternating_orders())
    except PlanInfeasibleError:                 # too short to turn 360° at each end
        return None, None, None
    return d.predicted_2sigma_kt, "-".join("LCH"[j] for j in d.order), d.low_share


def bound_summary(reference_predicted_kt):
    """The information bound at each flight time, at the acceleration limit ("bound") and
    without ramps ("bound_no_ramps"): the best design at 240 s, its gain over two-speed's
    prediction at 240 s, and the flight time at which it reaches that prediction (None
    outside the times planned)."""
    out = {}
    for accel, key in ((1.0, "bound"), (1e3, "bound_no_ramps")):
        bounds = {str(int(t)): information_bound_kt(t, accel) for t in BOUND_DURATIONS_S}
        at_240 = bounds[str(int(REFERENCE[1]))]
        out[f"{key}_kt"] = {t: round(b[0], 3) for t, b in bounds.items() if b[0]}
        out[f"{key}_design_at_240s"] = list(at_240[1:])
        out[f"{key}_gain_at_240s"] = round(1.0 - at_240[0] / reference_predicted_kt, 3)
        out[f"{key}_time_to_reference_s"] = _time_to(
            {t: {"predicted_kt": v} for t, v in out[f"{key}_kt"].items()},
            reference_predicted_kt)
    return out


def summarize(rows, cases=None):
    by_design = {}
    for (design, duration), rs in group(rows, "design", "duration_s").items():
        good = ok_rows(rs)
        two_sigma = column(good, "dv_2sigma_range_kt")
        entry = {"n_runs": len(rs), "n_ok": len(good),
                 "dv_2sigma_range_kt": _median(two_sigma),
                 # standard error of a median, 1.253 sigma / sqrt(n) for a normal sample
                 "dv_2sigma_range_se_kt": (float(1.253 * np.std(two_sigma) / np.sqrt(len(good)))
                                           if len(good) > 1 else None),
                 "coverage": _mean(column(good, "dv_inside_range")),
                 "dv_err_max_kt_rms": _rms(column(good, "dv_err_max_kt")),
                 "mean_2sigma_range_kt": _mean(two_sigma),
                 "predicted_kt": round(predicted_kt(design, duration), 3)}
        if len(good) >= EMULATE_MIN_RUNS:
            entry["emulated_kt"], entry["emulated_mean_kt"] = (
                round(v, 3) for v in emulated_kt(design, duration))
        by_design.setdefault(design, {})[str(int(duration))] = entry
    ref = by_design.get(REFERENCE[0], {}).get(str(int(REFERENCE[1])), {})
    out = {"by_design": by_design, "range_kt": list(RANGE_KT),
           "turbulence_mps": TURBULENCE_MPS, "reference": ref}
    if ref:
        out["information_bound"] = bound_summary(ref["predicted_kt"])
    for design, entries in by_design.items():
        for duration, entry in entries.items():
            entry["paired_ratio"] = _paired_ratio(rows, design, float(duration))
    for design in DESIGNS:
        same = by_design.get(design, {}).get(str(int(REFERENCE[1])))
        if design == REFERENCE[0] or same is None or same["paired_ratio"] is None:
            continue
        out[f"{design}_gain_at_240s"] = round(1.0 - same["paired_ratio"], 3)
        out[f"{design}_time_to_reference_s"] = _time_to(
            by_design[design], same["predicted_kt"] / same["paired_ratio"])
        out[f"{design}_predicted_time_to_reference_s"] = _time_to(
            by_design[design], ref.get("predicted_kt"))
    return out


def _paired_ratio(rows, design, duration_s):
    """Geometric mean over seeds of the worst-row 2σ of ΔV of this case over two-speed's at
    240 s on the same seed (common random numbers: the same turbulence at 240 s), or None."""
    ref = {r["seed"]: r.get("dv_2sigma_range_kt") for r in ok_rows(rows)
           if (r["design"], float(r["duration_s"])) == (REFERENCE[0], REFERENCE[1])}
    logs = [np.log(r["dv_2sigma_range_kt"] / ref[r["seed"]]) for r in ok_rows(rows)
            if (r["design"], float(r["duration_s"])) == (design, duration_s)
            and ref.get(r["seed"]) and r.get("dv_2sigma_range_kt")]
    return round(float(np.exp(np.mean(logs))), 3) if logs else None


def _time_to(entries, target_kt):
    """The flight time at which the design's predicted worst-row 2σ falls to `target_kt`
    (log-log interpolation of the predicted curve), or None outside the times planned."""
    pts = sorted((float(t), e["predicted_kt"]) for t, e in entries.items())
    if target_kt is None or len(pts) < 2:
        return None
    t, v = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    if not v.min() <= np.log(target_kt) <= v.max():
        return None
    order = np.argsort(v)
    return round(float(np.exp(np.interp(np.log(target_kt), v[order], t[order]))), 1)


def headline(summary):
    ref = summary["reference"].get("dv_2sigma_range_kt")
    opt = summary["by_design"].get("optimal", {}).get("240", {}).get("dv_2sigma_range_kt")
    if ref is None or opt is None:
        return "no converged two-speed and optimal flights at 240 s"
    gain = summary.get("optimal_gain_at_240s")
    reach = summary.get("optimal_time_to_reference_s")
    reach_text = f"{reach:.0f} s" if reach else "outside the times flown"
    bound = summary.get("information_bound", {}).get("bound_gain_at_240s")
    bound_text = f"; information bound {bound:.0%} below two-speed" if bound is not None else ""
    return (f"at 240 s optimal {opt:.2f} kt vs two-speed {ref:.2f} kt worst-row 2σ of ΔV over "
            f"72-98 KIAS ({gain:+.0%} gain); two-speed's value reached in {reach_text}"
            f"{bound_text}")


def plot(rows, summary, out_dir):
    return [save(figure(summary), out_dir, "design.png")]


def figure(summary):
    """Median worst-row 2σ of ΔV vs flight time (flown, with the median's standard error, and
    predicted, with the information bound), and the coverage of ±2σ, per design."""
    fig, ax = new_figure(1, 2, size=(5.0, 4.6))
    for (design, entries), marker in zip(summary["by_design"].items(), "Dos^v"):
        t = np.array(sorted(float(k) for k in entries))
        e = [entries[str(int(x))] for x in t]
        shift = {"optimal": -2.0, "optimal-2-level": 2.0, "continuous": 4.0,
                 "step-pause": 6.0}.get(design, 0.0)                       # bars apart
        bar = ax[0, 0].errorbar(t + shift, _nan([x["dv_2sigma_range_kt"] for x in e]),
                                yerr=_nan([x.get("dv_2sigma_range_se_kt") for x in e]),
                                fmt=marker + "-", capsize=2, label=f"{design} (flown)")
        color = bar.lines[0].get_color()
        ax[0, 0].plot(t, [x["predicted_kt"] for x in e], "x:" if t.size == 1 else ":",
                      color=color, label=f"{design} (predicted)")
        ax[0, 1].plot(t, 100 * _nan([x["coverage"] for x in e]), marker + "-", label=design,
                      color=color)
    bounds = summary.get("information_bound", {})
    for key, style, label in (("bound_kt", "k--", "information bound (1 m/s² ramps)"),
                              ("bound_no_ramps_kt", "k:", "information bound (no ramps)")):
        if key in bounds:
            pts = sorted((float(t), v) for t, v in bounds[key].items())
            ax[0, 0].plot(*zip(*pts), style, lw=0.8, label=label)
    ref = summary["reference"].get("dv_2sigma_range_kt")
    if ref:
        ax[0, 0].axhline(ref, color="0.6", lw=0.6, ls="-.", label="two-speed at 240 s")
    ax[0, 0].set_ylabel("2σ of ΔV, kt (median,\nworst over 72-98 KIAS)")
    ax[0, 1].set_ylabel("truth inside ±2σ, %")
    ax[0, 1].axhspan(90, 98, color="0.9")
    for a in ax.flat:
        a.set_xlabel("flight time, s")
    ax[0, 1].legend(fontsize=7)
    fig.legend(*ax[0, 0].get_legend_handles_labels(), loc="outside lower center", ncol=4,
               fontsize=7)
    fig.suptitle(f"Optimal design vs two-speed, {summary['turbulence_mps']:g} m/s turbulence")
    return fig


def _median(x):
    x = x[np.isfinite(x)]
    return float(np.median(x)) if x.size else None


def _mean(x):
    x = x[np.isfinite(x)]
    return float(np.mean(x)) if x.size else None


def _rms(x):
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x ** 2))) if x.size else None


def _nan(values):
    return np.array([np.nan if v is None else v for v in values], dtype=float)


STUDY = MonteCarloStudy(
    "design", "information-optimal speed schedule vs two-speed: worst-row 2σ of ΔV, 72-98 KIAS",
    task, cases, summarize, plot, headline, default_runs=20, quick_runs=1)
