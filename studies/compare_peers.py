"""pitotcal against the autopilots' calibrators on the same simulated flights, versus flight time.

Each run flies one seeded simulated calibration flight (`maneuvers.plan_maneuver` +
`maneuvers.simulate`, through `studies.common.fly`), then for each flight time T uses only the
first T seconds:

- pitotcal: `estimation.identify` on [0, T] (it refuses, with ObservabilityError, while the
  track has not turned enough: recorded as "no estimate", not as an error);
- the ArduPilot-style and PX4-style filters (`studies.baselines`), run over the whole flight,
  read at time T: what the autopilot would report after T seconds.

Scored against the simulation's truth: the airspeed correction ΔV at `vi_ref_kt` and the wind
vector, each with the method's own stated 2σ (covered = truth inside it; the wind uses the
2-D 95.45 % ellipse of the stated covariance).
"""

import csv
import json
import logging
from pathlib import Path

import numpy as np

from estimation.errors import ObservabilityError, PitotcalError

from .baselines import ardupilot_autocal, px4_wind_estimator

__all__ = ["run_compare_peers", "compare_one_flight", "METHODS"]

log = logging.getLogger(__name__)

NAME = "peers"
METHODS = ("pitotcal", "ardupilot", "px4")
CHI2_2D_2SIGMA = 6.18        # chi-square(2 dof) quantile of the 2-sigma (95.45 %) probability
DEFAULT_TIMES_S = (30.0, 60.0, 120.0, 240.0, 480.0, 600.0)


def _true_dv_kt(truth, vi_kt):
    from .common import true_delta_v_kt
    m = truth["model"]
    from estimation.models import get_model
    k = [truth["parameters"][p] for p in get_model(m).params]
    return float(true_delta_v_kt(m, k, vi_kt))


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
                       vi_ref_kt=85.0):
    """Rows {method, T_s, dv_err_kt, dv_2sigma_kt, dv_covered, wind_err_mps, ...} of one flight."""
    from estimation import identify

    if not times_s or any(t <= 0 for t in times_s):
        raise PitotcalError(f"times_s must be positive seconds, got {times_s!r}")
    t0 = float(flight.time_s[0])
    dv_true = _true_dv_kt(truth, vi_ref_kt)
    w_true = (truth["wind_n_mps"], truth["wind_e_mps"])
    tracks = {"ardupilot": ardupilot_autocal(flight), "px4": px4_wind_estimator(flight)}
    rows = []
    for T in times_s:
        part = flight.window(t0, t0 + T)
        base = {"T_s": float(T), "dv_true_kt": dv_true}
        try:
            res = identify(part, model=model)
            nk = len(res.coefficients)
            dv, dv2 = res.delta_v_kt(vi_ref_kt)
            row = {**base, "method": "pitotcal", "estimate": bool(res.success), "reason": "",
                   "k1": float(res.coefficients[0]), "dv_kt": float(dv),
                   "dv_2sigma_kt": float(dv2)}
            row.update(_wind_score(res.internal_params[nk:nk + 2],
                                   res.internal_covariance[nk:nk + 2, nk:nk + 2], w_true))
        except ObservabilityError as exc:
            row = {**base, "method": "pitotcal", "estimate": False, "reason": str(exc)}
        rows.append(row)
        for name, tr in tracks.items():
            i = tr.index_at(t0 + T)
            if i < 0:
                rows.append({**base, "method": name, "estimate": False,
                             "reason": "filter not initialised"})
                continue
            a = tr.at(t0 + T, vi_kt=vi_ref_kt)
            row = {**base, "method": name, "estimate": True, "reason": "", "k1": a["k1"],
                   "dv_kt": a["dv_kt"], "dv_2sigma_kt": a["dv_2sigma_kt"]}
            row.update(_wind_score((a["wind_n_mps"], a["wind_e_mps"]),
                                   tr.covariance[i][:2, :2], w_true))
            rows.append(row)
    for row in rows:
        if row.get("estimate"):
            row["dv_err_kt"] = row["dv_kt"] - dv_true
            row["dv_covered"] = bool(abs(row["dv_err_kt"]) <= row["dv_2sigma_kt"])
    return rows


