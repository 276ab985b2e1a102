"""`sensitivity`: accuracy and 2-σ of the calibration versus one factor at a time.

Factors (the paper's "important influences" and its open questions): GPS velocity noise and
rate, transducer noise, calibration bias and scale error, turbulence intensity, data rate
5-200 Hz, wind drift during the maneuver, pneumatic lag, test-area radius and bank limit. All
other settings stay at the T-2 baseline (the simulator's realistic defaults), flown twice: in
calm air and in light turbulence (0.5 m/s), because turbulence swamps the sensor factors when
present (it is the largest error source by far). Replicate r uses
the same seed at every level of every factor (common random numbers), so a curve shows the
factor's effect rather than sampling noise.
"""

import numpy as np

from ..engine.common import accuracy_summary, group, simulate_identify_score
from ..engine.figures import new_figure, plain_log_ticks, save
from ..engine.study import MonteCarloStudy

__all__ = ["FACTORS", "STUDY"]

# name -> (where: "sim" or "plan", keyword, levels, label); wind drift is (north, 0) m/s².
FACTORS = {
    "gps_noise_mps": ("sim", "gps_noise_mps", (0.0, 0.05, 0.1, 0.2, 0.5), "GPS velocity noise, m/s"),
    "gps_rate_hz": ("sim", "gps_rate_hz", (1.0, 2.0, 5.0, 10.0, 20.0), "GPS rate, Hz"),
    "qc_noise_pa": ("sim", "qc_noise_pa", (0.1, 0.5, 1.0, 2.0, 5.0), "transducer noise, Pa"),
    "qc_bias_pa": ("sim", "qc_bias_pa", (0.0, 1.0, 2.0, 5.0, 10.0), "transducer bias, Pa"),
    "qc_scale_error": ("sim", "qc_scale_error", (0.0, 0.005, 0.01, 0.02),
                       "transducer scale error, fraction of q_c"),
    "turbulence_mps": ("sim", "turbulence_mps", (0.0, 0.25, 0.5, 1.0, 2.0), "turbulence σ, m/s"),
    "rate_hz": ("sim", "rate_hz", (5.0, 10.0, 25.0, 50.0, 100.0, 200.0), "data rate, Hz"),
    "wind_drift_mps2": ("sim", "wind_drift_mps2", (0.0, 0.002, 0.005, 0.01, 0.02),
                        "wind drift, m/s²"),
    "pneumatic_lag_s": ("sim", "pneumatic_lag_s", (0.0, 0.05, 0.1, 0.2, 0.5), "pneumatic lag, s"),
    "radius_m": ("plan", "radius_m", (550.0, 700.0, 926.0, 1200.0), "test-area radius, m"),
    "bank_max_deg": ("plan", "bank_max_deg", (20.0, 25.0, 30.0, 35.0, 45.0), "bank limit, deg"),
}


BACKGROUND_TURBULENCE_MPS = (0.0, 0.5)   # calm, light


def task(seed, factor, level, background_turbulence_mps=0.5):
    where, key, _, _ = FACTORS[factor]
    value = (level, 0.0) if key == "wind_drift_mps2" else level
    sim = {"turbulence_mps": background_turbulence_mps}
    if where == "plan":
        return simulate_identify_score(seed, plan={key: value}, sim=sim)
    return simulate_identify_score(seed, sim={**sim, key: value})


def cases(runs, quick):
    out = []
    for r in range(runs):
        for factor, (_, _, levels, _) in FACTORS.items():
            backgrounds = (0.5,) if factor == "turbulence_mps" else BACKGROUND_TURBULENCE_MPS
            for background in backgrounds:
                for level in ((levels[0], levels[-1]) if quick else levels):
                    out.append({"factor": factor, "level": float(level),
                                "background_turbulence_mps": background, "seed_offset": r})
    return out


