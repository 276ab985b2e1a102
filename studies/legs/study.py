"""`legs`: the classic per-point GPS leg solutions against one global fit over the same legs.

Each run flies seven calibration points (70-160 KIAS) of four legs on tracks 010/100/190/280
through a random wind (5-25 kt, any direction) with a leg error of 0.5 kt per component, and
reduces the same legs twice: per point (the 4-leg subset mean, `estimation.legs.points`) and globally
(`estimation.legs.global_fit`, one wind per band). Two cases: the bound from the leg scatter (no
accuracy stated: Student t with N − 3 = 1 degree of freedom per point) and from a stated
accuracy (`groundspeed_sd_kt`, 2σ). One table row per point per run: the true ΔV, each method's
ΔV and 95 % half-width, and whether the truth lies inside. Same legs, same flying time: the
paper's argument (one global fit beats per-point solutions) on leg data.
"""

import numpy as np

from ..engine.common import column, group, percent
from ..engine.figures import new_figure, plain_log_ticks, save
from ..engine.study import MonteCarloStudy

__all__ = ["BOUNDS", "IAS_KT", "STUDY"]

IAS_KT = (70.0, 85.0, 100.0, 115.0, 130.0, 145.0, 160.0)
TRACKS_DEG = (10.0, 100.0, 190.0, 280.0)
LEG_SD_KT = 0.5
BOUNDS = ("scatter", "stated")


def task(seed, bound):
    """One leg flight reduced per point and globally: one row per point."""
    from pitotcal.estimation.legs.points import solve_points
    from pitotcal.estimation.legs.global_fit import fit_legs
    from pitotcal.maneuvers.fly.legs import simulate_legs

    rng = np.random.default_rng(seed)
    wind_kt, wind_from = float(rng.uniform(5.0, 25.0)), float(rng.uniform(0.0, 360.0))
    legs, truth = simulate_legs(ias_kt=IAS_KT, tracks_deg=TRACKS_DEG, wind_speed_kt=wind_kt,
                                wind_from_deg=wind_from, leg_sd_kt=LEG_SD_KT,
                                state_sd=bound == "stated", seed=seed)
    points, _ = solve_points(legs)
    fit = fit_legs(legs, initial_winds={s.point: (s.wind_n_mps, s.wind_e_mps) for s in points})
    gl_dv, gl_half = fit.delta_v_kt(truth.ias_kt)
    rows = []
    for i, s in enumerate(points):
        true = float(truth.dv_kt[i])
        rows.append({
            "ias_kt": IAS_KT[i], "wind_speed_kt": wind_kt, "wind_from_deg": wind_from,
            "dv_true_kt": true, "point_dv_kt": s.dv_kt, "point_half_kt": s.dv_half_kt,
            "point_inside": bool(abs(s.dv_kt - true) <= s.dv_half_kt),
            "global_dv_kt": float(gl_dv[i]), "global_half_kt": float(gl_half[i]),
            "global_inside": bool(abs(gl_dv[i] - true) <= gl_half[i]),
            "success": bool(fit.converged)})
    return rows


def cases(runs, quick):
    return [{"bound": b, "seed_offset": r} for r in range(runs) for b in BOUNDS]


def _inside(rows, name):
    x = [r.get(name) in (True, "True") for r in rows if r.get(name) is not None]
    return float(np.mean(x)) if x else None


def summarize(rows, cases=None):
    out = {}
    for (bound,), rs in group(rows, "bound").items():
        good = [r for r in rs if not r.get("error")]
        pt, gl = column(good, "point_half_kt"), column(good, "global_half_kt")
        out[bound] = {
            "n_points": len(good),
            "coverage_point": _inside(good, "point_inside"),
            "coverage_global": _inside(good, "global_inside"),
            "median_half_point_kt": float(np.nanmedian(pt)) if good else None,
            "median_half_global_kt": float(np.nanmedian(gl)) if good else None,
            "global_narrower_share": float(np.mean(gl < pt)) if good else None,
            "rms_err_point_kt": _rms(column(good, "point_dv_kt") - column(good, "dv_true_kt")),
            "rms_err_global_kt": _rms(column(good, "global_dv_kt") - column(good, "dv_true_kt"))}
    return {"by_bound": out, "leg_sd_kt": LEG_SD_KT, "ias_kt": list(IAS_KT),
            "target_coverage": [0.90, 0.98]}


def _rms(x):
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x ** 2))) if x.size else None


def headline(summary):
    parts = []
    for bound, s in summary["by_bound"].items():
        if s["coverage_point"] is None:
            continue
        parts.append(f"{bound}: global ΔV ±{s['median_half_global_kt']:.2f} kt vs per point "
                     f"±{s['median_half_point_kt']:.2f} kt (median 95 % half-widths), coverage "
                     f"global {percent(s['coverage_global'])}, per point "
                     f"{percent(s['coverage_point'])}")
    return "; ".join(parts) if parts else "no finished run"


def plot(rows, summary, out_dir):
    """Median 95 % half-width against KIAS, per point and global, for each bound; coverage."""
    fig, ax = new_figure(1, 2, size=(5.0, 3.8))
    for bound, ls in zip(BOUNDS, ("-", "--")):
        rs = [r for r in rows if r.get("bound") == bound and not r.get("error")]
        if not rs:
            continue
        ias = column(rs, "ias_kt")
        for name, color, label in (("point_half_kt", "C3", "per point"),
                                   ("global_half_kt", "C0", "global")):
            med = [np.nanmedian(column(rs, name)[ias == v]) for v in IAS_KT]
            ax[0, 0].plot(IAS_KT, med, ls, color=color, marker="o", label=f"{label} ({bound})")
    ax[0, 0].set_yscale("log")
    plain_log_ticks(ax[0, 0])
    ax[0, 0].set_xlabel("KIAS")
    ax[0, 0].set_ylabel("median 95 % half-width of ΔV, kt")
    ax[0, 0].legend(fontsize=8, loc="center right")
    by = summary["by_bound"]
    labels = [f"{b}\n{m}" for b in by for m in ("per point", "global")]
    values = [by[b][k] or 0.0 for b in by for k in ("coverage_point", "coverage_global")]
    ax[0, 1].bar(range(len(values)), values, color=["C3", "C0"] * len(by))
    ax[0, 1].axhspan(0.90, 0.98, color="0.85", zorder=0, label="target 90-98 %")
    ax[0, 1].axhline(0.95, color="k", lw=0.8)
    ax[0, 1].set_xticks(range(len(values)), labels, fontsize=8)
    ax[0, 1].set_ylim(0.5, 1.0)
    ax[0, 1].set_ylabel("share of points with the truth inside")
    ax[0, 1].legend(fontsize=8, loc="lower right")
    fig.suptitle("GPS legs: per-point classic bounds vs one global fit (same legs)")
    return [save(fig, out_dir, "legs.png")]


STUDY = MonteCarloStudy("legs", "per-point classic GPS leg bounds vs one global fit: "
                        "half-widths and coverage", task, cases, summarize, plot, headline,
                        default_runs=100, quick_runs=3,
                        columns=("run_index", "seed", "bound", "ias_kt"))
