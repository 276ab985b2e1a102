"""What every study run does: plan (cached), fly, identify, and score the result against truth.

Only the public API of `maneuvers` and `estimation` is used. Plans and flights are cached per
process (a Dask worker keeps its cache between runs), so a sweep that re-identifies one flight
several ways, or flies one plan many times, plans and simulates once.
"""

import dataclasses
import functools
import json

import numpy as np

from pitotcal.core.checks import wrap_deg
from pitotcal.core.models import delta_v_kt, get_model
from pitotcal.core.scenario import T2_PLAN
from pitotcal.core.units import incompressible_cas_mps, mps_to_kt, wind_polar

__all__ = [
    "N_DV_GRID",
    "accuracy_summary",
    "column",
    "first_seconds",
    "fly",
    "get_plan",
    "group",
    "identify_flight",
    "ok_rows",
    "percent",
    "run_fly_identify",
    "score",
    "stats",
    "truth_delta_v_kt",
    "truth_for",
    "vi_grid_kt",
    "window_wind",
]

N_DV_GRID = 7   # points of the V_i grid on which ΔV is scored


def _key(mapping):
    return json.dumps(mapping or {}, sort_keys=True)


def get_plan(**plan_kwargs):
    """`maneuvers.plan_maneuver(**plan_kwargs)`, cached per process (T-2 defaults filled in)."""
    return _plan_cached(_key({**T2_PLAN, **plan_kwargs}))


@functools.lru_cache(maxsize=32)
def _plan_cached(key):
    from pitotcal.maneuvers import plan_maneuver
    return plan_maneuver(**json.loads(key))


def fly(plan_kwargs=None, sim_kwargs=None, seed=0):
    """(Flight, truth) of `maneuvers.simulate` on the (cached) plan; cached per process."""
    return _fly_cached(_key({**T2_PLAN, **(plan_kwargs or {})}), _key(sim_kwargs), int(seed))


@functools.lru_cache(maxsize=4)
def _fly_cached(plan_key, sim_key, seed):
    from pitotcal.maneuvers import simulate
    sim = json.loads(sim_key)
    for name in ("k", "wind_drift_mps2"):      # JSON turned tuples into lists
        if name in sim:
            sim[name] = tuple(sim[name])
    # keep_history: the wind flown through, to give a part of the flight its own truth
    return simulate(_plan_cached(plan_key), seed=seed, keep_history=True, **sim)


def _window_mean_wind(truth, flight):
    """Mean wind vector (TO, m/s) flown through at the samples of `flight`, or None when the
    truth keeps no history of them."""
    hist = truth.history
    if not hist or "wind_n_mps" not in hist:
        return None
    t = np.asarray(hist["time_s"], dtype=float)
    pick = np.isin(np.round(t, 6), np.round(flight.time_s, 6))
    if not pick.any():
        return None
    return (float(np.mean(np.asarray(hist["wind_n_mps"])[pick])),
            float(np.mean(np.asarray(hist["wind_e_mps"])[pick])))


def window_wind(truth, flight):
    """The true wind vector (wind_n_mps, wind_e_mps; TO) of the samples in `flight` (a part of
    the simulated one): the time-average of the wind flown through over their times (the whole
    flight's average when the truth keeps no history)."""
    mean = _window_mean_wind(truth, flight)
    return mean if mean is not None else (float(truth.wind_n_mps), float(truth.wind_e_mps))


def truth_for(truth, flight):
    """The truth of the samples in `flight` (a part of the simulated one): the wind becomes
    the time-average over those samples' times."""
    mean = _window_mean_wind(truth, flight)
    if mean is None:
        return truth
    speed, from_deg = wind_polar(*mean)
    params = {**truth.parameters, "wind_speed_mps": float(speed),
              "wind_from_deg": float(from_deg)}
    return dataclasses.replace(truth, parameters=params)


def identify_flight(flight, model="inverse"):
    """`estimation.identify` with the study defaults (GPS noise estimated from the data)."""
    from pitotcal.estimation import identify
    return identify(flight, model=model)


def first_seconds(flight, seconds):
    """The first `seconds` of a flight (all of it when None)."""
    if seconds is None:
        return flight
    return flight.window(flight.time_s[0], flight.time_s[0] + float(seconds))


def truth_delta_v_kt(truth, vi_kt):
    """The true ΔV (kt) of a simulator `Truth` at indicated `vi_kt`, by the airspeed law of
    its air data (the standard CAS law for compressible truth)."""
    model = get_model(truth.model)
    return delta_v_kt(model, [truth.parameters[p] for p in model.params], vi_kt,
                      getattr(truth, "air_data", "incompressible"))


def vi_grid_kt(qci_pa, n=N_DV_GRID):
    """`n` indicated airspeeds (kt) spanning the 2-98 % range of the impact pressures flown."""
    vi_kt = mps_to_kt(incompressible_cas_mps(np.maximum(qci_pa, 0.0)))
    lo, hi = np.percentile(vi_kt, [2.0, 98.0])
    return np.linspace(lo, hi, n)


