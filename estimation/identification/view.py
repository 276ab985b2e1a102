"""Presentation of an `IdentificationResult`: summary text, correction table, figure.

`IdentificationResult.summary()`, `.correction_table()` and `.plot()` delegate here (its record,
`.to_dict()`, is `estimation.identification.record`). The summary and the figure speak knots and
degrees; nothing here re-fits: the static-source products use the result's own `static_fit`.

Every 2-sigma here is the colored-residual-corrected one (`result.covariance`); the plain
Hessian (Cramer-Rao) 2-sigma is shown beside it, in parentheses in the summary and as
`std_plain` / `dv_2sigma_plain_kt` in the JSON, because with correlated residuals it is often
several times too small.
"""

import math

import numpy as np

from pitotcal.core import airdata
from pitotcal.core.models import get_model
from pitotcal.core.units import RHO0_KGM3, incompressible_cas_mps, mps_to_kt

from .static_source import (
    air_data_lines,
    plot_altimeter_correction,
    plot_static_error,
    static_source_products,
    static_table_lines,
)

__all__ = ["correction_table", "default_step_kt", "flown_vi_kt", "plot", "summary"]

# unit of each reported parameter that is not a model coefficient
_WIND_UNITS = {"wind_speed_mps": "m/s", "wind_from_deg": "deg"}
_MAX_POINTS = 4000           # samples drawn as faint points: enough to see the cloud, cheap


def _compressible(result):
    return getattr(result, "air_data", "incompressible") == "compressible"


def airspeed_kt(result, qc_pa):
    """The airspeed of impact pressures, kt, by the result's law: the standard calibrated
    airspeed (compressible) or sqrt(2 q / rho0) (incompressible)."""
    return mps_to_kt(airdata.airspeed_law(result.air_data)[1](qc_pa))


def flown_vi_kt(result):
    """(lowest, highest) indicated airspeed V_i flown, kt: sqrt(2 q_ci / rho0), or the
    standard CAS of q_ci (V_ic) for a compressible result."""
    qci = np.asarray(result.qci_pa, dtype=float)
    qci = qci[np.isfinite(qci) & (qci > 0)]
    if qci.size == 0:
        raise ValueError("the result holds no positive q_ci samples")
    vi = airspeed_kt(result, np.array([qci.min(), qci.max()]))
    return float(vi[0]), float(vi[1])


def default_step_kt(span_kt):
    """Table step for a V_i span: 1 kt up to 20 kt, 2 kt up to 60, 5 kt up to 150, else 10."""
    for limit, step in ((20.0, 1.0), (60.0, 2.0), (150.0, 5.0)):
        if span_kt <= limit:
            return step
    return 10.0