def _summarize(rows, times_s, runs, model, truth_model, k, dv_tol_kt, wind_tol_mps):
    table = {}
    for method in METHODS:
        per_t = {}
        for T in times_s:
            sel = [r for r in rows if r["method"] == method and r["T_s"] == T]
            est = [r for r in sel if r.get("estimate")]
            entry = {"runs": len(sel), "estimates": len(est)}
            if est:
                dv_err = np.array([r["dv_err_kt"] for r in est])
                w_err = np.array([r["wind_err_mps"] for r in est])
                entry.update(
                    dv_rms_err_kt=float(np.sqrt(np.mean(dv_err ** 2))),
                    dv_median_2sigma_kt=float(np.median([r["dv_2sigma_kt"] for r in est])),
                    dv_coverage=float(np.mean([r["dv_covered"] for r in est])),
                    wind_rms_err_mps=float(np.sqrt(np.mean(w_err ** 2))),
                    wind_median_2sigma_mps=float(np.median([r["wind_2sigma_mps"] for r in est])),
                    wind_coverage=float(np.mean([r["wind_covered"] for r in est])))
            per_t[f"{T:g}"] = entry
        table[method] = per_t

    def first_time(method, what, tol):
        # reached = accurate AND the method itself says so (its stated 2-sigma is within the
        # tolerance) AND that statement is honest (it covers the truth in >= 80 % of runs)
        unit = "kt" if what == "dv" else "mps"
        for T in times_s:
            e = table[method][f"{T:g}"]
            if (e["estimates"] == e["runs"] and e.get(f"{what}_rms_err_{unit}", np.inf) <= tol
                    and e.get(f"{what}_median_2sigma_{unit}", np.inf) <= tol
                    and e.get(f"{what}_coverage", 0.0) >= 0.8):
                return float(T)
        return None

    reach = {m: {"dv": first_time(m, "dv", dv_tol_kt), "wind": first_time(m, "wind", wind_tol_mps)}
             for m in METHODS}
    claims = []
    for what, tol, unit in (("dv", dv_tol_kt, "kt"), ("wind", wind_tol_mps, "m/s")):
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
            claims.append(f"{what}: RMS error and stated 2-sigma both <= {tol:g} {unit}, truth "
                          f"inside the stated 2-sigma in >= 80 % of runs: {verdict}")
    return {"study": NAME, "runs": runs, "times_s": list(times_s), "fit_model": model,
            "truth_model": truth_model, "truth_k": list(k),
            "dv_tolerance_kt": dv_tol_kt, "wind_tolerance_mps": wind_tol_mps,
            "by_method": table, "time_to_tolerance_s": reach, "claims": claims}


