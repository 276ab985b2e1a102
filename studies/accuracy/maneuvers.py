"""`maneuvers` (paper Figs. 10-11): step-and-pause vs continuous vs two-speed, 70-100 KCAS.

For each profile and flight time the maneuver is planned (T-2 case otherwise), flown and
identified; a replicate uses the same seed for every profile and time (common random numbers),
so the curves differ by the maneuver, not by the luck of the draw. A profile that cannot be
planned in that time is a row with the planner's message.
"""

import numpy as np

from ..engine.common import accuracy_summary, group, simulate_identify_score
from ..engine.figures import new_figure, plain_log_ticks, save
from ..engine.study import MonteCarloStudy

__all__ = ["DURATIONS_S", "PROFILES", "STUDY"]

PROFILES = ("step-pause", "continuous", "two-speed")
DURATIONS_S = (180.0, 210.0, 240.0, 300.0, 360.0, 480.0)
QUICK_DURATIONS_S = (240.0,)


def task(seed, profile, duration_s):
    return simulate_identify_score(seed, plan={"profile": profile, "duration_s": duration_s})


def cases(runs, quick):
    durations = QUICK_DURATIONS_S if quick else DURATIONS_S
    return [{"profile": p, "duration_s": d, "seed_offset": r}
            for r in range(runs) for p in PROFILES for d in durations]


def summarize(rows, cases=None):
    out = {}
    for (profile, duration), rs in group(rows, "profile", "duration_s").items():
        out.setdefault(profile, {})[str(int(duration))] = accuracy_summary(
            rs, wind_from_err_rms_deg="wind_from_deg_err")
    return {"by_profile": out, "best_at_240s": _best(out, "240")}


def headline(summary):
    """The result in one line: the profile with the tightest 2σ of ΔV at 240 s, and the others."""
    best = summary["best_at_240s"]
    if best is None:
        return "no profile gave a converged calibration at 240 s"
    at_240 = [(p, v["240"]["dv_2sigma_max_kt"]) for p, v in summary["by_profile"].items()
              if "240" in v and v["240"]["dv_2sigma_max_kt"] is not None]
    others = ", ".join(f"{p} {dv:.2f}" for p, dv in at_240)
    return f"at 240 s {best} gives the tightest 2σ of ΔV ({others} kt)"


def _best(by_profile, duration):
    """The profile with the smallest median 2σ of ΔV at this flight time, or None."""
    scored = [(v[duration]["dv_2sigma_max_kt"], p) for p, v in by_profile.items()
              if duration in v and v[duration]["dv_2sigma_max_kt"] is not None]
    return min(scored)[1] if scored else None


def plot(rows, summary, out_dir):
    return [save(figure(summary), out_dir, "maneuvers.png")]


def figure(summary):
    """2σ of ΔV and the ΔV error versus flight time, per profile (log axes, plain labels)."""
    fig, ax = new_figure(1, 2, size=(5.0, 3.8))
    for profile, marker in zip(PROFILES, "osD"):
        entry = summary["by_profile"].get(profile, {})
        t = sorted(float(k) for k in entry)
        two_sigma = [entry[str(int(x))]["dv_2sigma_max_kt"] for x in t]
        err = [entry[str(int(x))]["dv_err_max_kt_rms"] for x in t]
        ax[0, 0].plot(t, _nan(two_sigma), marker + "-", label=profile)
        ax[0, 1].plot(t, _nan(err), marker + "-", label=profile)
    # two-line labels: one line is taller than the panel and runs into the title
    ax[0, 0].set_ylabel("2σ of ΔV, kt\n(largest over the speed range)")
    ax[0, 1].set_ylabel("ΔV error vs truth, kt\n(rms over runs of the largest)")
    for a in ax.flat:
        a.set_xlabel("flight time, s")
        a.set_yscale("log")
        plain_log_ticks(a)
        a.axhline(0.2, color="0.5", ls=":", lw=0.8)
        a.legend(fontsize=8)
    fig.suptitle("Calibration maneuvers, 70-100 KCAS (dotted: the paper's 0.2 kt)")
    return fig


def _nan(values):
    return np.array([np.nan if v is None else v for v in values], dtype=float)


STUDY = MonteCarloStudy(
    "maneuvers", "step-pause vs continuous vs two-speed: 2σ of ΔV and error vs time",
    task, cases, summarize, plot, headline, default_runs=10, quick_runs=1)
