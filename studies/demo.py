"""`pitotcal demo`: the whole job on the paper's T-2 case, with known truth to compare against.

Plan the continuous 70-100 KCAS maneuver (0.5 nm = 926 m radius, 800 ft = 244 m, 240 s, 30°
bank, 5 m/s wind from 270°), fly it in the simulator (light turbulence, realistic sensors: 50 Hz
transducer with 0.5 Pa noise, 5 Hz GPS with 0.05 m/s noise), identify the inverse+ model and
the wind, and write everything into one folder, ending with the calibration report (the
deliverable, `pitotcal report`) made from the result just identified.
"""

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pitotcal.core.checks import positive
from pitotcal.core.scenario import T2_PLAN, TRUE_K
from pitotcal.io.atomic import atomic_open
from pitotcal.io.jsonfile import write_json

from .engine.common import truth_delta_v_kt
from .engine.figures import new_figure, save
from .engine.runner import output_folder

__all__ = ["DEMO_SIM", "DemoResult", "format_table", "run_demo"]

log = logging.getLogger(__name__)

# "Light turbulence, realistic sensors": the simulator's defaults, written out here
# so the demo does not change silently when they do.
# Compressible truth, so the flight carries the static port and OAT and the demo shows the
# default calibration (the standard CAS law, ΔV = ΔV_pc).
DEMO_SIM = {"model": "inverse", "k": TRUE_K["inverse"], "turbulence_mps": 0.5, "rate_hz": 50.0,
            "qc_noise_pa": 0.5, "gps_rate_hz": 5.0, "gps_noise_mps": 0.05,
            "air_data": "compressible"}


@dataclass(frozen=True)
class DemoResult:
    """What `run_demo` did.

    Attributes
    ----------
    out_dir : Path
    files : dict
        Role -> path: ``plan_csv``, ``flight_csv``, ``truth_json``, ``result_json``,
        ``plan_png``, ``calibration_png``, ``residuals_png``, ``report_html`` (last).
    table : list of dict
        Rows {vi_kt, dv_kt, dv_2sigma_kt, dv_true_kt} over the flown range.
    result : pitotcal.IdentificationResult
    truth : pitotcal.maneuvers.fly.truth.Truth
        The simulator's truth.
    timing_s : dict
        Seconds spent planning, simulating, identifying (with the budget), writing and making
        the report.
    """

    out_dir: Path
    files: dict
    table: list
    result: object
    truth: object
    timing_s: dict = field(default_factory=dict)


