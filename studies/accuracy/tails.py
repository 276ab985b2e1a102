"""`coverage-tails`: do the default flights' bands cover truth row by row, and how often all at once?

Every run plans the default maneuver (`pitotcal plan`, one way or `--return` up and down),
flies it in Dryden turbulence with the default compressible air data (`pitotcal simulate`),
identifies it with the defaults and the GUM budget (`pitotcal identify`) and scores, against
the simulator's truth, every row of the correction table: inside its ±2σ band, inside its
expanded uncertainty U. Per parameter it keeps the z-score (the wind against the wind flown
through, and against the air mass's mean wind).

Rows of one flight are correlated (ΔV is a function of k1 and k2 alone), so the chance that all
of them lie inside their pointwise ±2σ is below 95 % even when each band is honest. Each run
computes that chance for its own covariance (`joint_inside`: the ΔV rows drawn as a joint
normal) so the observed "every row inside" rate has an expectation to be held against.
"""

import numpy as np

from ..engine.common import column, get_flight, ok_rows, percent, truth_delta_v_kt
from ..engine.figures import new_figure, save
from ..engine.study import MonteCarloStudy
from .coverage import wilson_interval

__all__ = ["PLANS", "STUDY", "TURBULENCE_MPS", "clustered_interval", "joint_inside", "task"]

PLANS = {"one-way": {}, "up-and-down": {"return_leg": True}}
TURBULENCE_MPS = (0.5, 1.0)
PARAMETERS = ("k1", "k2", "wind_speed_mps", "wind_from_deg")
# Joint-normal draws per flight for the expected "every row inside" chance (its standard error
# is below 0.8 % at any rate).
JOINT_DRAWS = 4000
# Seeds of the k-th turbulence level start at seed + k * SEED_STRIDE.
SEED_STRIDE = 1000
# Relative step of the central differences of ΔV with respect to each coefficient.
REL_STEP = 1e-6


def task(seed, plan, turbulence_mps):
    """Plan, fly and identify one default flight; its row-by-row and per-parameter scores."""
    from pitotcal.estimation import identify
    from pitotcal.estimation.identification.budget import BudgetInputs

    flight, truth = get_flight(PLANS[plan], {"turbulence_mps": turbulence_mps,
                                             "air_data": "compressible"}, seed)
    result = identify(flight, budget=BudgetInputs())
    row = {"success": bool(result.success), "n_samples": int(result.n_samples),
           "n_warnings": len(result.warnings)}
    row.update(_parameter_scores(result, truth))
    row.update(_row_scores(result, truth, seed))
    return row


def _parameter_scores(result, truth):
    """z of each parameter against truth; the wind also against the air mass's mean wind."""
    out = {}
    mean = truth.wind_mean_process
    process = {"wind_speed_mps": float(mean["speed_mps"]), "wind_from_deg": float(mean["from_deg"])}
    for i, name in enumerate(result.param_names):
        if name not in PARAMETERS:
            continue
        std = float(np.sqrt(result.covariance[i, i]))
        est = float(result.params[i])
        out[name] = est
        out[f"{name}_std"] = std
        for suffix, true in (("", truth.parameters[name]), ("_process", process.get(name))):
            if true is None:
                continue
            err = est - float(true)
            if name.endswith("_deg"):
                err = (err + 180.0) % 360.0 - 180.0
            out[f"{name}_z{suffix}"] = err / std if std > 0 else float("nan")
    return out