def correction_table(result, step_kt=None):
    """Airspeed correction over the flown V_i range.

    Parameters
    ----------
    result : IdentificationResult
    step_kt : float, optional
        Grid step, kt; default `default_step_kt` of the flown span.

    Returns
    -------
    list of dict
        Rows {vi_kt, dv_kt, dv_2sigma_kt, dv_2sigma_plain_kt, vc_kt}: indicated airspeed V_i,
        correction ΔV = V_c - V_i and its 2-sigma (corrected, and plain Hessian), calibrated
        V_c = V_i + ΔV, all kt. The first and last rows are the lowest and highest V_i flown
        (rounded inward to 0.1 kt); between them the multiples of `step_kt`. A compressible
        result's rows (V_i = V_ic, ΔV = ΔV_pc) add the static-source products of
        `estimation.identification.static_source`: mach_i, dmach, dmach_2sigma, dh_ft, dh_2sigma_ft,
        dpp_qcic, dpp_qcic_2sigma.
    """
    lo, hi = flown_vi_kt(result)
    if step_kt is None:
        step_kt = default_step_kt(hi - lo)
    if not (isinstance(step_kt, (int, float)) and math.isfinite(step_kt) and step_kt > 0):
        raise ValueError(f"step_kt={step_kt!r} must be a positive number of knots")
    lo_r, hi_r = math.ceil(lo * 10.0) / 10.0, math.floor(hi * 10.0) / 10.0
    if hi_r < lo_r:                       # one speed flown (within 0.1 kt)
        lo_r = hi_r = round(lo, 1)
    inner = np.arange(math.floor(lo_r / step_kt) + 1, math.ceil(hi_r / step_kt)) * step_kt
    grid = np.unique(np.concatenate([[lo_r], inner[(inner > lo_r) & (inner < hi_r)], [hi_r]]))
    dv, band = result.delta_v_kt(grid)
    _, band_plain = result.delta_v_kt(grid, plain=True)
    rows = [{"vi_kt": float(v), "dv_kt": float(d), "dv_2sigma_kt": float(b),
             "dv_2sigma_plain_kt": float(bp), "vc_kt": float(v + d)}
            for v, d, b, bp in zip(grid, np.atleast_1d(dv), np.atleast_1d(band),
                                   np.atleast_1d(band_plain))]
    if _compressible(result) and result.ps_pa is not None:
        extra = static_source_products(result, grid)
        keys = _STATIC_KEYS + (_REFERENCE_KEYS if "dpt_qcic" in extra else ())
        for i, row in enumerate(rows):
            row.update({key: float(np.atleast_1d(extra[key])[i]) for key in keys})
    return rows


_STATIC_KEYS = ("mach_i", "dmach", "dmach_2sigma", "dh_ft", "dh_2sigma_ft", "dpp_qcic",
                "dpp_qcic_2sigma")
_REFERENCE_KEYS = ("dpt_qcic", "dpt_qcic_2sigma")


# --- human summary ----------------------------------------------------------------------

def _fmt(x, digits=4):
    return "n/a" if x is None or not np.isfinite(x) else f"{x:.{digits}g}"


def _wind(result):
    """(speed kt, 2sigma kt, plain 2sigma kt, from deg, 2sigma deg, plain 2sigma deg)."""
    v, d = result.value("wind_speed_mps"), result.value("wind_from_deg")
    return (mps_to_kt(v), 2 * mps_to_kt(result.stddev("wind_speed_mps")),
            2 * mps_to_kt(result.stddev("wind_speed_mps", plain=True)),
            d, 2 * result.stddev("wind_from_deg"), 2 * result.stddev("wind_from_deg", plain=True))


