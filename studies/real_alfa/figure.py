"""The `real-alfa` study's figure: k1, wind speed and wind direction over the real flight, from
pitotcal (one value ± 2σ), the peer filters (over time) and the autopilot's own log."""

import numpy as np

from ..peers.baselines import k1_from_ardupilot_ratio
from ..engine.figures import save

__all__ = ["plot_real_flight"]


def plot_real_flight(path, summary, ardupilot, px4, autopilot, segment_s):
    """Three panels over time since the first sample; the powered segment shaded, the engine
    failure dotted. Wind directions are shown in [0, 360) (a track broken where it wraps)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 9), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    c = summary["pitotcal"]["constant"]
    peers = ((ardupilot, "C0"), (px4, "C2"))

    ax = axes[0]
    ax.plot(autopilot["ratio_t"], k1_from_ardupilot_ratio(autopilot["ratio"]), "C3", lw=2,
            label=f"autopilot ARSPD_RATIO {summary['autopilot']['ratio']:.3f}")
    for tr, col in peers:
        ax.plot(tr.time_s, tr.k1, col, label=f"{tr.name}-style filter (±2σ)")
        ax.fill_between(tr.time_s, tr.k1 - 2 * tr.k1_std, tr.k1 + 2 * tr.k1_std, color=col,
                        alpha=0.15)
    _band(ax, c["k1"]["value"], c["k1"]["2sigma"],
          f"pitotcal constant k1 = {c['k1']['value']:.3f} ± {c['k1']['2sigma']:.3f}")
    ax.set_ylabel("k1 = Δp/q_c")

    ax = axes[1]
    ax.plot(autopilot["wind_t"], autopilot["wind_speed"], "C3", lw=2, label="autopilot WIND")
    for tr, col in peers:
        ax.plot(tr.time_s, tr.wind_speed_mps, col, label=f"{tr.name}-style filter")
    _band(ax, c["wind_speed_mps"]["value"], c["wind_speed_mps"]["2sigma"], "pitotcal ±2σ")
    ax.set_ylabel("wind speed, m/s")

    ax = axes[2]
    ax.plot(*_wrapped_with_breaks(autopilot["wind_t"], autopilot["wind_from"]), "C3", lw=2,
            label="autopilot WIND")
    for tr, col in peers:
        ax.plot(*_wrapped_with_breaks(tr.time_s, tr.wind_from_deg), col,
                label=f"{tr.name}-style filter")
    _direction_band(ax, c["wind_from_deg"]["value"], c["wind_from_deg"]["2sigma"])
    ax.set_ylim(0.0, 360.0)
    ax.set_yticks(np.arange(0.0, 361.0, 45.0))
    ax.set_ylabel("wind from, deg")
    ax.set_xlabel("time since first sample, s")
    for ax in axes:
        ax.axvspan(segment_s[0], segment_s[1], color="y", alpha=0.07)
        ax.axvline(summary["failure_time_s"], color="r", ls=":", lw=1)
        ax.legend(fontsize=7, loc="best")
    axes[0].set_title("ALFA Carbon-Z: powered segment (shaded) before the engine failure "
                      "(dotted)")
    return save(fig, path.parent, path.name)


def _band(ax, value, two_sigma, label):
    ax.axhline(value, color="k", lw=2, label=label)
    ax.axhspan(value - two_sigma, value + two_sigma, color="k", alpha=0.15)


def _direction_band(ax, value, two_sigma):
    """pitotcal's direction ± 2σ in [0, 360): a band crossing north is drawn as two pieces."""
    value = value % 360.0
    ax.axhline(value, color="k", lw=2, label="pitotcal ±2σ")
    lo, hi = value - two_sigma, value + two_sigma
    ax.axhspan(max(lo, 0.0), min(hi, 360.0), color="k", alpha=0.15)
    if lo < 0.0:
        ax.axhspan(lo + 360.0, 360.0, color="k", alpha=0.15)
    if hi > 360.0:
        ax.axhspan(0.0, hi - 360.0, color="k", alpha=0.15)


def _wrapped_with_breaks(t, deg):
    """Directions in [0, 360) with a gap (NaN) where a track crosses north, so the line does not
    run across the whole axis."""
    t = np.asarray(t, dtype=float)
    deg = np.asarray(deg, dtype=float) % 360.0
    jump = np.flatnonzero(np.abs(np.diff(deg)) > 180.0) + 1
    return np.insert(t, jump, np.nan), np.insert(deg, jump, np.nan)
