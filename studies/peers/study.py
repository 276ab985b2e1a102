"""`peers`: pitotcal against the autopilots' calibrators on the same simulated flights, versus
flight time.

Each run flies one seeded simulated calibration flight (`maneuvers.plan_maneuver` +
`maneuvers.simulate`, through `studies.engine.common.get_flight`), then for each flight time T
uses only the first T seconds:

- pitotcal: `estimation.identify` on [0, T] (it refuses, with ObservabilityError, while the
  track has not turned enough: recorded as "no estimate", not as an error);
- the ArduPilot-style and PX4-style filters (`studies.peers.ardupilot`, `studies.peers.px4`), run
  over the whole flight, read at time T: what the autopilot would report after T seconds.

Scored against the simulation's truth: the airspeed correction ΔV at `VI_REF_KT`, the largest
ΔV error over the V_i range flown in [0, T] (where a single scale is structurally wrong when the
truth is not `constant`), and the wind vector, each with the method's own stated 2σ (covered =
truth inside it; the wind uses the 2-D 95.45 % ellipse of the stated covariance). The truth
wind of the first T seconds is the time-average of the wind flown through in those seconds.

Two truth cases, sharing their seeds: the peers' own `constant` structure (k1 = 0.05, the fair
case for them; the top level of the summary), and the paper's `inverse` model (pitotcal fits
`inverse`; the peers still learn one scale, so they are structurally biased at the ends of the
speed range; ``inverse_truth`` in the summary).
"""

import numpy as np

from pitotcal.core.errors import ObservabilityError, PitotcalError
from pitotcal.core.scenario import TRUE_K

from .baselines import delta_v_kt_from_k1
from ..engine.common import get_flight, stats, truth_delta_v_kt, vi_grid_kt, window_wind
from .ardupilot import ardupilot_autocal
from .figure import plot_peers
from .px4 import px4_wind_estimator
from ..engine.study import MonteCarloStudy

__all__ = ["METHODS", "STUDY", "TRUTH_CASES", "compare_one_flight", "peer_task"]

NAME = "peers"
METHODS = ("pitotcal", "ardupilot", "px4")
CHI2_2D_2SIGMA = 6.18        # chi-square(2 dof) quantile of the 2-sigma (95.45 %) probability
DEFAULT_TIMES_S = (30.0, 60.0, 120.0, 240.0, 480.0, 600.0)
QUICK_TIMES_S = (30.0, 240.0)
# (true model, its coefficients): the peers' own one-scale structure first, then the paper's
TRUTH_CASES = (("constant", (0.05,)), ("inverse", TRUE_K["inverse"]))
VI_REF_KT = 85.0             # where ΔV is compared
DV_TOL_KT = 0.5              # accuracy targets of the time-to-accuracy claims
WIND_TOL_MPS = 0.5
COLUMNS = ("seed", "method", "T_s", "estimate", "k1", "dv_kt", "dv_true_kt", "dv_err_kt",
           "dv_2sigma_kt", "dv_covered", "wind_err_mps", "wind_2sigma_mps", "wind_covered",
           "reason", "truth_model", "dv_range_err_max_kt", "dv_range_2sigma_max_kt",
           "dv_range_covered", "run_index", "error")


def _range_score(dv, dv2, dv_true):
    err = np.abs(np.asarray(dv, dtype=float) - dv_true)
    return {"dv_range_err_max_kt": float(err.max()),
            "dv_range_2sigma_max_kt": float(np.max(dv2)),
            "dv_range_covered": bool(np.all(err <= np.asarray(dv2, dtype=float)))}


def _wind_score(est, cov, true):
    err = np.asarray(est) - np.asarray(true)
    cov = np.asarray(cov, dtype=float)
    try:
        d2 = float(err @ np.linalg.solve(cov, err))
    except np.linalg.LinAlgError:
        d2 = np.inf
    return {"wind_err_mps": float(np.hypot(*err)),
            "wind_2sigma_mps": float(2.0 * np.sqrt(max(np.trace(cov), 0.0) / 2.0)),
            "wind_covered": bool(d2 <= CHI2_2D_2SIGMA)}


