"""What `pitotcal legs` reports: the per-point classic solutions beside the global fit.

`analyze_legs` runs both; `legs_json` is the JSON (docs/interfaces.md, "pitotcal legs"),
`legs_summary` the text in knots and degrees, `plot_legs` the figure: per-point ΔV with its
95 % bars and the global curve with its band.
"""

import warnings

import numpy as np

from pitotcal.core.errors import ObservabilityError
from pitotcal.core.units import KT_TO_MPS, m_to_ft

from .points import solve_points
from .global_fit import fit_legs

__all__ = ["POINT_KEYS", "analyze_legs", "flight_legs_json", "flight_legs_text",
           "legs_as_result", "legs_json", "legs_summary", "plot_legs"]

# The keys of each entry of the JSON's "points" list, in order.
POINT_KEYS = ("point", "ias_kt", "tas_kt", "tas_2sigma_kt", "wind_speed_kt", "wind_from_deg",
              "dv_kt", "dv_2sigma_kt", "method")


def analyze_legs(legs, model="inverse", wind="per-band"):
    """Per-point classic solutions and the global fit of a `LegData`.

    Returns
    -------
    (list of PointSolution, LegFit or None, list of str)
        The global fit is None (with a warning saying why) when the legs cannot determine it,
        e.g. a single calibration point; a degenerate point raises `ObservabilityError`.
    """
    points, notes = solve_points(legs)
    start = {s.point: (s.wind_n_mps, s.wind_e_mps) for s in points}
    try:
        fit = fit_legs(legs, model=model, wind=wind, initial_winds=start)
        notes += list(fit.warnings)
    except ObservabilityError as exc:
        fit = None
        notes.append(f"no global fit: {exc}")
    for note in notes:
        warnings.warn(note, stacklevel=2)
    return points, fit, notes


def _point_row(s):
    speed, frm = s.wind
    return dict(zip(POINT_KEYS, (
        s.point, s.ias_kt, s.tas_mps / KT_TO_MPS, s.tas_half_mps / KT_TO_MPS,
        speed / KT_TO_MPS, frm, s.dv_kt, s.dv_half_kt, s.method)))


def _detail(s):
    return {"point": s.point, "n_legs": int(s.legs.size), "bound": s.bound,
            "half_width_factor": s.half_width_factor, "tas_dop": s.dop,
            "tas_subset_sd_kt": s.tas_subset_sd_mps / KT_TO_MPS,
            "naive_average_tas_kt": s.naive_tas_mps / KT_TO_MPS,
            "naive_average_bias_kt": (s.naive_tas_mps - s.tas_mps) / KT_TO_MPS,
            "pressure_alt_ft": m_to_ft(s.pressure_alt_m), "oat_c": s.oat_k - 273.15,
            "qc_pa": s.qc_pa, "dp_static_pa": s.qc_pa - s.qci_pa, "vc_kt": s.vc_kt,
            "residuals_kt": list(s.residuals_mps / KT_TO_MPS),
            "tas_offsets_kt": list(_offsets(s) / KT_TO_MPS)}


def _offsets(s):
    """Each leg's TAS less the point's (zero for a solution made without them)."""
    return np.zeros(s.legs.size) if s.tas_offsets_mps is None else s.tas_offsets_mps


def legs_json(legs, points, fit, notes):
    """The result as a JSON-ready dict: source, n_legs, temperature (the column the OAT came
    from), points, points_detail, global, warnings."""
    from pitotcal.io.jsonfile import json_ready

    return json_ready({"source": legs.source, "n_legs": legs.n,
                       "temperature": getattr(legs, "temperature", "oat_c"),
                       "points": [_point_row(s) for s in points],
                       "points_detail": [_detail(s) for s in points],
                       "global": None if fit is None else fit.to_dict(),
                       "warnings": list(notes)})


def _fmt(x, spec):
    return "n/a" if x is None or not np.isfinite(x) else format(x, spec)