def summarize(rows, cases=None):
    out = {}
    for (factor, background, level), rs in group(rows, "factor", "background_turbulence_mps",
                                                 "level").items():
        entry = out.setdefault(factor, {"label": FACTORS[factor][3], "levels": []})
        if factor == "turbulence_mps":
            background = None          # the factor itself
        entry["levels"].append({
            "level": level, "background_turbulence_mps": background,
            **accuracy_summary(rs, k1_err_rms="k1_err", k2_err_rms_pa="k2_err")})
    return {"factors": out}


def headline(summary):
    """The result in one line: the factor over whose levels the 2σ of ΔV changes most."""
    widest = None
    for entry in summary["factors"].values():
        for background in (None, 0.0, 0.5):
            lv = [e for e in entry["levels"] if e.get("background_turbulence_mps") == background
                  and e["dv_2sigma_max_kt"] is not None and e["dv_2sigma_max_kt"] > 0]
            if len(lv) < 2:
                continue
            lo = min(lv, key=lambda e: e["dv_2sigma_max_kt"])
            hi = max(lv, key=lambda e: e["dv_2sigma_max_kt"])
            ratio = hi["dv_2sigma_max_kt"] / lo["dv_2sigma_max_kt"]
            if widest is None or ratio > widest[0]:
                widest = (ratio, entry["label"], background, lo, hi)
    if widest is None:
        return "too few converged runs to compare the factors"
    _, label, background, lo, hi = widest
    air = "" if background is None else (" in calm air" if background == 0 else
                                         f" in {background:g} m/s turbulence")
    factor, unit = label.rsplit(", ", 1)
    return (f"2σ of ΔV changes most with {factor}{air}: {lo['dv_2sigma_max_kt']:.2g} kt at "
            f"{lo['level']:g} to {hi['dv_2sigma_max_kt']:.2g} kt at {hi['level']:g} {unit}")


def plot(rows, summary, out_dir):
    factors = summary["factors"]
    ncols = 4
    nrows = max(1, int(np.ceil(len(factors) / ncols)))
    fig, ax = new_figure(nrows, ncols, size=(3.6, 2.9))
    for a, (factor, entry) in zip(ax.flat, factors.items()):
        for background, color in ((None, "tab:blue"), (0.5, "tab:blue"), (0.0, "tab:orange")):
            lv = [e for e in entry["levels"] if e.get("background_turbulence_mps") == background]
            if not lv:
                continue
            tag = "" if background is None else (" calm" if background == 0 else " turb 0.5")
            x = np.array([e["level"] for e in lv], dtype=float)
            two = np.array([np.nan if e["dv_2sigma_max_kt"] is None else e["dv_2sigma_max_kt"]
                            for e in lv])
            err = np.array([np.nan if e["dv_err_max_kt_rms"] is None
                            else e["dv_err_max_kt_rms"] for e in lv])
            a.plot(x, two, "o-", color=color, label="2σ of ΔV" + tag)
            a.plot(x, err, "s--", color=color, label="ΔV error (rms)" + tag)
        a.set_xlabel(entry["label"])
        a.set_yscale("log")
        plain_log_ticks(a)
        if factor in ("rate_hz", "gps_rate_hz"):
            a.set_xscale("log")
            plain_log_ticks(a, "x")
        a.axhline(0.2, color="0.5", ls=":", lw=0.8)
        a.legend(fontsize=7)
    for a in list(ax.flat)[len(factors):]:
        a.set_visible(False)
    for row in ax:
        row[0].set_ylabel("ΔV, kt (largest over the speed range)")
    fig.suptitle("Sensitivity of the T-2 calibration, one factor at a time (dotted: 0.2 kt)")
    return [save(fig, out_dir, "sensitivity.png")]


STUDY = MonteCarloStudy(
    "sensitivity", "accuracy and 2σ of ΔV vs sensor, atmosphere and maneuver factors",
    task, cases, summarize, plot, headline, default_runs=5, quick_runs=1)