def compare_one_flight(flight, truth, *, times_s=DEFAULT_TIMES_S, model="constant",
                       vi_ref_kt=VI_REF_KT):
    """Rows {method, T_s, dv_err_kt, dv_2sigma_kt, dv_covered, dv_range_err_max_kt,
    dv_range_2sigma_max_kt, dv_range_covered, wind_err_mps, ...} of one simulated flight and
    its `Truth`; `model` is the structure pitotcal fits."""
    if not times_s or any(t <= 0 for t in times_s):
        raise PitotcalError(f"times_s must be positive seconds, got {times_s!r}",
                            param="times_s")
    t0 = float(flight.time_s[0])
    dv_true = float(truth_delta_v_kt(truth, vi_ref_kt))
    tracks = {"ardupilot": ardupilot_autocal(flight), "px4": px4_wind_estimator(flight)}
    rows = []
    for T in times_s:
        part = flight.window(t0, t0 + T)
        grid = vi_grid_kt(part.qci_pa)
        scoring = {"w_true": window_wind(truth, part), "grid": grid,
                   "grid_true": np.asarray(truth_delta_v_kt(truth, grid), dtype=float),
                   "vi_ref_kt": vi_ref_kt}
        base = {"T_s": float(T), "dv_true_kt": dv_true}
        rows.append({**base, **_pitotcal_row(part, model, scoring)})
        for name, track in tracks.items():
            rows.append({**base, "method": name, **_peer_row(track, t0 + T, scoring)})
    for row in rows:
        if row.get("estimate"):
            row["dv_err_kt"] = row["dv_kt"] - dv_true
            row["dv_covered"] = bool(abs(row["dv_err_kt"]) <= row["dv_2sigma_kt"])
    return rows


def _pitotcal_row(part, model, scoring):
    """pitotcal's estimate from the first T seconds, scored; "no estimate" while it refuses."""
    from pitotcal.estimation import identify

    try:
        res = identify(part, model=model)
    except ObservabilityError as exc:
        return {"method": "pitotcal", "estimate": False, "reason": str(exc)}
    nk = len(res.coefficients)
    dv, dv2 = res.delta_v_kt(scoring["vi_ref_kt"])
    row = {"method": "pitotcal", "estimate": bool(res.success), "reason": "",
           "k1": float(res.coefficients[0]), "dv_kt": float(dv), "dv_2sigma_kt": float(dv2)}
    row.update(_wind_score(res.internal_params[nk:nk + 2],
                           res.internal_covariance[nk:nk + 2, nk:nk + 2], scoring["w_true"]))
    row.update(_range_score(*res.delta_v_kt(scoring["grid"]), scoring["grid_true"]))
    return row


def _peer_row(track, t_s, scoring):
    """What a peer filter reported at `t_s`, scored; "no estimate" before it initialised."""
    i = track.index_at(t_s)
    if i < 0:
        return {"estimate": False, "reason": "filter not initialised"}
    a = track.at(t_s, vi_kt=scoring["vi_ref_kt"])
    row = {"estimate": True, "reason": "", "k1": a["k1"], "dv_kt": a["dv_kt"],
           "dv_2sigma_kt": a["dv_2sigma_kt"]}
    row.update(_wind_score((a["wind_n_mps"], a["wind_e_mps"]), track.covariance[i][:2, :2],
                           scoring["w_true"]))
    k1, s1 = track.k1[i], track.k1_std[i]
    grid = scoring["grid"]
    # same first-order propagation as BaselineTrack.at, on the whole grid
    row.update(_range_score(delta_v_kt_from_k1(k1, grid),
                            2.0 * s1 * grid / (2.0 * (1.0 - k1) ** 1.5), scoring["grid_true"]))
    return row


def peer_task(seed, truth_model, fit_model, k, plan, sim, times_s, vi_ref_kt):
    """One run of the study (module level: it goes to Dask workers): fly one seeded flight of
    the truth case and score every method at every T; a list of rows."""
    flight, truth = get_flight(plan, {**sim, "model": truth_model, "k": tuple(k)}, seed)
    return compare_one_flight(flight, truth, times_s=times_s, model=fit_model,
                              vi_ref_kt=vi_ref_kt)


def cases(runs, quick):
    """`runs` seeded flights per truth case (the cases share their seeds); the plan is the
    T-2 continuous one stretched to the longest T."""
    times_s = QUICK_TIMES_S if quick else DEFAULT_TIMES_S
    plan = {"duration_s": max(times_s)}
    return [{"truth_model": m, "fit_model": m, "k": tuple(k), "plan": plan, "sim": {},
             "times_s": times_s, "vi_ref_kt": VI_REF_KT, "seed_offset": r}
            for m, k in TRUTH_CASES for r in range(runs)]


def summarize(rows, cases):
    """Per truth case, per method and T: RMS error, median stated 2σ and coverage of ΔV at
    `VI_REF_KT`, of the largest ΔV error over the flown range and of the wind; the first T
    reaching the targets; the claims in words. The constant case is the top level, the inverse
    case ``inverse_truth``."""
    summaries = []
    for m, k in TRUTH_CASES:
        mine = [c for c in cases if c["truth_model"] == m]
        if not mine:
            continue
        good = [r for r in rows if r.get("truth_model") == m and not r.get("error")]
        one = _summarize_case(good, mine[0]["times_s"], len(mine), m, k)
        one.update(plan=mine[0]["plan"], sim={**mine[0]["sim"], "model": m, "k": list(k)},
                   vi_ref_kt=VI_REF_KT)
        summaries.append(one)
    summary = summaries[0]
    if len(summaries) > 1:
        summary["inverse_truth"] = summaries[1]
    return summary


