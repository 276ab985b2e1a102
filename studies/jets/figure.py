"""The `jets` study's figure: Δp_p/p_s against M_ic for each test point (output error with its
2σ band, the self-survey's bins with 2σ, JMOSS's curve when given), and each method's wind and
OAT minus the radiosonde's."""

import numpy as np

from ..engine.figures import save

__all__ = ["plot_jets"]

_STYLE = {"output_error": ("C0", "output error (Mach spline, r fitted)"),
          "self_survey": ("C1", "self-survey"), "jmoss": ("C3", "JMOSS")}


def plot_jets(out_dir, filename, points):
    """One panel per test point and one of the misses against the radiosonde; the path."""
    from matplotlib.figure import Figure

    n = max(len(points), 1)
    fig = Figure(figsize=(4.6 * n + 4.2, 5.2), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, n + 1, gridspec_kw={"width_ratios": [1.0] * n + [0.8]}))
    for ax, p in zip(axes[:-1], points):
        _curves(ax, p)
    _misses(axes[-1], points)
    return save(fig, out_dir, filename)


def _curves(ax, p):
    col, label = _STYLE["output_error"]
    m = np.array([s["mach_ic"] for s in p["spe"]])
    v = np.array([s["dpp_ps"] for s in p["spe"]])
    w = np.array([s["dpp_ps_2sigma"] for s in p["spe"]])
    ax.plot(m, v, col, lw=2, label=f"{label}, r = {p['recovery']:.3f}")
    ax.fill_between(m, v - w, v + w, color=col, alpha=0.2, lw=0)
    ss = p["self_survey"]
    col, label = _STYLE["self_survey"]
    ax.errorbar([s["mach_ic"] for s in ss["spe"]], [s["dpp_ps"] for s in ss["spe"]],
                yerr=[s["dpp_ps_2sigma"] for s in ss["spe"]], fmt="o", ms=3, color=col,
                elinewidth=0.8, label=f"{label} (bins ±2σ), r = {ss['recovery']:.3f}")
    if "jmoss" in p:
        col, label = _STYLE["jmoss"]
        jm = p["jmoss"]
        ax.plot([s["mach_ic"] for s in jm["spe"]], [s["dpp_ps"] for s in jm["spe"]], col,
                ls="--", lw=1.5, label=f"{label}, its r = {jm['recovery']:.2f}")
    ours = np.concatenate([v - w, v + w, [s["dpp_ps"] for s in ss["spe"]]])
    pad = 0.1 * (np.max(ours) - np.min(ours))
    # JMOSS's polynomial runs off above M_ic 0.97: the scale is ours
    ax.set_ylim(np.min(ours) - pad, np.max(ours) + pad)
    ax.set_title(f"{p['name']}, {p['altitude_ft']:,.0f} ft")
    ax.set_xlabel("M_ic")
    ax.set_ylabel("Δp_p / p_s")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")


def _misses(ax, points):
    """Wind miss (kt) and OAT − sonde (K) per point and method."""
    have = [p for p in points if "radiosonde" in p]
    if not have:
        ax.text(0.5, 0.5, "no radiosonde (WB.txt)", ha="center", transform=ax.transAxes)
        ax.set_axis_off()
        return
    methods = [("output_error", lambda p: p), ("self_survey", lambda p: p["self_survey"]),
               ("jmoss", lambda p: p.get("jmoss"))]
    x = np.arange(len(have))
    for i, (name, get) in enumerate(methods):
        col, label = _STYLE[name]
        wind = [(get(p) or {}).get("wind_miss_kt", np.nan) for p in have]
        oat = [(get(p) or {}).get("oat_minus_sonde_k", np.nan) for p in have]
        ax.plot(x + 0.12 * (i - 1), wind, "o", color=col, label=f"{label}: wind miss, kt")
        ax.plot(x + 0.12 * (i - 1), oat, "s", mfc="none", color=col,
                label=f"{label}: OAT − sonde, K")
    for level in (-4.0, 4.0):
        ax.axhline(level, color="0.5", ls=":", lw=1)
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.set_xticks(x, [p["name"] for p in have])
    ax.set_xlim(-0.5, len(have) - 0.5)
    ax.set_title("against the radiosonde (±4 dotted)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=1)
