"""Presentation of an uncertainty `Budget`: JSON keys, summary text, the U band of the figure.

The budget's presentation beside the identification's own (estimation.identification.view):

- `add_budget(out, budget)`: the result dict of `IdentificationResult.to_dict()` gains
  `dv_U_kt` and `u_dv_by_source_kt` in each `airspeed_correction` row and the top-level
  `uncertainty_budget` list (docs/interfaces.md, "Uncertainty budget");
- `budget_summary(result, budget)`: the text printed after the summary;
- `budget_report(result_dict)`: the report's budget tables, by source (with where each input
  came from) and by speed, and the settings (sensor class, temperature source, lever arm);
- `plot_budget_band(ax, result, budget)`: the expanded-uncertainty band on the ΔV axes of the
  calibration figure (`IdentificationResult.plot` returns the figure; its first axes).
"""

import numpy as np

from ..identification.budget import COVERAGE_K
from ..identification.record import with_budget

__all__ = ["SOURCE_LABELS", "add_budget", "budget_report", "budget_summary", "plot_budget_band",
           "source_label"]

# each source of the budget in words (report tables) and as a short column head (summary
# text), in SOURCES order after the statistical term
SOURCE_LABELS = {"statistical": ("Statistical (the fit's 2σ / 2)", "stat"),
                 "oat": ("Outside air temperature", "OAT"),
                 "humidity": ("Relative humidity", "RH"),
                 "gps_velocity_bias": ("GPS velocity bias", "GPSb"),
                 "gps_latency": ("GPS latency", "lat"),
                 "probe_lever_arm": ("Probe lever arm", "arm"),
                 "qc_scale": ("Impact-pressure transducer scale", "scale"),
                 "qc_offset": ("Impact-pressure transducer offset", "offs"),
                 "static_pressure": ("Static-pressure transducer", "ps")}
_HEADS = {k: short for k, (_, short) in SOURCE_LABELS.items()}


def source_label(name):
    """A budget source in words (the name itself, spaced, when it is not one of ours)."""
    return SOURCE_LABELS.get(name, (name.replace("_", " "), name))[0]


def add_budget(out, budget):
    """`out` (a result dict) with `dv_U_kt` per correction row and `uncertainty_budget`
    (`estimation.identification.record.with_budget`; `identify(..., budget=...)` puts the
    budget in its record itself)."""
    return with_budget(out, budget)


def budget_summary(result, budget):
    """The budget as text: ΔV with 2σ and U per speed, then each source's u per speed."""
    dv = np.atleast_1d(result.delta_v_kt(budget.vi_kt)[0])
    two_sigma = 2.0 * budget.statistical_kt
    lines = [
        f"Uncertainty budget (GUM; U = {COVERAGE_K:g} u_c, statistical and Type B):",
        f"  {'KIAS':>7}{'ΔV kt':>9}{'±2σ kt':>9}{'±U kt':>9}{'KCAS':>8}",
    ]
    for v, d, s2, u in zip(budget.vi_kt, dv, two_sigma, budget.expanded_kt):
        lines.append(f"  {v:7.1f}{d:+9.2f}{s2:9.2f}{_num(u, 9, 2)}{v + d:8.1f}")
    names = list(budget.terms_kt)
    lines += ["", "  standard uncertainty of ΔV by source, kt:",
              f"  {'KIAS':>7}{'stat':>7}" + "".join(f"{_HEADS.get(n, n)[:6]:>7}" for n in names)
              + f"{'u_c':>7}"]
    for i, v in enumerate(budget.vi_kt):
        terms = "".join(_num(budget.terms_kt[n][i], 7, 3) for n in names)
        lines.append(f"  {v:7.1f}{budget.statistical_kt[i]:7.3f}{terms}"
                     f"{_num(budget.combined_kt[i], 7, 3)}")
    lines += ["", f"  {'source':<20}{'input u':>14}{'max u(ΔV) kt':>15}  from"]
    for row in budget.to_list():
        given = (f"{row['u_input']:.4g} {row['unit']}" if "u_input" in row
                 else "(2σ / 2)")
        lines.append(f"  {row['source']:<20}{given:>14}{_num(row['u_dv_kt'], 15, 3)}"
                     + (f"  {row['origin']}" if row.get("origin") else ""))
    lines += [f"  {r['input']}: {_value(r)} ({r['origin']})" for r in budget.input_list
              if r["input"] in _SETTINGS]
    return "\n".join(lines)