def _method_entry(sel):
    """Accuracy of one method at one T over the runs `sel` (rows with an estimate scored)."""
    est = [r for r in sel if r.get("estimate")]
    entry = {"runs": len(sel), "estimates": len(est)}
    if est:
        entry.update(
            dv_rms_err_kt=stats(est, "dv_err_kt")["rms"],
            dv_median_2sigma_kt=stats(est, "dv_2sigma_kt")["median"],
            dv_coverage=stats(est, "dv_covered")["mean"],
            dv_range_rms_err_kt=stats(est, "dv_range_err_max_kt")["rms"],
            dv_range_median_2sigma_kt=stats(est, "dv_range_2sigma_max_kt")["median"],
            dv_range_coverage=stats(est, "dv_range_covered")["mean"],
            wind_rms_err_mps=stats(est, "wind_err_mps")["rms"],
            wind_median_2sigma_mps=stats(est, "wind_2sigma_mps")["median"],
            wind_coverage=stats(est, "wind_covered")["mean"])
    return entry


def _summarize_case(rows, times_s, runs, truth_model, k):
    table = {method: {f"{T:g}": _method_entry([r for r in rows if r["method"] == method
                                                and r["T_s"] == T]) for T in times_s}
             for method in METHODS}
    reach = {m: {"dv": _first_time(table[m], times_s, "dv", DV_TOL_KT),
                 "wind": _first_time(table[m], times_s, "wind", WIND_TOL_MPS),
                 "dv_range": _first_time(table[m], times_s, "dv_range", DV_TOL_KT)}
             for m in METHODS}
    return {"study": NAME, "runs": runs, "times_s": list(times_s), "fit_model": truth_model,
            "truth_model": truth_model, "truth_k": list(k),
            "dv_tolerance_kt": DV_TOL_KT, "wind_tolerance_mps": WIND_TOL_MPS,
            "by_method": table, "time_to_tolerance_s": reach,
            "claims": _claims(reach, times_s, (("dv", DV_TOL_KT, "kt"),
                                               ("wind", WIND_TOL_MPS, "m/s"))),
            "claims_dv_range": _claims(reach, times_s, (("dv_range", DV_TOL_KT, "kt"),))}


def _first_time(per_t, times_s, what, tol):
    """The first T at which a method is accurate AND says so (its stated 2σ is within the
    tolerance) AND that statement is honest (it covers the truth in >= 80 % of runs)."""
    unit = "kt" if what.startswith("dv") else "mps"
    for T in times_s:
        e = per_t[f"{T:g}"]
        if (e["estimates"] == e["runs"] and e.get(f"{what}_rms_err_{unit}", np.inf) <= tol
                and e.get(f"{what}_median_2sigma_{unit}", np.inf) <= tol
                and e.get(f"{what}_coverage", 0.0) >= 0.8):
            return float(T)
    return None


def _claims(reach, times_s, items):
    out = []
    for what, tol, unit in items:
        ours = reach["pitotcal"][what]
        for peer in ("ardupilot", "px4"):
            theirs = reach[peer][what]
            if ours is None:
                verdict = "pitotcal never reached it within the flight"
            elif theirs is None:
                verdict = (f"pitotcal after {ours:g} s; {peer}-style never within "
                           f"{max(times_s):g} s")
            else:
                verdict = (f"pitotcal after {ours:g} s, {peer}-style after {theirs:g} s "
                           f"(fraction {ours / theirs:.2f})")
            out.append(f"{what}: RMS error and stated 2-sigma both <= {tol:g} {unit}, truth "
                       f"inside the stated 2-sigma in >= 80 % of runs: {verdict}")
    return out


def headline(summary):
    """The result in one line: the first flight time at which each method's wind and ΔV are
    within the targets (constant truth)."""
    reach = summary["time_to_tolerance_s"]

    def when(method, what):
        t = reach[method][what]
        return "never" if t is None else f"{t:g} s"

    names = {"pitotcal": "pitotcal", "ardupilot": "ArduPilot-style", "px4": "PX4-style"}
    parts = [f"{label} ±{tol:g} {unit}: " + ", ".join(f"{names[m]} {when(m, what)}"
                                                        for m in METHODS)
             for what, label, tol, unit in (("wind", "wind", WIND_TOL_MPS, "m/s"),
                                            ("dv", f"ΔV at {VI_REF_KT:g} kt", DV_TOL_KT, "kt"))]
    return "first flight time with error and stated 2σ within " + "; ".join(parts)


def plot(rows, summary, out_dir):
    figures = [plot_peers(summary, out_dir, f"{NAME}.png")]
    if "inverse_truth" in summary:
        figures.append(plot_peers(summary["inverse_truth"], out_dir, f"{NAME}-inverse.png"))
    return figures


STUDY = MonteCarloStudy(
    NAME, "pitotcal vs ArduPilot's and PX4's calibrators: accuracy and honesty vs flight time",
    peer_task, cases, summarize, plot, headline, default_runs=10, quick_runs=2, columns=COLUMNS)
