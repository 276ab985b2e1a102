"""Figures of the calibration report (`pitotcal report`), as PNG bytes to embed.

From the result JSON alone: the airspeed correction ΔV vs V_i with its 2σ and U bands and the
compliance limit, and the altimeter correction ΔH_pc when the result carries it. With the
flight: the paper-style calibration figure of `estimation.identification.view.plot` (its residual panel
included) and the ground track integrated from GPS velocity beside the residual histogram.
"""

import io

import numpy as np

__all__ = ["VI_LABEL", "altimeter_png", "calibration_png", "correction_png", "draw_u_band",
           "png_bytes", "track_png"]

_DPI = 100
# every speed axis of the report is the indicated airspeed, as the tables' first column
VI_LABEL = "indicated airspeed V_i (kt)"


def png_bytes(fig):
    """The figure as PNG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI)
    return buf.getvalue()


def _figure(size=(8.0, 4.2)):
    from matplotlib.figure import Figure  # no pyplot: no GUI backend

    return Figure(figsize=size, layout="constrained")


def _column(rows, key):
    return np.array([np.nan if r.get(key) is None else r[key] for r in rows], dtype=float)


def draw_u_band(ax, vi_kt, dv_kt, u_kt):
    """ΔV ± U (k = 2) as a hatched orange band with its edges drawn, legend refreshed."""
    ax.fill_between(vi_kt, dv_kt - u_kt, dv_kt + u_kt, facecolor="none", edgecolor="tab:orange",
                    hatch="//", lw=0.0, alpha=0.7,
                    label="U (k = 2): statistical + Type B")
    for sign in (-1, 1):
        ax.plot(vi_kt, dv_kt + sign * u_kt, color="tab:orange", lw=1.2)
    ax.legend(fontsize=8, loc="best")


def _u_rows(result):
    """(vi, dv, U) of the correction rows when every row has dv_U_kt, else None."""
    rows = result.get("airspeed_correction") or []
    u = _column(rows, "dv_U_kt")
    if not rows or not np.isfinite(u).all():
        return None
    return _column(rows, "vi_kt"), _column(rows, "dv_kt"), u


def correction_png(result, compliance=None):
    """ΔV = V_c − V_i vs V_i: the 2σ band, U when present, and ± the airspeed limit."""
    rows = result["airspeed_correction"]
    vi, dv = _column(rows, "vi_kt"), _column(rows, "dv_kt")
    band = _column(rows, "dv_2sigma_kt")
    fig = _figure()
    ax = fig.subplots()
    ax.fill_between(vi, dv - band, dv + band, color="tab:blue", alpha=0.35,
                    label="2σ statistical")
    ax.plot(vi, dv, color="tab:blue", lw=2, label="ΔV = V_c − V_i")
    if compliance and compliance.get("airspeed"):
        lim = [r for r in compliance["airspeed"]["rows"] if r.get("vi_kt") is not None]
        if lim:
            lv, ll = _column(lim, "vi_kt"), _column(lim, "limit_kt")
            ax.plot(lv, ll, "r--", lw=1, label=f"limit ({compliance['regulation']})")
            ax.plot(lv, -ll, "r--", lw=1)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set(xlabel=VI_LABEL, ylabel="ΔV (kt)", title="Airspeed correction over the flown range")
    ax.legend(fontsize=8, loc="best")
    if (u := _u_rows(result)) is not None:
        draw_u_band(ax, *u)
    return png_bytes(fig)


def altimeter_png(result, compliance=None):
    """ΔH_pc vs V_i at the test altitude with its 2σ, at sea level, and ± the altimeter limit
    where it is judged; None without dh_ft."""
    rows = [r for r in result["airspeed_correction"] if r.get("dh_ft") is not None]
    if not rows:
        return None
    vi, dh, band = _column(rows, "vi_kt"), _column(rows, "dh_ft"), _column(rows, "dh_2sigma_ft")
    fig = _figure()
    ax = fig.subplots()
    if np.isfinite(band).all():
        ax.fill_between(vi, dh - band, dh + band, color="tab:green", alpha=0.3, label="2σ")
    ax.plot(vi, dh, color="tab:green", lw=2, label="ΔH_pc at the test altitude")
    if compliance and compliance.get("altimeter", {}).get("rows"):
        # the compliance rows are by KCAS: drawn at the KIAS of the same table row
        def at_vi(sel):
            return np.interp(_column(sel, "vc_kt"), _column(rows, "vc_kt"), vi)

        alt = compliance["altimeter"]["rows"]
        sea = [r for r in alt if r.get("dh_ft") is not None]
        if sea:
            ax.plot(at_vi(sea), _column(sea, "dh_ft"), color="tab:blue", lw=1.5,
                    label="ΔH_pc at sea level (judged)")
        lim = [r for r in alt if r.get("limit_ft") is not None]
        if lim:
            lv, ll = at_vi(lim), _column(lim, "limit_ft")
            ax.plot(lv, ll, "r--", lw=1, label="limit, ±30 ft per 100 kt, at least ±30 ft")
            ax.plot(lv, -ll, "r--", lw=1)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set(xlabel=VI_LABEL, ylabel="ΔH_pc (ft)", title="Altimeter correction")
    ax.legend(fontsize=8, loc="best")
    return png_bytes(fig)


def calibration_png(ident, result=None):
    """The paper-style four-panel calibration figure of an `IdentificationResult`, with the U
    band of `result` (the JSON's dv_U_kt) on its ΔV panel when every row has one."""
    fig = ident.plot()
    if result is not None and (u := _u_rows(result)) is not None:
        draw_u_band(fig.axes[0], *u)
    return png_bytes(fig)


def track_png(flight, ident):
    """Ground track (integrated GPS velocity, coloured by q_ci) and the residual histogram."""
    t = np.asarray(flight.time_s, dtype=float)
    dt = np.diff(t, prepend=t[0])
    east = np.cumsum(np.asarray(flight.gps_ve_mps) * dt)
    north = np.cumsum(np.asarray(flight.gps_vn_mps) * dt)
    fig = _figure((10.0, 4.4))
    ax_t, ax_h = fig.subplots(1, 2, width_ratios=[1.2, 1.0])
    step = max(1, t.size // 5000)
    sc = ax_t.scatter(east[::step], north[::step], c=np.asarray(flight.qci_pa)[::step], s=2,
                      cmap="viridis", rasterized=True)
    fig.colorbar(sc, ax=ax_t, label="q_ci (Pa)")
    from pitotcal.core.units import mps_to_kt

    wind = ident.value("wind_speed_mps"), np.radians(ident.value("wind_from_deg"))
    span = max(np.ptp(east), np.ptp(north), 1.0)
    x0, y0 = east.min(), north.max()
    # the red arrow points where the wind blows TO
    ax_t.annotate("", xy=(x0 - 0.15 * span * np.sin(wind[1]), y0 - 0.15 * span * np.cos(wind[1])),
                  xytext=(x0, y0), arrowprops={"arrowstyle": "->", "color": "tab:red", "lw": 2})
    ax_t.set(xlabel="east (m)", ylabel="north (m)", aspect="equal",
             title=f"Ground track from GPS velocity\nwind {mps_to_kt(wind[0]):.1f} kt from "
                   f"{ident.value('wind_from_deg'):.0f}° (red arrow: blows to)")
    r = np.asarray(ident.residuals_pa, dtype=float)
    ax_h.hist(r[np.isfinite(r)], bins=60, density=True, color="tab:purple", alpha=0.7)
    s = max(float(np.nanstd(r)), 1e-9)
    x = np.linspace(*ax_h.get_xlim(), 200)
    ax_h.plot(x, np.exp(-0.5 * (x / s) ** 2) / (s * np.sqrt(2 * np.pi)), "k-", lw=1,
              label="normal, same RMS")
    ax_h.set(xlabel="q_ci residual (Pa)", ylabel="probability density (1/Pa)",
             title="Residual distribution")
    ax_h.legend(fontsize=8)
    return png_bytes(fig)
