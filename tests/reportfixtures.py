"""Constructed result JSONs for the report and compliance tests: with and without the
additions of the air-data issue (dv_U_kt, dh_ft, air_data, uncertainty_budget) and of the
legs command ("points", "global")."""

import numpy as np


def result_json(dv_kt=-1.0, band_kt=0.3, u_kt=None, dh_ft=None, dh_2sigma_ft=2.0,
                vi_kt=(70.0, 100.0), step_kt=5.0, legs=False, altitude_ft=0.0, dh_u_ft=None):
    """A result dict whose correction is the constant `dv_kt` (or a function of V_i) with 2σ
    `band_kt`; `u_kt` adds dv_U_kt (and an uncertainty budget), `dh_ft` adds the altimeter
    columns (at the indicated pressure altitude `altitude_ft`; `dh_u_ft` their expanded U) and
    the compressible air-data keys."""
    vi = np.arange(vi_kt[0], vi_kt[1] + 1e-9, step_kt)
    rows = []
    for v in vi:
        d = float(dv_kt(v) if callable(dv_kt) else dv_kt)
        row = {"vi_kt": float(v), "dv_kt": d, "dv_2sigma_kt": band_kt,
               "dv_2sigma_plain_kt": band_kt / 3, "vc_kt": float(v) + d}
        if u_kt is not None:
            row["dv_U_kt"] = u_kt
        if dh_ft is not None:
            row.update(mach_i=float(v) / 661.5, dmach=d / 661.5,
                       dh_ft=float(dh_ft(v) if callable(dh_ft) else dh_ft),
                       dh_2sigma_ft=dh_2sigma_ft)
            if dh_u_ft is not None:
                row["dh_U_ft"] = float(dh_u_ft(v) if callable(dh_u_ft) else dh_u_ft)
        rows.append(row)
    out = {
        "model": "inverse", "formula": "dp/qc = k1 + k2/qci",
        "parameters": {"k1": {"value": 0.02, "std": 0.001, "std_plain": 0.0004, "unit": ""},
                       "k2": {"value": 5.0, "std": 0.5, "std_plain": 0.2, "unit": "Pa"},
                       "wind_speed_mps": {"value": 5.1, "std": 0.05, "std_plain": 0.02,
                                          "unit": "m/s"},
                       "wind_from_deg": {"value": 271.0, "std": 0.6, "std_plain": 0.2,
                                         "unit": "deg"}},
        "n_samples": 12000, "converged": True, "message": "Solve_Succeeded", "iterations": 9,
        "warnings": ["constructed for a test"], "airspeed_correction": rows,
        "noise_std_pa": 0.6, "gps_noise_std_mps": 0.05, "candidates": [], "criterion": None,
        "timing_s": {"build": 0.1, "solve": 0.2}, "source": "flight.csv", "n_dropped": 0,
    }
    if u_kt is not None:
        out["uncertainty_budget"] = [{"source": "statistical", "u_dv_kt": band_kt / 2},
                                     {"source": "transducer calibration", "u_dv_kt": 0.2}]
    if dh_ft is not None:
        out["air_data"] = "compressible"
        out["static_source"] = {"assumed": "all pressure error in the static source",
                                "pressure_altitude_ic_ft": altitude_ft}
    if legs:
        out["points"] = [{"point": i + 1, "ias_kt": 70.0 + 10 * i, "tas_kt": 73.0 + 10 * i,
                          "tas_2sigma_kt": 0.4, "wind_speed_kt": 9.8, "wind_from_deg": 270.0,
                          "dv_kt": -1.0, "dv_2sigma_kt": 0.5, "method": "three-leg"}
                         for i in range(3)]
        out["global"] = {"model": "inverse", "dv_kt_at_80": -1.0}
    return out


def setting(path, value):
    """An edit of a parsed JSON document: the key at `path` (keys and indices) set to `value`."""
    def edit(doc):
        node = doc
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value
    return edit