def run_demo(out_dir="pitotcal-demo", *, seed=0, duration_s=T2_PLAN["duration_s"],
             rate_hz=DEMO_SIM["rate_hz"]):
    """Plan, fly and identify the T-2 case (with the GUM uncertainty budget, as `pitotcal identify`
    gives it); write plan, flight, result and figures to `out_dir`.

    Parameters
    ----------
    out_dir : str or Path
        Folder for the outputs (created when missing).
    seed : int
        Simulator seed (the same seed gives the same files).
    duration_s, rate_hz : float
        Maneuver length and data rate (shorter or slower only for quick checks).

    Returns
    -------
    DemoResult
    """
    import time

    from pitotcal.estimation import identify
    from pitotcal.io import write_flight_csv, write_plan
    from pitotcal.maneuvers import plan_maneuver, simulate, write_truth_json

    duration_s, rate_hz = positive("duration_s", duration_s), positive("rate_hz", rate_hz)
    out = output_folder(out_dir, "the plan, flight, result and figures")
    clock = {}
    t0 = time.perf_counter()
    plan = plan_maneuver(**{**T2_PLAN, "duration_s": float(duration_s)})
    clock["plan"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    flight, truth = simulate(plan, seed=seed, **{**DEMO_SIM, "rate_hz": float(rate_hz)})
    clock["simulate"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    # with the GUM uncertainty budget, as `pitotcal identify` gives it
    result = identify(flight, model="inverse", budget=True)
    clock["identify"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    files = {"plan_csv": out / "plan.csv", "flight_csv": out / "flight.csv",
             "truth_json": out / "flight.truth.json", "result_json": out / "result.json"}
    write_plan(plan, files["plan_csv"])
    write_flight_csv(flight, files["flight_csv"], comments={"source": "pitotcal demo",
                                                             "seed": seed})
    write_truth_json(truth, files["truth_json"])
    table = _table(result, truth)
    doc = result.to_dict()
    doc["truth"] = {"model": truth.model, "parameters": truth.parameters}
    doc["demo_table"] = table
    write_json(files["result_json"], doc)
    files["plan_png"] = _plan_figure(plan, out)
    files["calibration_png"] = out / "calibration.png"
    _calibration_figure(result, result.budget, files["calibration_png"])
    files["residuals_png"] = _residual_figure(result, out)
    clock["write"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    files["report_html"] = _report(result, flight, files, out)
    clock["report"] = time.perf_counter() - t0
    return DemoResult(out, {k: Path(v) for k, v in files.items()}, table, result, truth,
                      {k: round(v, 3) for k, v in clock.items()})


def _table(result, truth):
    """Correction rows of the result with the truth ΔV beside each."""
    rows = result.correction_table()
    vi = np.array([r["vi_kt"] for r in rows], dtype=float)
    dv_true = truth_delta_v_kt(truth, vi)
    return [{"vi_kt": float(r["vi_kt"]), "dv_kt": float(r["dv_kt"]),
             "dv_2sigma_kt": float(r["dv_2sigma_kt"]), "dv_true_kt": float(t)}
            for r, t in zip(rows, dv_true)]


def format_table(table, every_kt=5.0):
    """The calibration table as text: KCAS (indicated), ΔV, ±2σ, truth ΔV, inside?"""
    lines = ["  V_i kt   ΔV kt    ±2σ kt   truth ΔV kt   inside ±2σ",
             "  ------   ------   ------   -----------   ----------"]
    last = -np.inf
    for i, row in enumerate(table):
        if row["vi_kt"] - last < every_kt - 1e-6 and i != len(table) - 1:
            continue
        last = row["vi_kt"]
        inside = abs(row["dv_kt"] - row["dv_true_kt"]) <= row["dv_2sigma_kt"]
        lines.append(f"  {row['vi_kt']:6.1f}   {row['dv_kt']:+6.3f}   {row['dv_2sigma_kt']:6.3f}"
                     f"   {row['dv_true_kt']:+11.3f}   {'yes' if inside else 'NO':>10}")
    return "\n".join(lines)


def _report(result, flight, files, out):
    """The calibration report of the result just identified (no second identification)."""
    import json

    from pitotcal.estimation.reporting.calibration_report import build_report, render_html

    doc = json.loads(files["result_json"].read_text())
    options = {"command": "pitotcal demo", "regulation": "23.1323",
               "speed_range_kt": "flown range"}
    context = build_report(doc, flight=flight, ident=result, options=options,
                           inputs=[("Result JSON", files["result_json"]),
                                   ("Flight", files["flight_csv"])])
    path = out / "report.html"
    with atomic_open(path, "w", encoding="utf-8") as fh:
        fh.write(render_html(context))
    return path


def _calibration_figure(result, budget, path):
    """The paper-style calibration figure with the budget's U band on its ΔV panel."""
    from pitotcal.estimation.reporting.budget_tables import plot_budget_band
    from pitotcal.io.atomic import save_figure

    fig = result.plot()
    plot_budget_band(fig.axes[0], result, budget)
    save_figure(fig, path, dpi=110)
    return path


def _plan_figure(plan, out):
    """The planner's plan figure (ground track, CAS schedule, q histogram)."""
    from pitotcal.maneuvers import plot_plan
    path = out / "plan.png"
    plot_plan(plan, path)
    return path


def _residual_figure(result, out):
    """Output residuals vs time and their histogram (white? Gaussian? drifting?)."""
    fig, ax = new_figure(1, 2, size=(4.8, 3.6))
    ax[0, 0].plot(result.time_s, result.residuals_pa, ",", alpha=0.6)
    ax[0, 0].set_xlabel("time, s")
    ax[0, 0].set_ylabel("q_ci residual, Pa")
    ax[0, 0].set_title(f"residual rms {result.noise_std_pa:.2f} Pa, N = {result.n_samples}")
    ax[0, 1].hist(result.residuals_pa, bins=60, density=True, alpha=0.7)
    x = np.linspace(*ax[0, 1].get_xlim(), 200)
    s = max(float(result.noise_std_pa), 1e-9)
    ax[0, 1].plot(x, np.exp(-0.5 * (x / s) ** 2) / (s * np.sqrt(2 * np.pi)), "k-", lw=1)
    ax[0, 1].set_xlabel("q_ci residual, Pa")
    ax[0, 1].set_ylabel("probability density, 1/Pa")
    ax[0, 1].set_title("histogram and the normal of the same rms")
    return Path(save(fig, out, "residuals.png"))

