"""`noise`: do the 2σ bounds hold, and how wide are they, when the noise has several time scales?

Every run flies the T-2 continuous maneuver (as `coverage`) under one of four noise cases and
identifies the inverse model: GPS velocity noise 0.5 m/s in 0.5 m/s turbulence
(two time scales), calm air with a Gauss-Markov GPS velocity error (σ 0.05 m/s, τ 30 s, on top
of the default white 0.05 m/s) identified without and with that error stated
(`identify(gps_error_sigma_mps=, gps_error_tau_s=)`), the `coverage` study's 1 m/s
turbulence and the default 0.5 m/s. Per case it reports the coverage of every parameter and of the ΔV table rows (the
truth inside ±2σ), the rms z-score (1 when the σ are right, not merely safe), the median 2σ
(how sharp they are) and the 90th percentile over flights of the largest ΔV 2σ (how steady).

The true wind is the mean wind the air mass was given (the process mean): the bounds count
the gusts, and their average over the flight, as error, so that is what they cover. The
average of the wind actually flown through already contains that gust average; z-scores
against it are kept as ``P_z_flown`` (they are smaller: the bounds look 1.3-1.6x too wide).
"""

import numpy as np

from ..engine.common import column, ok_rows, percent
from .coverage import PARAMETERS, run_scored, wilson_interval
from ..engine.figures import new_figure, save
from ..engine.study import MonteCarloStudy

__all__ = ["IDENTIFY_OPTIONS", "NOISE_CASES", "STUDY"]

_GM = {"turbulence_mps": 0.0, "gps_gm_sigma_mps": 0.05, "gps_gm_tau_s": 30.0}
# name -> simulate's options
NOISE_CASES = {
    "gps-noise-turbulence": {"gps_noise_mps": 0.5, "turbulence_mps": 0.5},
    "gauss-markov-gps-calm": _GM,
    "gauss-markov-gps-stated": _GM,
    "turbulence": {"turbulence_mps": 1.0},
    "turbulence-0.5": {"turbulence_mps": 0.5},
}
# name -> identify's options (the rest: the defaults)
IDENTIFY_OPTIONS = {"gauss-markov-gps-stated": {"gps_error_sigma_mps": 0.05,
                                                "gps_error_tau_s": 30.0}}

def task(seed, noise_case, engine="own"):
    sim = dict(NOISE_CASES[noise_case])
    if engine != "own":
        sim["engine"] = engine
    return run_scored(seed, sim, **IDENTIFY_OPTIONS.get(noise_case, {}))


def cases(runs, quick):
    # common random numbers: run r of every case uses the same seed
    return [{"noise_case": name, "seed_offset": r} for r in range(runs) for name in NOISE_CASES]


def summarize(rows, cases=None):
    out = {"cases": {}}
    for name in NOISE_CASES:
        good = ok_rows([r for r in rows if r.get("noise_case") == name])
        if good:
            out["cases"][name] = case_summary(good)
    return out


def case_summary(good):
    """Coverage per parameter and of the ΔV table rows, rms z and median 2σ of one case."""
    params, zs = {}, []
    for name in PARAMETERS:
        z = column(good, f"{name}_z")
        z = z[np.isfinite(z)]
        std = column(good, f"{name}_std")
        zs.append(z)
        params[name] = {"coverage_2sigma": float(np.mean(np.abs(z) <= 2.0)) if z.size else None,
                        "coverage_2sigma_interval95": wilson_interval(np.abs(z) <= 2.0),
                        "rms_z": float(np.sqrt(np.mean(z ** 2))) if z.size else None,
                        "median_2sigma": float(2.0 * np.nanmedian(std)), "n": int(z.size)}
        flown = column(good, f"{name}_z_flown")
        flown = flown[np.isfinite(flown)]
        if flown.size:
            params[name]["rms_z_flown"] = float(np.sqrt(np.mean(flown ** 2)))
            params[name]["coverage_2sigma_flown"] = float(np.mean(np.abs(flown) <= 2.0))
    rows_in = column(good, "dv_inside_2sigma")
    allz = np.concatenate(zs)
    return {"n_runs_used": len(good), "parameters": params,
            "rows_inside_2sigma": float(np.nanmean(rows_in)),
            "rms_z": float(np.sqrt(np.mean(allz ** 2))) if allz.size else None,
            "median_dv_2sigma_max_kt": float(np.nanmedian(column(good, "dv_2sigma_max_kt"))),
            # the wide tail of the bands: how steady the noise model is from flight to flight
            "p90_dv_2sigma_max_kt": float(np.nanpercentile(column(good, "dv_2sigma_max_kt"), 90))}


def headline(summary):
    """Per case: the lowest and highest parameter coverage, the rows inside, the rms z."""
    parts = []
    for name, case in summary.get("cases", {}).items():
        cov = [p["coverage_2sigma"] for p in case["parameters"].values()
               if p["coverage_2sigma"] is not None]
        parts.append(f"{name}: parameters {percent(min(cov))}-{percent(max(cov))}, rows "
                     f"{percent(case['rows_inside_2sigma'])}, rms z {case['rms_z']:.2f}")
    if not parts:
        return f"no run of {summary.get('n_runs', 0)} converged: no coverage to report"
    return "truth inside ±2σ: " + "; ".join(parts)


def plot(rows, summary, out_dir):
    return [save(figure(summary), out_dir, "noise.png")]


def figure(summary):
    """Coverage of each parameter per case, against the nominal 95.4%."""
    fig, ax = new_figure(1, 1, size=(7.0, 4.0))
    a = ax[0, 0]
    names = list(summary.get("cases", {}))
    width = 0.8 / max(len(PARAMETERS), 1)
    pos = np.arange(len(names))
    for i, p in enumerate(PARAMETERS):
        cov = [summary["cases"][n]["parameters"][p]["coverage_2sigma"] or 0.0 for n in names]
        a.bar(pos + (i - 1.5) * width, cov, width, label=p)
    a.axhspan(0.90, 0.98, color="0.9", zorder=0, label="target 90-98%")
    a.axhline(0.9545, color="k", ls="--", lw=0.8, label="nominal 95.4%")
    a.set_xticks(pos, [n.replace("-gps-", "-gps\n").replace("-turb", "\nturb") for n in names],
                 fontsize=8)
    lowest = min([c for n in names for c in (summary["cases"][n]["parameters"][p]
                                             ["coverage_2sigma"] for p in PARAMETERS)
                  if c is not None], default=1.0)
    a.set_ylim(min(0.8, lowest - 0.02), 1.01)      # zoomed: the differences show
    a.set_ylabel("fraction of truths inside ±2σ")
    a.legend(fontsize=7, loc="lower center", bbox_to_anchor=(0.5, 1.0), ncols=3)
    return fig


STUDY = MonteCarloStudy(
    "noise", "2-σ coverage and sharpness under noise of several time scales",
    task, cases, summarize, plot, headline, default_runs=100, quick_runs=1,
    engines=("own", "jsbsim"))