# the inputs that are no uncertainty, listed under the budget's table, in words
_SETTINGS = {"sensor_class": "Sensor class", "oat_source": "Temperature source",
             "probe_arm_m": "Probe lever arm corrected in the data"}


def _value(row):
    """An input list row's value with its unit."""
    value = row.get("value")
    text = f"{value:g}" if isinstance(value, (int, float)) else str(value)
    return f"{text} {row.get('unit', '')}".strip()


def _num(x, width, digits):
    """`x` right-aligned in `width` with `digits` decimals, or "n/a" (a term not computed)."""
    ok = x is not None and np.isfinite(x)
    return f"{x:{width}.{digits}f}" if ok else f"{'n/a':>{width}}"


def budget_report(result):
    """The budget tables of the calibration report, from a result JSON: `sources` [{label,
    input, u_max, vi_at_max}] and, when every correction row carries each source per speed
    (`u_dv_by_source_kt`), `heads` and `by_speed` [{vi, u: [...], U}] in the order of
    `uncertainty_budget`."""
    rows = result.get("airspeed_correction") or []
    entries = [b for b in result.get("uncertainty_budget") or [] if isinstance(b, dict)]
    names = [b.get("source", "") for b in entries]
    per = [r for r in rows if isinstance(r.get("u_dv_by_source_kt"), dict)]
    per = per if per and len(per) == len(rows) else []
    sources = []
    for b in entries:
        u_in, unit = b.get("u_input"), b.get("unit", "")
        given = ("—" if u_in is None else f"{100 * u_in:.3g} % of reading" if unit == "1"
                 else f"{u_in:.3g} {unit}".strip())
        at = None
        if per and (b.get("u_dv_kt") or 0.0) >= 5e-4:        # a zero term has no largest
            at = max(per, key=lambda r: r["u_dv_by_source_kt"].get(b["source"], -1.0))["vi_kt"]
        sources.append({"label": source_label(b.get("source", "")), "input": given,
                        "u_max": b.get("u_dv_kt"), "vi_at_max": at,
                        "origin": b.get("origin", "")})
    by_speed = [{"vi": r["vi_kt"], "u": [r["u_dv_by_source_kt"].get(n) for n in names],
                 "U": r.get("dv_U_kt")} for r in per]
    heads = [SOURCE_LABELS.get(n, (n, n))[1] for n in names]
    settings = [{"input": _SETTINGS[r["input"]], "value": _value(r),
                 "origin": r.get("origin", "")}
                for r in result.get("budget_inputs") or []
                if isinstance(r, dict) and r.get("input") in _SETTINGS]
    return {"sources": sources, "heads": heads, "by_speed": by_speed, "settings": settings}


def plot_budget_band(ax, result, budget):
    """Draw ΔV ± U (k = 2) over the flown speeds on `ax`, beside the statistical 2σ band.

    Between the table's speeds U is interpolated linearly (it varies slowly with V_i).
    """
    from .figures import draw_u_band

    vi = np.linspace(float(budget.vi_kt[0]), float(budget.vi_kt[-1]), 200)
    dv = np.asarray(result.delta_v_kt(vi)[0], dtype=float) * np.ones_like(vi)
    draw_u_band(ax, vi, dv, np.interp(vi, budget.vi_kt, budget.expanded_kt))
    return ax