def legs_summary(legs, points, fit, notes):
    """The text `pitotcal legs` prints (knots, degrees true, wind FROM)."""
    temperature = getattr(legs, "temperature", "oat_c")
    lines = [f"Legs: {legs.source} ({legs.n} legs, {len(points)} points)"
             + ("" if temperature in ("oat_c", "oat_k") else
                f"; OAT from {temperature}, at each leg's true Mach"), "",
             ("Per point, the classic solution (±: 95 % half-width; bound: stated GPS accuracy, "
             "samples (the legs' own GPS scatter), leg scatter, or none):"),
             (f"  {'point':<7}{'method':<7}{'KIAS':>6}{'KTAS':>8}{'±':>6}{'wind kt':>9}"
             f"{'from':>6}{'ΔV kt':>8}{'±':>6}  {'bound':<8}{'avg-GS bias':>11}")]
    for s in points:
        r = _point_row(s)
        lines.append(
            f"  {s.point:<7}{s.method:<7}{r['ias_kt']:6.1f}{r['tas_kt']:8.2f}"
            f"{_fmt(r['tas_2sigma_kt'], '6.2f'):>6}{r['wind_speed_kt']:9.1f}"
            f"{r['wind_from_deg']:6.0f}{r['dv_kt']:+8.2f}{_fmt(r['dv_2sigma_kt'], '6.2f'):>6}"
            f"  {s.bound:<8}{(s.naive_tas_mps - s.tas_mps) / KT_TO_MPS:+11.2f}")
    if fit is not None:
        lines += ["", _global_text(fit)]
    if notes:
        lines += ["", "Warnings:"] + [f"  - {n}" for n in notes]
    return "\n".join(lines)


def _global_text(fit):
    d = fit.to_dict()
    state = "converged" if fit.converged else "DID NOT CONVERGE"
    out = [(f"Global fit over all legs: {d['model']}   {d['formula']}   (winds {fit.wind_mode}; "
           f"{fit.n_samples} legs, {fit.dof} degrees of freedom, {state}; leg noise "
           f"{fit.noise_std_mps / KT_TO_MPS:.2f} kt, {fit.noise_source})")]
    for name, p in d["parameters"].items():
        out.append(f"  {name:<6}{p['value']:>12.5g}  ±{fit.half_width_factor * p['std']:.2g}"
                   f"{' ' + p['unit'] if p['unit'] else ''}")
    for w in d["winds"]:
        out.append(f"  wind {w['group']}: {w['wind_speed_kt']:.1f} kt from "
                   f"{w['wind_from_deg']:.0f}° (±{w['wind_2sigma_kt']:.1f} kt)")
    out += ["", ("Airspeed correction, ΔV = V_c − V_ic (add ΔV to the indicated airspeed; ±: 95 % "
                "half-width, 2σ when each leg carries its accuracy):"),
            f"  {'KIAS':>7}{'ΔV kt':>9}{'±95% kt':>10}{'KCAS':>8}"]
    out += [f"  {r['vi_kt']:7.1f}{r['dv_kt']:+9.2f}{r['dv_2sigma_kt']:10.2f}{r['vc_kt']:8.1f}"
            for r in d["airspeed_correction"]]
    return "\n".join(out)


def plot_legs(points, fit, path, series=None):
    """Per-point ΔV (95 % bars) and the global curve with its band, saved to `path`; with
    `series` (an IdentificationResult) its curve and 2σ band too."""
    from matplotlib.figure import Figure

    from pitotcal.io.atomic import save_figure

    fig = Figure(figsize=(7.0, 4.5), layout="constrained")
    ax = fig.subplots()
    if fit is not None:
        lo, hi = fit.vi_range_kt
        vi = np.linspace(lo, hi, 200)
        dv, half = fit.delta_v_kt(vi)
        name = "global fit" if series is None else "global fit over the legs"
        two_sigma = fit.noise_source in ("stated", "samples")
        ax.fill_between(vi, dv - half, dv + half, color="C0", alpha=0.25,
                        label=f"{name} ({fit.model}) ±2σ" if two_sigma
                        else f"{name} ({fit.model}), 95 % band")
        ax.plot(vi, dv, color="C0", lw=2)
    if series is not None:
        vi = np.linspace(min(s.ias_kt for s in points), max(s.ias_kt for s in points), 200)
        dv, half = series.delta_v_kt(vi)
        ax.fill_between(vi, dv - half, dv + half, color="C2", alpha=0.18,
                        label=f"time-series fit ({series.model}) ±2σ, colored residuals")
        ax.plot(vi, dv, color="C2", lw=1.5, ls="--")
    ias = np.array([s.ias_kt for s in points])
    dv_pts = np.array([s.dv_kt for s in points])
    half = np.array([s.dv_half_kt for s in points])
    has = np.isfinite(half)
    ax.errorbar(ias[has], dv_pts[has], yerr=half[has], fmt="o", color="C3", capsize=3,
                label="per point (classic), 95 %")
    if np.any(~has):
        ax.plot(ias[~has], dv_pts[~has], "x", color="C3", label="per point, no bound")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("indicated airspeed V_ic, kt")
    ax.set_ylabel("ΔV_pc = V_c − V_ic, kt")
    ax.set_title("Airspeed correction from GPS legs: per point vs one global fit")
    ax.legend(fontsize=8)
    save_figure(fig, path, dpi=110)
    return path


def _series_dict(res):
    return None if res["series"] is None else res["series"].to_dict()