def _row_scores(result, truth, seed):
    """Every correction-table row against truth: inside ±2σ, inside U, and the chance that all
    rows lie inside ±2σ at once were the bands exact (`joint_inside`)."""
    table = result.correction_table()
    vi = np.array([r["vi_kt"] for r in table])
    dv = np.array([r["dv_kt"] for r in table])
    band = np.array([r["dv_2sigma_kt"] for r in table])
    err = dv - truth_delta_v_kt(truth, vi)
    z = err / (band / 2.0)
    u_kt = (np.asarray(result.budget.expanded_kt, dtype=float) if result.budget is not None
            else np.full_like(vi, np.nan))
    in_2s, in_u = np.abs(err) <= band, np.abs(err) <= u_kt
    return {"n_rows": int(vi.size), "rows_in_2sigma": int(in_2s.sum()),
            "rows_in_u": int(in_u.sum()), "all_in_2sigma": float(in_2s.all()),
            "all_in_u": float(in_u.all()), "row_z_max_abs": float(np.max(np.abs(z))),
            "row_z_low": float(z[0]), "row_z_mid": float(z[vi.size // 2]),
            "row_z_high": float(z[-1]), "u_over_2sigma_min": float(np.min(u_kt / band)),
            "vi_low_kt": float(vi[0]), "vi_high_kt": float(vi[-1]),
            "joint_expected_2sigma": joint_inside(result, vi, seed)}


def joint_inside(result, vi_kt, seed=0, draws=JOINT_DRAWS):
    """The chance that every ΔV row at `vi_kt` lies inside its ±2σ at once, were the estimate's
    error exactly normal with the result's covariance: ΔV linearised in the model's
    coefficients, the coefficient error drawn `draws` times (seeded by `seed`).

    Returns
    -------
    float
        A fraction; 0.9545 for a single row, less the more independent the rows.
    """
    from pitotcal.core.models import delta_v_kt, get_model

    model = get_model(result.model)
    k = np.asarray(result.params[:len(model.params)], dtype=float)
    cov = np.asarray(result.covariance, dtype=float)[:k.size, :k.size]
    grad = np.empty((np.size(vi_kt), k.size))
    for j in range(k.size):
        h = REL_STEP * max(abs(k[j]), 1.0)
        up, down = k.copy(), k.copy()
        up[j] += h
        down[j] -= h
        grad[:, j] = (delta_v_kt(model, up, vi_kt, result.air_data)
                      - delta_v_kt(model, down, vi_kt, result.air_data)) / (2.0 * h)
    sigma = np.sqrt(np.einsum("ij,jk,ik->i", grad, cov, grad))
    # the covariance of a two-coefficient model is 2x2: an eigen square root copes with a
    # k1-k2 correlation of 0.999+ where a Cholesky factor may not
    w, v = np.linalg.eigh(cov)
    root = v * np.sqrt(np.clip(w, 0.0, None))
    rng = np.random.default_rng(int(seed))
    x = rng.standard_normal((draws, k.size)) @ root.T @ grad.T
    return float(np.mean(np.all(np.abs(x) <= 2.0 * sigma, axis=1)))


def cases(runs, quick):
    grid = [(p, t) for p in PLANS for t in TURBULENCE_MPS]
    if quick:
        grid = [("up-and-down", 0.5)]
    # the plans share seeds (seed + r: `pitotcal simulate --seed` of run r, the turbulence
    # option scaling one realisation); each turbulence level has its own, so its cells are
    # independent samples rather than the same gusts made larger
    return [{"plan": p, "turbulence_mps": t,
             "seed_offset": r + SEED_STRIDE * TURBULENCE_MPS.index(t)} for p, t in grid
            for r in range(runs)]


def summarize(rows, cases=None):
    out = {"cells": []}
    cells = []
    for r in rows:
        key = (r.get("plan"), float(r.get("turbulence_mps")))
        if key not in cells:
            cells.append(key)
    for plan, turb in cells:
        good = ok_rows([r for r in rows if r.get("plan") == plan
                        and float(r.get("turbulence_mps")) == turb])
        if good:
            out["cells"].append({"plan": plan, "turbulence_mps": turb, **cell_summary(good)})
    return out


def cell_summary(good):
    """Row coverage of ±2σ and U, the observed and expected "every row inside" rates, and
    per parameter the rms z and the ±2σ coverage, each rate with its Wilson 95 % interval."""
    n_rows = column(good, "n_rows")
    in_2s, in_u = column(good, "rows_in_2sigma"), column(good, "rows_in_u")
    all_2s = column(good, "all_in_2sigma") > 0.5
    expected = column(good, "joint_expected_2sigma")
    out = {"n_flights": len(good), "n_rows": int(n_rows.sum()),
           "row_coverage_2sigma": float(in_2s.sum() / n_rows.sum()),
           "row_coverage_2sigma_interval95": clustered_interval(in_2s, n_rows),
           "row_coverage_u": float(in_u.sum() / n_rows.sum()),
           "row_coverage_u_interval95": clustered_interval(in_u, n_rows),
           "all_rows_in_2sigma": float(np.mean(all_2s)),
           "all_rows_in_2sigma_interval95": wilson_interval(all_2s),
           "all_rows_in_2sigma_expected": float(np.mean(expected)),
           # observed minus expected count over its Poisson-binomial std
           "all_rows_in_2sigma_z": float((all_2s.sum() - expected.sum())
                                         / np.sqrt(max(np.sum(expected * (1 - expected)), 1e-12))),
           "all_rows_in_u": float(np.mean(column(good, "all_in_u") > 0.5)),
           "row_z_max_abs_max": float(np.max(column(good, "row_z_max_abs"))),
           "parameters": {}}
    for name in PARAMETERS:
        for suffix in ("", "_process"):
            z = column(good, f"{name}_z{suffix}")
            z = z[np.isfinite(z)]
            if z.size == 0:
                continue
            inside = np.abs(z) <= 2.0
            out["parameters"][name + suffix] = {
                "rms_z": float(np.sqrt(np.mean(z ** 2))),
                "rms_z_interval95": _rms_interval(z),
                "coverage_2sigma": float(np.mean(inside)),
                "coverage_2sigma_interval95": wilson_interval(inside),
                "max_abs_z": float(np.max(np.abs(z))), "n": int(z.size)}
    return out


def clustered_interval(inside, n_rows, z=1.96):
    """95 % interval of the row coverage sum(inside) / sum(n_rows), flights as the sampling
    unit: the rows of one flight move together (one k1-k2 error tilts them all), so counting
    them as independent draws would make the interval several times too narrow."""
    inside, n_rows = np.asarray(inside, dtype=float), np.asarray(n_rows, dtype=float)
    m = inside.size
    if m < 2:
        return None
    p = inside.sum() / n_rows.sum()
    se = np.sqrt(np.sum((inside - p * n_rows) ** 2) / (m * (m - 1))) / n_rows.mean()
    return [float(max(p - z * se, 0.0)), float(min(p + z * se, 1.0))]


def _rms_interval(z):
    """95 % interval of the rms z of n normal z-scores: n rms² / χ²_n at its 2.5 and 97.5 %
    points, the χ² quantiles by Wilson-Hilferty (good to 0.5 % at n = 40)."""
    n = z.size
    if n < 2:
        return None
    rms2 = float(np.mean(z ** 2))
    lo_q, hi_q = (n * (1 - 2 / (9 * n) + s * np.sqrt(2 / (9 * n))) ** 3 for s in (1.96, -1.96))
    return [float(np.sqrt(n * rms2 / lo_q)), float(np.sqrt(n * rms2 / hi_q))]


def headline(summary):
    parts = []
    for c in summary.get("cells", []):
        parts.append(
            f"{c['plan']} {c['turbulence_mps']:g} m/s: rows inside 2σ "
            f"{percent(c['row_coverage_2sigma'])}, inside U {percent(c['row_coverage_u'])}; "
            f"all rows inside 2σ {percent(c['all_rows_in_2sigma'])} (expected "
            f"{percent(c['all_rows_in_2sigma_expected'])}); k1 rms z "
            f"{c['parameters']['k1']['rms_z']:.2f}")
    if not parts:
        return f"no run of {summary.get('n_runs', 0)} converged"
    return "; ".join(parts)


def plot(rows, summary, out_dir):
    return [save(figure(rows, summary), out_dir, "coverage-tails.png")]


def figure(rows, summary):
    """Per cell: the k1 z-scores against N(0, 1), and the observed against the expected
    "every row inside ±2σ" rate."""
    good = ok_rows(rows)
    fig, ax = new_figure(1, 2, size=(5.0, 3.8))
    x = np.linspace(-5, 5, 401)
    ax[0, 0].plot(x, np.exp(-0.5 * x * x) / np.sqrt(2 * np.pi), "k-", lw=1.2, label="N(0, 1)")
    cells = summary.get("cells", [])
    for c in cells:
        z = column([r for r in good if r.get("plan") == c["plan"]
                    and float(r.get("turbulence_mps")) == c["turbulence_mps"]], "k1_z")
        ax[0, 0].hist(np.clip(z[np.isfinite(z)], -5, 5), bins=np.linspace(-5, 5, 41),
                      density=True, histtype="step",
                      label=f"{c['plan']} {c['turbulence_mps']:g} m/s")
    ax[0, 0].set_xlabel("k1 z-score (clipped at ±5)")
    ax[0, 0].legend(fontsize=8)
    pos = np.arange(len(cells))
    b = ax[0, 1]
    b.bar(pos - 0.2, [c["all_rows_in_2sigma"] for c in cells], 0.4, label="observed")
    b.bar(pos + 0.2, [c["all_rows_in_2sigma_expected"] for c in cells], 0.4,
          label="expected, exact bands")
    b.set_xticks(pos, [f"{c['plan']}\n{c['turbulence_mps']:g} m/s" for c in cells], fontsize=8)
    b.set_ylim(0, 1.05)
    b.set_ylabel("flights with every ΔV row inside ±2σ")
    b.legend(fontsize=8)
    return fig


STUDY = MonteCarloStudy(
    "coverage-tails", "row-by-row and all-rows coverage of the default flights' ΔV bands and U",
    task, cases, summarize, plot, headline, default_runs=100, quick_runs=2)
