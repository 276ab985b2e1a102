"""The result record: the JSON of an `IdentificationResult` (docs/interfaces.md §3).

`identify` computes, once, every product the record holds (the residuals' noise model the
monitor designs from, the measured static-error fit, the uncertainty budget, the GPS-error
statement and how the flight was read: `estimation.identification.identify.complete`);
`to_dict` writes them out and never re-fits. The one reader of a record, for `identify --live`,
`report`, `monitor` and `plan --calibration` alike, is `pitotcal.io.result_record.read_result`.
"""

from pitotcal.core.models import get_model
from pitotcal.core.units import m_to_ft
from pitotcal.io.jsonfile import json_ready

from . import static_source

__all__ = ["to_dict", "with_budget"]

_WIND_UNITS = {"wind_speed_mps": "m/s", "wind_from_deg": "deg"}


def to_dict(result):
    """The record `pitotcal identify --json` writes (docs/interfaces.md §3); no NaN (null).

    Returns
    -------
    dict
        model, formula, parameters {name: {value, std, std_plain, unit}}, covariance and
        covariance_plain {names, matrix}, correlation {names, matrix}, n_samples, converged,
        message, iterations, warnings, airspeed_correction (rows of `correction_table`, with
        dv_U_kt when there is a budget), noise_std_pa, gps_noise_std_mps, candidates,
        criterion, timing_s, air_data, consistency (when it ran), static_source (compressible),
        source, n_dropped, uncertainty_budget (with a budget), noise_model (absent for a record
        too short for it), gps_error, reading; windows and cut_s when the windows were
        chosen from a whole-flight log (`pitotcal.io.windows`); wind_model and wind_track
        (when fitted).
    """
    from .view import correction_table

    model = get_model(result.model)
    units = dict(zip(model.params, model.units), **_WIND_UNITS)
    names = list(result.param_names)
    std, std_plain = result.std, result.std_plain
    out = {
        "model": result.model,
        "formula": model.formula,
        "parameters": {
            name: {"value": result.params[i], "std": std[i], "std_plain": std_plain[i],
                   "unit": units.get(name, "")}
            for i, name in enumerate(names)},
        "covariance": {"names": names, "matrix": result.covariance},
        "covariance_plain": {"names": names, "matrix": result.covariance_plain},
        "correlation": {"names": names, "matrix": result.correlation},
        "n_samples": result.n_samples,
        "converged": bool(result.converged),
        "message": result.message,
        "iterations": result.iterations,
        "warnings": list(result.warnings),
        "airspeed_correction": correction_table(result),
        "noise_std_pa": result.noise_std_pa,
        "gps_noise_std_mps": result.gps_noise_std_mps,
        "candidates": list(result.candidates),
        "criterion": result.criterion,
        "timing_s": dict(result.timing_s),
        "air_data": result.air_data,
    }
    if result.consistency:          # docs/interfaces.md §20
        out["consistency"] = dict(result.consistency)
    if result.air_data == "compressible":
        out["static_source"] = _static_source_record(result)
    out.update(source=result.source, n_dropped=int(result.n_dropped))
    if result.budget is not None:
        out = with_budget(out, result.budget)
    if result.monitor_noise is not None:       # absent for a record too short for it
        out["noise_model"] = result.monitor_noise
    reading = dict(result.reading) if result.reading is not None else None
    if reading and reading.get("windows"):      # the windows chosen from a whole-flight log
        out.update(windows=reading.pop("windows"), cut_s=reading.pop("cut_s", {}))
    out.update(gps_error=result.gps_error, reading=reading)
    if result.wind_model is not None:       # docs/interfaces.md §3, the wind model
        out.update(wind_model=result.wind_model, wind_track=result.wind_track)
    return json_ready(out)


def _static_source_record(result):
    """{"assumed", "pressure_altitude_ic_ft"[, "k_static"]}: what was assumed or measured."""
    h_ic = static_source.pressure_altitude_ic_m(result)
    statement, fit = static_source.static_statement(result)
    out = {"assumed": statement,
           "pressure_altitude_ic_ft": None if h_ic is None else float(m_to_ft(h_ic))}
    if fit is not None:
        out["k_static"] = fit
    return out


def with_budget(out, budget):
    """`out` (a record) with `dv_U_kt` and `u_dv_by_source_kt` (each source's standard
    uncertainty of ΔV at that speed, kt) per correction row, a compressible result's ΔH and ΔM
    the same (`Budget.product_row`), `uncertainty_budget`, `budget_inputs` (every input, its
    value and where it came from) and the budget's warnings; the rows are matched by speed (the
    budget has the table's speeds)."""
    at = {round(float(v), 6): i for i, v in enumerate(budget.vi_kt)}
    new_rows = []
    for row in out.get("airspeed_correction", []):
        i = at.get(round(float(row["vi_kt"]), 6))
        new_rows.append({**row, **({"dv_U_kt": None} if i is None else {
            "dv_U_kt": float(budget.expanded_kt[i]),
            "u_dv_by_source_kt": {"statistical": float(budget.statistical_kt[i]),
                                  **{n: float(u[i]) for n, u in budget.terms_kt.items()}},
            **budget.product_row(i)})})
    warnings = list(out.get("warnings", []))
    warnings += [w for w in budget.warnings if w not in warnings]
    return json_ready({**out, "airspeed_correction": new_rows,
                       "uncertainty_budget": budget.to_list(),
                       "budget_inputs": list(getattr(budget, "input_list", ())),
                       "warnings": warnings})