def flight_legs_json(res, source):
    """The JSON of `pitotcal legs FLIGHT`: that of a leg file plus input "flight", detection,
    segments [{leg, point, start_s, end_s, groundspeed_kt, track_deg, groundspeed_sd_kt
    (pooled, as used), groundspeed_sd_own_kt, ias_kt}] and global_timeseries (the identify JSON of the legs' samples, or null)."""
    from pitotcal.io.jsonfile import json_ready

    legs = res["legs"]
    out = legs_json(legs, res["points"], res["fit"], res["notes"])
    out["source"] = str(source)
    segments = [{"leg": i + 1, "point": legs.point[i], "start_s": float(lo), "end_s": float(hi),
                 "groundspeed_kt": legs.groundspeed_mps[i] / KT_TO_MPS,
                 "track_deg": legs.track_deg[i],
                 "groundspeed_sd_kt": legs.groundspeed_sd_mps[i] / KT_TO_MPS,
                 "groundspeed_sd_own_kt": res["leg_sd_own_mps"][i] / KT_TO_MPS,
                 "ias_kt": legs.ias_kt[i]} for i, (lo, hi) in enumerate(res["spans"])]
    out.update({"input": "flight", "detection": res["detection"], "segments": segments,
                "global_timeseries": _series_dict(res)})
    return json_ready(out)


def flight_legs_text(res):
    """The legs found in a flight and the time-series fit beside the per-point ΔV."""
    legs = res["legs"]
    how = ("given windows" if res["detection"] == "windows" else
           "detected: " + ", ".join(f"{k} {v:g}" for k, v in res["detection"].items()))
    pooled = legs.groundspeed_sd_mps[0] / KT_TO_MPS
    lines = [f"Legs from the time series ({how}):",
             (f"  {'leg':>4}{'point':>7}{'start s':>10}{'end s':>9}{'KIAS':>7}{'GS kt':>8}"
              f"{'track':>7}{'sd kt':>7}   (sd: the leg's own; pooled {pooled:.2f} kt used)")]
    for i, (lo, hi) in enumerate(res["spans"]):
        lines.append(f"  {i + 1:4d}{legs.point[i]:>7}{lo:10.1f}{hi:9.1f}{legs.ias_kt[i]:7.1f}"
                     f"{legs.groundspeed_mps[i] / KT_TO_MPS:8.2f}{legs.track_deg[i]:7.1f}"
                     f"{res['leg_sd_own_mps'][i] / KT_TO_MPS:7.2f}")
    series, fit = res["series"], res["fit"]
    if series is None:
        return "\n".join(lines)
    d = series.to_dict()
    lines += ["", (f"Global fit over the legs' time series (identify, {series.n_samples} samples, "
                   f"one wind, colored-residual 2σ; {'converged' if series.converged else 'DID NOT CONVERGE'}):")]
    for name in d["parameters"]:
        p = d["parameters"][name]
        lines.append(f"  {name:<16}{p['value']:>12.5g}  ±{2 * p['std']:.2g} {p.get('unit') or ''}")
    lines += ["", "ΔV at each point, kt (±: 95 % half-width):",
              f"  {'point':<7}{'KIAS':>6}{'classic':>14}{'leg global':>14}{'time series':>14}"]
    for s in res["points"]:
        dv_s, h_s = series.delta_v_kt(s.ias_kt)
        glob = ("n/a" if fit is None else
                "{:+.2f}±{:.2f}".format(*(float(x) for x in fit.delta_v_kt(s.ias_kt))))
        lines.append(f"  {s.point:<7}{s.ias_kt:6.1f}{s.dv_kt:+9.2f}±{_fmt(s.dv_half_kt, '.2f'):<4}"
                     f"{glob:>14}{float(dv_s):+9.2f}±{float(h_s):.2f}")
    return "\n".join(lines)


# the global leg fit's keys shown under the legs table (the rest are the result's own)
_LEGS_GLOBAL_KEYS = ("model", "wind_mode", "n_samples", "dof", "noise_std_kt", "noise_source")


def legs_as_result(doc):
    """A `pitotcal legs --json` as a report input: its global fit is the result, its points
    the legs table; a legs JSON without a global fit is returned as it is (and refused)."""
    glob = doc.get("global")
    if not isinstance(doc.get("points"), list) or not isinstance(glob, dict):
        return doc
    notes = list(doc.get("warnings") or [])
    notes += [w for w in glob.get("warnings") or [] if w not in notes]
    return {**glob, "source": doc.get("source"), "warnings": notes, "points": doc["points"],
            "global": {k: glob[k] for k in _LEGS_GLOBAL_KEYS if k in glob}}