def summary(result):
    """Human summary in knots and degrees: what `pitotcal identify` prints.

    Model and formula, each parameter with its 2-sigma (colored-residual corrected) and the
    plain Hessian 2-sigma in parentheses, the wind in kt and degrees from, the airspeed
    correction table (KIAS, ΔV, 2-sigma, KCAS), candidates of `--model auto`, and warnings.
    """
    model = get_model(result.model)
    state = "converged" if result.converged else "DID NOT CONVERGE"
    lines = [
        f"Pressure-error model: {result.model}   {model.formula}",
        (f"{result.n_samples} samples, solver {state} in {result.iterations} iterations "
         f"({result.message}); residual RMS {_fmt(result.noise_std_pa, 3)} Pa, "
         f"GPS velocity noise {_fmt(result.gps_noise_std_mps, 2)} m/s"),
        "",
        f"  {'parameter':<14}{'value':>12}{'±2σ':>12}{'(plain ±2σ)':>14}",
    ]
    for name, unit in zip(model.params, model.units):
        i = result.param_names.index(name)
        label = f"{name} [{unit}]" if unit else name
        lines.append(f"  {label:<14}{_fmt(result.params[i], 5):>12}"
                     f"{'±' + _fmt(2 * result.std[i], 2):>12}"
                     f"{'(±' + _fmt(2 * result.std_plain[i], 2) + ')':>14}")
    spd, spd2, spd2p, frm, frm2, frm2p = _wind(result)
    lines += [
        (f"  {'wind speed':<14}{_fmt(spd, 4) + ' kt':>12}{'±' + _fmt(spd2, 2):>12}"
         f"{'(±' + _fmt(spd2p, 2) + ')':>14}   = {_fmt(result.value('wind_speed_mps'), 4)} m/s"),
        (f"  {'wind from':<14}{f'{frm:.1f}°':>12}{'±' + _fmt(frm2, 2) + '°':>12}"
         f"{'(±' + _fmt(frm2p, 2) + '°)':>14}   true, the direction it blows from"),
        *_wind_model_lines(result),
        "",
    ]
    table = correction_table(result)
    if _compressible(result):
        lines += air_data_lines(result)
    lines += [
        "Airspeed correction, ΔV = V_c - V_i (add ΔV to the indicated airspeed):",
        f"  {'KIAS':>7}{'ΔV kt':>9}{'±2σ kt':>9}{'(plain)':>9}{'KCAS':>8}",
    ]
    for row in table:
        lines.append(f"  {row['vi_kt']:7.1f}{row['dv_kt']:+9.2f}{row['dv_2sigma_kt']:9.2f}"
                     f"{'(' + format(row['dv_2sigma_plain_kt'], '.2f') + ')':>9}"
                     f"{row['vc_kt']:8.1f}")
    if table and "dh_ft" in table[0]:
        lines += static_table_lines(result, table)
    if result.candidates:
        crit = result.criterion or "criterion"
        lines += ["", f"Candidate structures ({crit}; lowest chosen):"]
        for cand in result.candidates:
            # scalars only: the candidates' own parameter dicts would swamp the table
            extra = ", ".join(f"{k}={_fmt(v) if isinstance(v, float) else v}"
                              for k, v in cand.items()
                              if k != "model" and isinstance(v, (int, float, str, bool)))
            mark = "*" if cand.get("model") == result.model else " "
            lines.append(f"  {mark} {cand.get('model', '?'):<10}{extra}")
    if result.warnings:
        lines += ["", "Warnings:"] + [f"  - {w}" for w in result.warnings]
    return "\n".join(lines)


# --- figure -----------------------------------------------------------------------------

def _implied_ratio(result, model):
    """Per-sample Δp/q_c implied by the residuals: q_ci = (1 - g) q_c with q_c from the fit.

    The residual is r = q_ci - (1 - f) q_c (estimation/residual.py), so q_c = (q_ci - r) / (1 - f)
    and g = 1 - q_ci (1 - f) / (q_ci - r): the model's curve plus each sample's scatter.
    """
    qci = np.asarray(result.qci_pa, dtype=float)
    f = np.asarray(model(result.coefficients, qci), dtype=float) * np.ones_like(qci)
    with np.errstate(divide="ignore", invalid="ignore"):
        g = 1.0 - qci * (1.0 - f) / (qci - np.asarray(result.residuals_pa, dtype=float))
    return qci, g