def score(result, truth, flight=None):
    """Flat row: estimates, 1-σ (corrected and plain), truth, error and z of every parameter,
    and the airspeed correction ΔV against truth over the flown V_i range.

    Columns: ``success``, ``iterations``, ``n_samples``, ``noise_std_pa``; for each parameter P
    reported by both: ``P``, ``P_std``, ``P_std_plain``, ``P_true``, ``P_err`` (direction wrapped
    to ±180°), ``P_z``, ``P_z_plain``; ``dv_err_max_kt`` (largest |ΔV error| on the grid),
    ``dv_2sigma_max_kt``, ``dv_2sigma_mean_kt``, ``dv_inside_2sigma`` (fraction of grid points
    whose truth lies inside ±2σ), ``dv_true_mean_kt``, ``vi_min_kt``, ``vi_max_kt``.
    """
    truth_params = truth.parameters
    row = {"success": bool(result.success), "iterations": int(result.iterations),
           "n_samples": int(result.n_samples), "noise_std_pa": float(result.noise_std_pa)}
    for i, name in enumerate(result.param_names):
        if name not in truth_params or truth_params[name] is None:
            continue
        est, true = float(result.params[i]), float(truth_params[name])
        std = float(np.sqrt(result.covariance[i, i]))
        std_plain = float(np.sqrt(result.covariance_plain[i, i]))
        err = float(wrap_deg(est - true)) if name.endswith("_deg") else est - true
        row.update({name: est, f"{name}_std": std, f"{name}_std_plain": std_plain,
                    f"{name}_true": true, f"{name}_err": err,
                    f"{name}_z": err / std if std > 0 else float("nan"),
                    f"{name}_z_plain": err / std_plain if std_plain > 0 else float("nan")})
    grid = vi_grid_kt(result.qci_pa if flight is None else flight.qci_pa)
    lo, hi = grid[0], grid[-1]
    dv, dv_2s = result.delta_v_kt(grid)
    dv_true = truth_delta_v_kt(truth, grid)
    err = np.abs(dv - dv_true)
    row.update({"dv_err_max_kt": float(err.max()), "dv_2sigma_max_kt": float(dv_2s.max()),
                "dv_2sigma_mean_kt": float(dv_2s.mean()),
                "dv_inside_2sigma": float(np.mean(err <= dv_2s)),
                "dv_true_mean_kt": float(dv_true.mean()),
                "vi_min_kt": float(lo), "vi_max_kt": float(hi)})
    return row


def run_fly_identify(seed, plan=None, sim=None, model="inverse", seconds=None):
    """Plan, fly and identify one flight (optionally only its first `seconds`); the scored row."""
    flight, truth = fly(plan, sim, seed)
    used = first_seconds(flight, seconds)
    return score(identify_flight(used, model), truth_for(truth, used), used)


# --- small helpers for summaries ----------------------------------------------------------

def ok_rows(rows):
    """The rows of runs that finished (no error) and whose solver converged."""
    # "True" as text: rows read back from a CSV (studies.engine.runner.read_table)
    return [r for r in rows if not r.get("error") and r.get("success", True) in (True, "True")]


def column(rows, name):
    """Values of one column as a float array (missing -> NaN)."""
    return np.array([float(r.get(name, np.nan)) if r.get(name) is not None else np.nan
                     for r in rows], dtype=float)


def group(rows, *keys):
    """Rows grouped by the values of `keys`, in first-seen order: {(v1, ...): [rows]}."""
    out = {}
    for r in rows:
        out.setdefault(tuple(r.get(k) for k in keys), []).append(r)
    return out


def stats(rows, name):
    """{median, mean, rms, p95_abs, n} of a column over finite values (NaN when none)."""
    x = column(rows, name)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return {"median": None, "mean": None, "rms": None, "p95_abs": None, "n": 0}
    return {"median": float(np.median(x)), "mean": float(np.mean(x)),
            "rms": float(np.sqrt(np.mean(x ** 2))),
            "p95_abs": float(np.percentile(np.abs(x), 95.0)), "n": int(x.size)}


def accuracy_summary(rows, **extra_errors):
    """Per-case accuracy of ΔV and the wind over a group of run rows (failed runs counted)."""
    good = ok_rows(rows)
    summary = {
        "n_runs": len(rows), "n_ok": len(good),
        "dv_2sigma_max_kt": stats(good, "dv_2sigma_max_kt")["median"],
        "dv_err_max_kt_rms": stats(good, "dv_err_max_kt")["rms"],
        "dv_inside_2sigma": stats(good, "dv_inside_2sigma")["mean"],
        "wind_speed_err_rms_mps": stats(good, "wind_speed_mps_err")["rms"],
    }
    summary.update({key: stats(good, name)["rms"] for key, name in extra_errors.items()})
    summary["errors"] = sorted({r["error"] for r in rows if r.get("error")})
    return summary


def percent(fraction):
    """A fraction as a percentage with one decimal, none when whole: 0.961 -> "96.1%",
    0.085 -> "8.5%" (not "8%"), 1.0 -> "100%"."""
    return f"{fraction:.1%}".replace(".0%", "%")