def run_compare_peers(out_dir, runs=10, seed=0, *, times_s=DEFAULT_TIMES_S, model="constant",
                      k=(0.05,), plan=None, sim=None, vi_ref_kt=85.0, dv_tol_kt=0.5,
                      wind_tol_mps=0.5, plot=True):
    """Monte Carlo comparison of pitotcal with the peer filters; writes peers.csv/.json/.png.

    Parameters
    ----------
    out_dir : path
    runs : int
        Seeded flights (seeds `seed`, `seed` + 1, ...).
    times_s : sequence of float
        Flight times T at which every method is scored (first T seconds).
    model, k : str, tuple
        True pressure-error structure and coefficients; pitotcal fits the same structure.
        The default (`constant`, k1 = 0.05) is the peers' own structure: the fair case for them.
    plan, sim : dict, optional
        Overrides of the plan (default: the T-2 continuous plan stretched to max(times_s)) and
        of the simulator options.
    dv_tol_kt, wind_tol_mps : float
        Accuracy targets of the time-to-accuracy claim.

    Returns
    -------
    dict
        The summary written to peers.json (per method and T: RMS error, median stated 2σ and
        coverage of ΔV and wind; the first T reaching the targets; the claims in words).
    """
    from .common import fly

    if int(runs) < 1:
        raise PitotcalError(f"runs must be >= 1, got {runs!r}")
    times_s = tuple(sorted(float(t) for t in times_s))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    plan_kw = {"duration_s": max(times_s), **(plan or {})}
    sim_kw = {"model": model, "k": tuple(k), **(sim or {})}
    rows = []
    for r in range(int(runs)):
        s = int(seed) + r
        flight, truth = fly(plan_kw, sim_kw, s)
        for row in compare_one_flight(flight, truth, times_s=times_s, model=model,
                                      vi_ref_kt=vi_ref_kt):
            rows.append({"seed": s, **row})
        log.info("peers: run %d/%d done", r + 1, runs)
    summary = _summarize(rows, times_s, int(runs), model, sim_kw["model"], sim_kw["k"],
                         dv_tol_kt, wind_tol_mps)
    summary.update(plan=plan_kw, sim=sim_kw, vi_ref_kt=vi_ref_kt)
    _write_rows(out / f"{NAME}.csv", rows)
    with open(out / f"{NAME}.json", "w") as fh:
        json.dump(summary, fh, indent=2, default=float)
    if plot:
        summary["figures"] = [str(_plot(out / f"{NAME}.png", summary))]
    return summary


def _write_rows(path, rows):
    cols = ["seed", "method", "T_s", "estimate", "k1", "dv_kt", "dv_true_kt", "dv_err_kt",
            "dv_2sigma_kt", "dv_covered", "wind_err_mps", "wind_2sigma_mps", "wind_covered",
            "reason"]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols, extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow(row)


def _plot(path, summary):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    colors = {"pitotcal": "k", "ardupilot": "C0", "px4": "C2"}
    for method in METHODS:
        tab = summary["by_method"][method]
        T = np.array([float(t) for t in tab])
        get = lambda key: np.array([tab[t].get(key, np.nan) for t in tab], dtype=float)  # noqa: E731
        c = colors[method]
        axes[0].plot(T, get("dv_rms_err_kt"), "o-", color=c, label=f"{method}: RMS error")
        axes[0].plot(T, get("dv_median_2sigma_kt"), "s--", color=c, mfc="none",
                     label=f"{method}: stated 2σ")
        axes[1].plot(T, get("wind_rms_err_mps"), "o-", color=c, label=f"{method}: RMS error")
        axes[1].plot(T, get("wind_median_2sigma_mps"), "s--", color=c, mfc="none",
                     label=f"{method}: stated 2σ")
        axes[2].plot(T, get("dv_coverage"), "o-", color=c, label=f"{method}: ΔV")
        axes[2].plot(T, get("wind_coverage"), "s--", color=c, mfc="none", label=f"{method}: wind")
    axes[0].axhline(summary["dv_tolerance_kt"], color="r", lw=0.8, ls=":")
    axes[1].axhline(summary["wind_tolerance_mps"], color="r", lw=0.8, ls=":")
    axes[2].axhline(0.9545, color="r", lw=0.8, ls=":")
    axes[0].set_ylabel(f"ΔV at {summary['vi_ref_kt']:g} kt, kt")
    axes[1].set_ylabel("wind vector, m/s")
    axes[2].set_ylabel("fraction of truths inside stated 2σ")
    axes[2].set_ylim(-0.02, 1.02)
    from matplotlib.ticker import NullFormatter, ScalarFormatter
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xticks(summary["times_s"])
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("flight time used T, s")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_yscale("log")
    axes[1].set_yscale("log")
    axes[0].legend(fontsize=6)
    axes[2].legend(fontsize=6)
    fig.suptitle(f"pitotcal vs autopilot calibrators, {summary['runs']} simulated flights "
                 f"(truth {summary['truth_model']} k={summary['truth_k']})")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