def _every(n, limit):
    return np.arange(0, n, max(1, n // limit))


def _wind_model_lines(result):
    """A drifting wind's line of the summary: the drift, the knots and the test (none for a
    constant wind: the mean wind above is the whole wind)."""
    wm = result.wind_model or {}
    if wm.get("kind") == "constant per window":
        track = result.wind_track
        return ["  wind per calibration window: " + "; ".join(
            f"{i + 1}: {mps_to_kt(v):.1f} ± {mps_to_kt(u):.1f} kt from {f:.0f}°"
            for i, (v, u, f) in enumerate(zip(track["speed_mps"], track["speed_2sigma_mps"],
                                              track["from_deg"])))]
    if wm.get("kind") != "drifting":
        return []
    from .wind_drift import drift_size

    vec, dspeed, turn = drift_size(result.wind_track)
    test = wm.get("test") or {}
    stat = (f"; Wald test of no drift {test['statistic']:.1f} on {test['dof']} dof"
            if test else "")
    return [f"  wind drifting (time-average above): moved {vec:.1f} m/s (speed "
            f"{dspeed:.1f} m/s, direction {turn:.0f}°), knots every {wm['knot_s']:.0f} s{stat}"]


def plot(result, path=None):
    """The calibration figure in the manner of the paper's Figs. 7-8.

    Four panels: ΔV vs V_i with the 2-sigma band (plain Hessian band dashed); Δp/q_c vs q_ci
    with its band and the per-sample ratio implied by the residuals as faint points; the
    q_ci distribution; the residual time history. The wind is in the title; a drifting wind
    adds its track with the 2-sigma bands of speed and direction below. A compressible
    result shows Δp_p/q_cic vs M_ic and ΔH_pc vs V_ic (`estimation.identification.static_source`) in place
    of the second and third.

    Parameters
    ----------
    result : IdentificationResult
    path : str or path-like, optional
        Where to save (format from the extension, e.g. .png, .pdf).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure  # no pyplot: no GUI backend, safe in workers

    drifting = (result.wind_model or {}).get("kind") == "drifting"
    fig = Figure(figsize=(12, 11.5 if drifting else 8.5), layout="constrained")
    grid = fig.add_gridspec(3 if drifting else 2, 2)
    ax_dv, ax_dp, ax_hist, ax_res = (fig.add_subplot(grid[i, j]) for i in (0, 1) for j in (0, 1))
    if drifting:
        _plot_wind_track(fig.add_subplot(grid[2, :]), result.wind_track)
    _plot_correction(ax_dv, result)
    if _compressible(result) and result.ps_pa is not None:
        # the static-source products in place of Δp/q_c vs q_ci and the q_ci histogram
        g = _implied_ratio(result, get_model(result.model))[1]
        plot_static_error(ax_dp, result, g, flown_vi_kt(result))
        plot_altimeter_correction(ax_hist, result, flown_vi_kt(result))
    else:
        _plot_pressure_error(ax_dp, result)
        _plot_distribution(ax_hist, result)
    _plot_residuals(ax_res, result)
    spd, spd2, _, frm, frm2, _ = _wind(result)
    state = "" if result.converged else "   [SOLVER DID NOT CONVERGE]"
    air = " (compressible, V_i = V_ic)" if _compressible(result) else ""
    wind = "time-average wind" if drifting else "wind"
    fig.suptitle(f"{result.model} model{air}, {result.n_samples} samples — {wind} {spd:.1f} ± {spd2:.1f}"
                 f" kt from {frm:.0f}° ± {frm2:.1f}° (2σ){state}", fontsize=13)
    if path is not None:
        from pitotcal.io.atomic import save_figure

        save_figure(fig, path, dpi=110)
    return fig


def _plot_correction(ax, result):
    """ΔV vs V_i over the flown range, with the corrected and the plain 2-sigma bands."""
    lo, hi = flown_vi_kt(result)
    pad = max(0.5, 0.02 * (hi - lo))
    vi = np.linspace(max(lo - pad, 1.0), hi + pad, 200)
    dv, band = result.delta_v_kt(vi)
    _, band_plain = result.delta_v_kt(vi, plain=True)
    ax.fill_between(vi, dv - band, dv + band, color="tab:blue", alpha=0.25,
                    label="2σ (colored-residual corrected)")
    ax.plot(vi, dv, color="tab:blue", lw=2, label="ΔV = V_c − V_i")
    for sign in (-1, 1):
        ax.plot(vi, dv + sign * band_plain, color="tab:blue", lw=0.8, ls="--",
                label="2σ plain Hessian" if sign > 0 else None)
    for v in (lo, hi):
        ax.axvline(v, color="0.5", lw=0.8, ls=":", label="flown range" if v == lo else None)
    ax.set(xlabel="indicated airspeed V_i (kt)", ylabel="ΔV (kt)", title="Airspeed correction")
    ax.legend(fontsize=8, loc="best")


def _plot_pressure_error(ax, result):
    """Δp/q_c vs q_ci with its band, and the per-sample ratio implied by the residuals."""
    model = get_model(result.model)
    qci, g = _implied_ratio(result, model)
    pick = _every(qci.size, _MAX_POINTS)
    ax.plot(qci[pick], g[pick], ".", color="0.6", ms=2, alpha=0.3, rasterized=True,
            label="per sample (from residuals)")
    qq = np.linspace(float(np.nanmin(qci)), float(np.nanmax(qci)), 200)
    ratio, rband = result.pressure_error(qq)
    ratio = np.asarray(ratio, dtype=float) * np.ones_like(qq)
    ax.fill_between(qq, ratio - rband, ratio + rband, color="tab:red", alpha=0.3, label="2σ")
    ax.plot(qq, ratio, color="tab:red", lw=2, label=model.formula)
    # the scatter is much wider than the band: zoom on the curve, keep the cloud's bulk
    finite = g[np.isfinite(g)]
    if finite.size:
        p5, p95 = np.percentile(finite, [5, 95])
        span = max(p95 - p5, 4 * float(np.max(rband)), 1e-4)
        mid = 0.5 * (float(np.min(ratio)) + float(np.max(ratio)))
        ax.set_ylim(mid - span, mid + span)
    ax.set(xlabel="measured impact pressure q_ci (Pa)", ylabel="Δp / q_c",
           title="Normalized pressure error")
    ax.legend(fontsize=8, loc="best")


def _plot_distribution(ax, result):
    """Histogram of q_ci, with V_i on a top axis."""
    qci = np.asarray(result.qci_pa, dtype=float)
    q_lo, q_hi = float(np.nanmin(qci)), float(np.nanmax(qci))
    ax.hist(qci[np.isfinite(qci)], bins=40, color="tab:green", alpha=0.8)
    # keep q >= 0 on the axis: the V_i axis above is only monotonic there
    margin = 0.03 * (q_hi - q_lo) + 1.0
    ax.set_xlim(max(0.0, q_lo - margin), q_hi + margin)
    ax.set(xlabel="q_ci (Pa)", ylabel="samples", title="Data distribution")
    ax_v = ax.secondary_xaxis(
        "top", functions=(lambda q: mps_to_kt(incompressible_cas_mps(q)),
                          lambda v: 0.5 * RHO0_KGM3 * (np.asarray(v) / mps_to_kt(1.0)) ** 2))
    ax_v.set_xlabel("V_i (kt)")


def _plot_wind_track(ax, track):
    """The fitted wind's speed (kt, left) and direction from (deg, right) along the record,
    each with its 2-sigma band."""
    t = np.asarray(track["time_s"], dtype=float)
    speed = mps_to_kt(np.asarray(track["speed_mps"], dtype=float))
    s2 = mps_to_kt(np.asarray(track["speed_2sigma_mps"], dtype=float))
    ax.fill_between(t, speed - s2, speed + s2, color="tab:blue", alpha=0.25)
    ax.plot(t, speed, color="tab:blue", lw=2, label="wind speed (2σ band)")
    ax.set(xlabel="time (s)", ylabel="wind speed (kt)", title="Drifting wind")
    ax_dir = ax.twinx()
    direction = np.degrees(np.unwrap(np.radians(track["from_deg"])))
    f2 = np.asarray(track["from_2sigma_deg"], dtype=float)
    ax_dir.fill_between(t, direction - f2, direction + f2, color="tab:orange", alpha=0.2)
    ax_dir.plot(t, direction, color="tab:orange", lw=2, label="from (2σ band)")
    ax_dir.set_ylabel("wind from (deg true)")
    lines = ax.get_legend_handles_labels()
    more = ax_dir.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], fontsize=8, loc="best")


def _plot_residuals(ax, result):
    """The residual time history (at most 20,000 points drawn)."""
    t = np.asarray(result.time_s, dtype=float)
    r = np.asarray(result.residuals_pa, dtype=float)
    step = _every(t.size, 20000)
    ax.plot(t[step], r[step], lw=0.5, color="tab:purple", rasterized=True)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set(xlabel="time (s)", ylabel="residual (Pa)",
           title=f"Output residual q_ci − predicted (RMS {_fmt(result.noise_std_pa, 3)} Pa)")
