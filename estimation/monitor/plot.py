"""The monitor's figure in the manner of the paper's Fig. 15: measured against predicted q_ci
with the flagged samples in red, and panels of the flight condition and of the tests."""


from pitotcal.core.units import mps_to_kt, wind_polar

__all__ = ["plot"]


def plot(result, path=None):
    """Four panels: q_ci measured (flagged red) and predicted; altitude; ground speed and the
    tracked wind; the four CUSUM statistics over their thresholds. Returns the Figure."""
    from matplotlib.figure import Figure  # no pyplot: no GUI backend, safe in workers

    fig = Figure(figsize=(12, 8), layout="constrained")
    ax_q, ax_alt, ax_gs, ax_s = fig.subplots(2, 2).ravel()
    t, flag = result.time_s, result.flagged
    ax_q.plot(t, result.qci_pa, color="0.55", lw=0.6, label="measured q_ci")
    ax_q.plot(t, result.predicted_pa, color="C0", lw=1.0, label="predicted from GPS + calibration")
    if flag.any():
        ax_q.plot(t[flag], result.qci_pa[flag], ".", color="red", ms=2, label="flagged")
    ax_q.set_ylabel("impact pressure q_ci, Pa")
    ax_q.legend(fontsize=8, loc="best")
    extra = result.extra
    if extra.get("alt_m") is not None:
        ax_alt.plot(t, extra["alt_m"], color="C2", lw=0.8)
    ax_alt.set_ylabel("altitude, m")
    if extra.get("groundspeed_mps") is not None:
        ax_gs.plot(t, mps_to_kt(extra["groundspeed_mps"]), color="C1", lw=0.8, label="ground speed")
    b = result.blocks
    speed, _ = wind_polar(b["wind_n_mps"], b["wind_e_mps"])
    ax_gs.plot(b["time_s"], mps_to_kt(speed), color="C4", lw=1.0, label="tracked wind speed")
    ax_gs.set_ylabel("kt")
    ax_gs.legend(fontsize=8, loc="best")
    for s, color in zip(("low", "high", "still", "erratic", "ramp"),
                        ("C3", "C1", "C0", "C5", "C2")):
        ax_s.plot(b["time_s"], b[s] / result.plan["h"][s], color=color, lw=0.9, label=s)
    ax_s.axhline(1.0, color="k", ls="--", lw=0.8)
    ax_s.set_ylabel("statistic / threshold")
    ax_s.set_ylim(0, 1.6)
    ax_s.legend(fontsize=8, ncols=5, loc="upper left")
    for ax in (ax_q, ax_alt, ax_gs, ax_s):
        ax.set_xlabel("time, s")
        ax.grid(alpha=0.3)
        for a in result.alarms:
            ax.axvspan(a["start_s"], a["end_s"], color="red", alpha=0.08)
    kinds = ", ".join(f"{a['kind']} at {a['start_s']:.1f} s" for a in result.alarms) or "none"
    fig.suptitle(f"Airspeed monitor: {result.source} — alarms: {kinds}", fontsize=12)
    if path is not None:
        from pitotcal.io.atomic import save_figure

        save_figure(fig, path, dpi=110)
    return fig


