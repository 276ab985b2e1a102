"""Parts of the pilot card: the lines an optimal design, alternating turns or a prior
calibration add (KIAS targets), and the card as a picture: the speed and bank traces, a track
sketch, and the card's text.

The sketch is what a pilot sets up from: the test-area circle, the planned ground track, the
start point, north up, and the wind arrow (blowing from where the settings say).
"""

import numpy as np

from pitotcal.core.scenario import CAS_TOLERANCE_KT
from pitotcal.core.units import m_to_ft, mps_to_kt
from pitotcal.io.atomic import save_figure

__all__ = ["PNG_OPTIONS", "calibration_lines", "design_lines", "draw_card",
           "draw_track_sketch", "kias_targets", "turn_text"]

# The plan's PNGs (card and plan figure): zlib level 1 encodes them in about a third of the
# default level's time (0.18 against 0.27 s for the plan figure) for files 7 % larger
PNG_OPTIONS = {"dpi": 110, "pil_kwargs": {"compress_level": 1}}


def draw_card(plan, text, png_path):
    """Write the card PNG: traces (top left), text (below) and, for a geo-referenced plan
    (``center_lat_deg`` in the settings: a card to set up from), a track sketch (top right);
    without it the card is what it was (and costs no more to draw)."""
    sketch = "center_lat_deg" in plan.settings
    from matplotlib.figure import Figure

    rows = text.splitlines()
    height = 2.9 + 0.135 * len(rows)
    fig = Figure(figsize=(8.27, height))
    # top: the speed trace with its tolerance band, what the pilot is judged against
    ax = fig.add_axes([0.09, 1 - 2.1 / height, 0.55 if sketch else 0.8, 1.8 / height])
    kt = mps_to_kt(plan.cas_mps)
    ax.fill_between(plan.time_s, kt - CAS_TOLERANCE_KT, kt + CAS_TOLERANCE_KT,
                    color="tab:blue", alpha=0.2, label=f"±{CAS_TOLERANCE_KT:.0f} KCAS")
    ax.plot(plan.time_s, kt, color="tab:blue", label="target KCAS")
    ax2 = ax.twinx()
    ax2.plot(plan.time_s, plan.bank_deg, color="tab:red", lw=0.8, label="bank")
    ax2.set_ylabel("bank, deg (+right)", color="tab:red")
    ax.set_xlabel("time, s")
    ax.set_ylabel("KCAS")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    if sketch:
        # square in inches: 1.8 in tall, 1.8 in wide
        draw_track_sketch(fig.add_axes([0.76, 1 - 2.1 / height, 1.8 / 8.27, 1.8 / height]),
                          plan)
    fig.text(0.04, 1 - 2.65 / height, text, family="monospace", fontsize=8, va="top")
    save_figure(fig, png_path, **PNG_OPTIONS)


def draw_track_sketch(ax, plan):
    """Test-area circle, ground track (thousands of feet from the centre, north up), start
    point, and the wind arrow."""
    s = plan.settings
    kft = 1e-3 * m_to_ft(1.0)
    east, north = plan.east_m * kft, plan.north_m * kft
    radius = float(s.get("radius_m", np.hypot(plan.north_m, plan.east_m).max())) * kft
    a = np.linspace(0, 2 * np.pi, 181)
    ax.plot(radius * np.sin(a), radius * np.cos(a), color="0.5", lw=0.8)
    ax.plot(east, north, color="tab:blue", lw=0.7)
    ax.plot(east[0], north[0], "o", color="tab:green", ms=4)
    ax.plot(0, 0, "+", color="k", ms=6)
    wind = float(s.get("wind_speed_mps", 0.0))
    if round(float(mps_to_kt(wind))) > 0:
        to = np.radians(float(s.get("wind_from_deg", 0.0)) + 180.0)
        length = 0.5 * radius
        x0, y0 = -0.5 * length * np.sin(to), -0.5 * length * np.cos(to)
        ax.annotate("", xy=(x0 + length * np.sin(to), y0 + length * np.cos(to)),
                    xytext=(x0, y0), arrowprops={"arrowstyle": "->", "color": "tab:gray"})
        ax.text(0.02, 0.02, f"wind {mps_to_kt(wind):.0f} kt", transform=ax.transAxes,
                fontsize=6, color="tab:gray")
    ax.set_aspect("equal")
    ax.set_xlim(-1.1 * radius, 1.1 * radius)
    ax.set_ylim(-1.1 * radius, 1.1 * radius)
    ax.set_title("track, kft, N up (green: start)", fontsize=7, y=1.0)     # y: as plot_plan
    ax.tick_params(labelsize=6)


def kias_targets(plan):
    """Indicated airspeed (kt) at each node with a prior calibration in the settings (model,
    coefficients): what the uncalibrated indicator shows at the KCAS target; None without."""
    cal = plan.settings.get("calibration")
    if not cal:
        return None
    from pitotcal.core.airdata import airspeed_law
    from pitotcal.core.measurement import isa_air
    from pitotcal.core.models import get_model, qci_from_qc_pa

    # the true q_c of the plan's TAS in the calibration's air data (the standard law for a
    # compressible one, ½ρV_t² for the paper's eq. 2), what the probe then reads, and the
    # airspeed an indicator shows for it by the same law
    mode = cal.get("air_data", "incompressible")
    qc = isa_air(plan.alt_m, mode).qc_pa(plan.tas_mps ** 2)
    qci = qci_from_qc_pa(get_model(cal["model"]), cal["k"], qc)
    return mps_to_kt(airspeed_law(mode)[1](qci))


def calibration_lines(s):
    """The card line that says where the KIAS column comes from (none without one)."""
    cal = s.get("calibration")
    if not cal:
        return []
    k = ", ".join(f"{v:.4g}" for v in cal["k"])
    source = cal.get("source", "?")
    line = (f"KIAS: the indicator's reading at the KCAS target, from {source} ({cal['model']} "
            f"k = {k})")
    return [line]


def turn_text(s):
    """The turn direction as the card states it."""
    turn = s.get("turn", "right")
    if turn != "both":
        return f"Turns {turn}"
    # why: a term that goes with the turn rate (a probe's lever arm) cancels over the flight
    return "Turns alternate R/L by speed group (lever-arm term averages out)"


def design_lines(s):
    """Why an optimal design's speeds are what they are (none for the paper profiles)."""
    if s.get("design") != "optimal":
        return []
    return [(f"Designed for information: dwells {s.get('dwell_order')} (L/C/H: low, check, "
             f"high), predicted dV 2sigma {s.get('predicted_dv_2sigma_kt')} kt "
             f"({s.get('criterion')}) in {s.get('turbulence_mps')} m/s turbulence"),
            (f"Stall {s.get('stall_kt')} KCAS x {s.get('stall_margin')} at the turn's load "
             f"factor holds the bank to {s.get('bank_max_deg')}°")]
