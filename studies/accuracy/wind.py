"""`wind` (paper Figs. 13-14): the estimated wind against the wind actually flown through.

Each maneuver profile is planned for, and flown in, several mean winds (with the simulator's
light turbulence). The flown wind is the time-average of the air-mass velocity along the path
(the simulator's truth); the paper compared with a tethered balloon 1 nm away and found agreement
within ~0.5 kt and ~4°.
"""

import numpy as np

from pitotcal.core.units import mps_to_kt

from ..engine.common import column, group, ok_rows, percent, simulate_identify_score, stats
from ..engine.figures import new_figure, save
from ..engine.study import MonteCarloStudy

__all__ = ["PROFILES", "STUDY", "WINDS"]

PROFILES = ("step-pause", "continuous", "two-speed")
WINDS = ((2.0, 45.0), (5.0, 270.0), (8.0, 160.0), (10.0, 330.0))
QUICK_WINDS = ((5.0, 270.0),)


def task(seed, profile, wind_speed_mps, wind_from_deg):
    wind = {"wind_speed_mps": wind_speed_mps, "wind_from_deg": wind_from_deg}
    return simulate_identify_score(seed, plan={"profile": profile, **wind}, sim=wind)


def cases(runs, quick):
    winds = QUICK_WINDS if quick else WINDS
    return [{"profile": p, "wind_speed_mps": s, "wind_from_deg": d, "seed_offset": r}
            for r in range(runs) for p in PROFILES for s, d in winds]


def summarize(rows, cases=None):
    out = {}
    for (profile,), rs in group(rows, "profile").items():
        good = ok_rows(rs)
        z_s, z_d = column(good, "wind_speed_mps_z"), column(good, "wind_from_deg_z")
        out[profile] = {
            "n_runs": len(rs), "n_ok": len(good),
            "speed_err_rms_kt": _kt(stats(good, "wind_speed_mps_err")["rms"]),
            "speed_err_max_kt": _kt(_absmax(column(good, "wind_speed_mps_err"))),
            "direction_err_rms_deg": stats(good, "wind_from_deg_err")["rms"],
            "direction_err_max_deg": _absmax(column(good, "wind_from_deg_err")),
            "speed_2sigma_median_kt": _kt(_twice(stats(good, "wind_speed_mps_std")["median"])),
            "direction_2sigma_median_deg": _twice(stats(good, "wind_from_deg_std")["median"]),
            "inside_2sigma": _frac(np.concatenate([np.abs(z_s) <= 2, np.abs(z_d) <= 2]),
                                   np.concatenate([z_s, z_d]))}
    return {"by_profile": out,
            "paper_agreement": {"speed_kt": 0.5, "direction_deg": 4.0,
                                "note": "paper: OE vs tethered balloon 1 nm away"}}


def headline(summary):
    """The result in one line: the worst RMS errors over the profiles, and the coverage."""
    by = summary["by_profile"].values()
    speed = [e["speed_err_rms_kt"] for e in by if e["speed_err_rms_kt"] is not None]
    direction = [e["direction_err_rms_deg"] for e in by if e["direction_err_rms_deg"] is not None]
    inside = [e["inside_2sigma"] for e in by if e["inside_2sigma"] is not None]
    if not speed or not direction or not inside:
        return "no converged run to compare with the flown wind"
    paper = summary["paper_agreement"]
    share = (percent(min(inside)) if min(inside) == max(inside)
             else f"{percent(min(inside))}-{percent(max(inside))}")
    return (f"estimated vs flown wind within {max(speed):.2f} kt and {max(direction):.1f}° RMS "
            f"(worst profile), truth inside 2σ in {share} of the estimates "
            f"(paper: {paper['speed_kt']:g} kt, {paper['direction_deg']:g}°)")


def _kt(v_mps):
    return None if v_mps is None else float(mps_to_kt(v_mps))


def _twice(v):
    return None if v is None else 2.0 * v


def _absmax(x):
    x = x[np.isfinite(x)]
    return float(np.max(np.abs(x))) if x.size else None


def _frac(mask, values):
    keep = np.isfinite(values)
    return float(np.mean(mask[keep])) if keep.any() else None


def plot(rows, summary, out_dir):
    """Estimate minus flown wind (±2σ bars) against the flown wind, with the paper's agreement
    (±0.5 kt, ±4°) dotted: errors are what a 1:1 plot would hide at this scale."""
    good = ok_rows(rows)
    fig, ax = new_figure(1, 2, size=(4.8, 3.8))
    for i, (profile, marker) in enumerate(zip(PROFILES, "osD")):
        rs = [r for r in good if r.get("profile") == profile]
        if not rs:
            continue
        jitter = (i - 1) * 0.12
        for a, p, scale, spread in ((ax[0, 0], "wind_speed_mps", float(mps_to_kt(1.0)), 1.0),
                                    (ax[0, 1], "wind_from_deg", 1.0, 25.0)):
            true, err, std = column(rs, f"{p}_true"), column(rs, f"{p}_err"), column(rs, f"{p}_std")
            a.errorbar(true * (scale if p == "wind_speed_mps" else 1.0) + jitter * spread,
                       err * scale, yerr=2 * std * scale, fmt=marker, ms=4, capsize=2,
                       alpha=0.8, label=profile)
    for a, xlabel, ylabel, band in (
            (ax[0, 0], "flown (time-average) wind speed, kt", "estimated - flown, kt ± 2σ", 0.5),
            (ax[0, 1], "flown (time-average) wind from, deg", "estimated - flown, deg ± 2σ", 4.0)):
        a.axhline(0.0, color="k", lw=0.8)
        for b in (-band, band):
            a.axhline(b, color="0.5", ls=":", lw=0.8)
        a.set_xlabel(xlabel)
        a.set_ylabel(ylabel)
        a.legend(fontsize=8)
    fig.suptitle("Estimated vs flown wind, per maneuver (paper Figs. 13-14; dotted: the paper's "
                 "agreement with a balloon)")
    return [save(fig, out_dir, "wind.png")]


STUDY = MonteCarloStudy("wind", "estimated vs flown wind speed and direction, per maneuver",
                        task, cases, summarize, plot, headline, default_runs=5, quick_runs=1)
