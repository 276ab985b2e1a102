"""The `peers` study's figure: error, stated 2σ and coverage of each method versus flight time."""

import numpy as np

from ..engine.figures import new_figure, plain_log_ticks, save

__all__ = ["plot_peers"]

COLORS = {"pitotcal": "k", "ardupilot": "C0", "px4": "C2"}


def plot_peers(summary, out_dir, filename):
    """Four panels over flight time T (log): ΔV at the reference speed, ΔV over the flown
    range, the wind vector (RMS error and median stated 2σ each), and the coverage of all
    three. `summary` is one truth case of the `peers` summary."""
    from matplotlib.ticker import NullFormatter

    fig, axes = new_figure(1, 4, size=(4.5, 4.4))
    axes = axes[0]
    for method, c in COLORS.items():
        tab = summary["by_method"][method]
        T = np.array([float(t) for t in tab])

        def get(key, tab=tab):
            return np.array([tab[t].get(key, np.nan) for t in tab], dtype=float)

        for ax, what in ((axes[0], "dv"), (axes[1], "dv_range")):
            ax.plot(T, get(f"{what}_rms_err_kt"), "o-", color=c, label=f"{method}: RMS error")
            ax.plot(T, get(f"{what}_median_2sigma_kt"), "s--", color=c, mfc="none",
                    label=f"{method}: stated 2σ")
        axes[2].plot(T, get("wind_rms_err_mps"), "o-", color=c, label=f"{method}: RMS error")
        axes[2].plot(T, get("wind_median_2sigma_mps"), "s--", color=c, mfc="none",
                     label=f"{method}: stated 2σ")
        axes[3].plot(T, get("dv_coverage"), "o-", color=c, label=f"{method}: ΔV at ref.")
        axes[3].plot(T, get("dv_range_coverage"), "^:", color=c, label=f"{method}: ΔV, all V_i")
        axes[3].plot(T, get("wind_coverage"), "s--", color=c, mfc="none", label=f"{method}: wind")
    for ax, level in ((axes[0], summary["dv_tolerance_kt"]), (axes[1], summary["dv_tolerance_kt"]),
                      (axes[2], summary["wind_tolerance_mps"]), (axes[3], 0.9545)):
        ax.axhline(level, color="r", lw=0.8, ls=":")
    axes[0].set_ylabel(f"ΔV at V_i = {summary['vi_ref_kt']:g} kt: error, stated 2σ; kt")
    axes[1].set_ylabel("ΔV over the flown V_i range: largest error, 2σ; kt")
    axes[2].set_ylabel("wind vector: error, stated 2σ; m/s")
    axes[3].set_ylabel("fraction of runs with truth inside stated 2σ")
    axes[3].set_ylim(-0.02, 1.02)
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xticks(summary["times_s"])
        plain_log_ticks(ax, "x")
        ax.xaxis.set_minor_formatter(NullFormatter())      # the T ticks only
        ax.set_xlabel("flight time used T, s")
        ax.grid(True, which="both", alpha=0.3)
    for ax in axes[:3]:
        ax.set_yscale("log")
        plain_log_ticks(ax)
    axes[0].legend(fontsize=6)
    axes[3].legend(fontsize=6)
    k = ", ".join(f"{v:g}" for v in summary["truth_k"])
    fig.suptitle(f"pitotcal ({summary['fit_model']} fit) vs autopilot calibrators (one scale), "
                 f"{summary['runs']} simulated flights, truth {summary['truth_model']} k = ({k}); "
                 f"dotted red: tolerance / nominal 95.45 %")
    return save(fig, out_dir, filename)
