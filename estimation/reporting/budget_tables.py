"""Presentation of an uncertainty `Budget`: JSON keys, summary text, the U band of the figure.

The budget's presentation beside the identification's own (estimation.identification.view):

- `add_budget(out, budget)`: the result dict of `IdentificationResult.to_dict()` gains
  `dv_U_kt` in each `airspeed_correction` row and the top-level `uncertainty_budget` list
  (docs/interfaces.md, "Uncertainty budget");
- `budget_summary(result, budget)`: the text printed after the summary;
- `plot_budget_band(ax, result, budget)`: the expanded-uncertainty band on the ΔV axes of the
  calibration figure (`IdentificationResult.plot` returns the figure; its first axes).
"""

import numpy as np

from ..identification.budget import COVERAGE_K
from ..identification.record import with_budget

__all__ = ["add_budget", "budget_summary", "plot_budget_band"]

# short column heads of the per-speed table, in SOURCES order
_HEADS = {"oat": "OAT", "humidity": "RH", "gps_velocity_bias": "GPSb", "gps_latency": "lat",
          "probe_lever_arm": "arm", "qc_scale": "scale", "qc_offset": "offs"}


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
        lines.append(f"  {v:7.1f}{d:+9.2f}{s2:9.2f}{u:9.2f}{v + d:8.1f}")
    names = list(budget.terms_kt)
    lines += ["", "  standard uncertainty of ΔV by source, kt:",
              f"  {'KIAS':>7}{'stat':>7}" + "".join(f"{_HEADS.get(n, n)[:6]:>7}" for n in names)
              + f"{'u_c':>7}"]
    for i, v in enumerate(budget.vi_kt):
        terms = "".join(f"{budget.terms_kt[n][i]:7.3f}" for n in names)
        lines.append(f"  {v:7.1f}{budget.statistical_kt[i]:7.3f}{terms}"
                     f"{budget.combined_kt[i]:7.3f}")
    lines += ["", f"  {'source':<20}{'input u':>14}{'max u(ΔV) kt':>15}"]
    for row in budget.to_list():
        given = (f"{row['u_input']:.4g} {row['unit']}" if "u_input" in row
                 else "(2σ / 2)")
        lines.append(f"  {row['source']:<20}{given:>14}{row['u_dv_kt']:15.3f}")
    return "\n".join(lines)


def plot_budget_band(ax, result, budget):
    """Draw ΔV ± U (k = 2) over the flown speeds on `ax`, beside the statistical 2σ band.

    Between the table's speeds U is interpolated linearly (it varies slowly with V_i).
    """
    vi = np.linspace(float(budget.vi_kt[0]), float(budget.vi_kt[-1]), 200)
    dv = np.asarray(result.delta_v_kt(vi)[0], dtype=float) * np.ones_like(vi)
    u = np.interp(vi, budget.vi_kt, budget.expanded_kt)
    ax.fill_between(vi, dv - u, dv + u, facecolor="none", edgecolor="tab:orange", hatch="//",
                    lw=0.0, alpha=0.7, label=f"U (k = {COVERAGE_K:g}): statistical + Type B")
    for sign in (-1, 1):
        ax.plot(vi, dv + sign * u, color="tab:orange", lw=1.2)
    ax.legend(fontsize=8, loc="best")
    return ax
