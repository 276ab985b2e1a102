"""`jets`: real jet flight-test points calibrated by two methods, against a radiosonde and JMOSS.

Every ``CLASS*.csv`` in `--data DIR` (a test point of the USAF Test Pilot School's export: GPS
velocity, pitot total and static-port pressure, a total-temperature probe, GPS height, attitude
and sideslip vane; read through `TPS_EXPORT_MAP` and `TPS_ATTITUDE_MAP`, or through
``DIR/columns.toml`` when present) is calibrated by

- output error with the Mach-dependent static error (its 2σ with the spline's representation
  error), the probe's recovery and the OAT, and, when the attitude is mapped, the airspeed's
  direction with the heading/vane misalignment and the attitude's time offset as unknowns
  (`pitotcal.estimation.identification.mach_oe.identify_mach`), and
- the self-survey (`pitotcal.estimation.survey.self_survey`),

each with every sample through Mach 1. ``DIR/WB.txt``, when present, is the radiosonde: its wind
and temperature at each point's median GPS height, and how much its own wind changes within
±`SONDE_LAYER_FT` of it. ``jmoss.json`` in DIR or in the output folder
(written by ``benchmarks/bench_jmoss.py --out``), when present, adds JMOSS's curve, wind and OAT.
Nothing is per file: a new test point in DIR is calibrated the same way.

Outputs: ``jets.csv`` (a row per point and method), ``jets.json`` (``points``: the output-error
numbers of each point, the self-survey's under ``self_survey``, JMOSS's under ``jmoss``) and
``jets.png``.
"""

import json
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import ft_to_m, m_to_ft, mps_to_kt
from pitotcal.estimation.identification.mach_oe import identify_mach, position_corrections
from pitotcal.estimation.survey import self_survey
from pitotcal.io.mapped_csv import mapped_attitude, read_mapped_csv
from pitotcal.io.radiosonde import read_sounding

from ..engine.runner import RunsInterrupted
from ..engine.study import Collected
from .figure import plot_jets

__all__ = ["COMPARE_MACH_IC", "STUDY", "TPS_ATTITUDE_MAP", "TPS_EXPORT_MAP", "JetsStudy",
           "calibrate_point"]

NAME = "jets"
# The Test Pilot School export's columns (the JMOSS sample format).
TPS_EXPORT_MAP = """\
time              = { column = "time_s",          unit = "s" }
gps_vn            = { column = "north_vel_fps",   unit = "ft/s" }
gps_ve            = { column = "east_vel_fps",    unit = "ft/s" }
gps_vd            = { column = "down_vel_fps",    unit = "ft/s" }
total_pressure    = { column = "total_pres_psi",  unit = "psi" }
static_pressure   = { column = "static_pres_psi", unit = "psi" }
total_temperature = { column = "total_temp_K",    unit = "K" }
gps_height        = { column = "height_ft",       unit = "ft" }
"""
# Its attitude and sideslip vane: the output error then compares the airspeed as a vector too.
TPS_ATTITUDE_MAP = """\
roll              = { column = "roll_angle_rad",   unit = "rad" }
pitch             = { column = "pitch_angle_rad",  unit = "rad" }
true_heading      = { column = "true_heading_rad", unit = "rad" }
sideslip          = { column = "aos_rad",          unit = "rad" }
"""
# Half the depth of the layer over which the sounding's own wind change is reported: a sounding
# taken tens of kilometres and minutes away may place a thin wind feature this far off.
SONDE_LAYER_FT = 500.0
# M_ic where the methods' curves are compared: below the transonic rise, where JMOSS's curve holds.
COMPARE_MACH_IC = tuple(np.round(np.arange(0.55, 0.9001, 0.05), 2))
_COLUMNS = ("point", "method", "altitude_ft", "wind_n_kt", "wind_e_kt", "wind_2sigma_kt",
            "wind_miss_kt", "oat_k", "oat_2sigma_k", "oat_minus_sonde_k", "recovery",
            "recovery_2sigma")


def calibrate_point(path, mapping, sonde=None):
    """Both methods on one test point: the point's JSON entry (module notes)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        flight = read_mapped_csv(path, mapping)
    h_m = float(np.median(flight.alt_m))
    at = sonde.at(h_m) if sonde is not None else None
    start = time.perf_counter()
    oe = identify_mach(flight, attitude=mapped_attitude(path, mapping))
    oe_s = time.perf_counter() - start
    start = time.perf_counter()
    ss = self_survey(flight)
    ss_s = time.perf_counter() - start
    entry = _method_entry(Path(path).stem, h_m, oe.to_dict(), at, oe_s)
    entry["n_samples"] = int(flight.n)
    entry["self_survey"] = _method_entry(Path(path).stem, h_m, _with_corrections(
        ss.to_dict(), float(np.median(flight.ps_pa))), at, ss_s)
    if at is not None:
        entry["radiosonde"] = {"wind_n_kt": float(mps_to_kt(at["wind_n_mps"])),
                               "wind_e_kt": float(mps_to_kt(at["wind_e_mps"])),
                               "temp_k": at["temp_k"], "ps_pa": at["ps_pa"],
                               "wind_spread_500ft_kt": float(mps_to_kt(sonde.wind_spread_mps(
                                   h_m, ft_to_m(SONDE_LAYER_FT))))}
    return entry


def _with_corrections(d, psi_pa):
    """The self-survey's bins with ΔV_pc, ΔM_pc, ΔH_pc at the point's median p_si."""
    m = np.array([s["mach_ic"] for s in d["spe"]])
    g = np.array([s["dpp_ps"] for s in d["spe"]])
    dv, dm, dh = position_corrections(m, g, psi_pa)
    spe = [{**s, "dv_kt": float(v), "dm": float(a), "dh_ft": float(h)}
           for s, v, a, h in zip(d["spe"], dv, dm, dh)]
    return {**d, "spe": spe}


def _method_entry(name, h_m, d, at, elapsed_s):
    """The keys of ``points[i]`` from a method's `to_dict`."""
    out = {"name": name, "altitude_ft": float(m_to_ft(h_m)),
           "wind_n_kt": float(mps_to_kt(d["wind_n_mps"])),
           "wind_e_kt": float(mps_to_kt(d["wind_e_mps"])),
           "wind_2sigma_kt": float(mps_to_kt(d["wind_2sigma_mps"])),
           "oat_k": d["oat_k"], "oat_2sigma_k": d["oat_2sigma_k"], "recovery": d["recovery"],
           "recovery_2sigma": d["recovery_2sigma"],
           "recovery_at_bound": d["recovery_at_bound"], "n_fit": d["n_fit"],
           "elapsed_s": round(elapsed_s, 2),
           "spe": [{k: s[k] for k in ("mach_ic", "dpp_ps", "dpp_ps_2sigma",
                                      "dpp_ps_spline_2sigma", "dv_kt", "dm", "dh_ft") if k in s}
                   for s in d["spe"]]}
    for key in ("airspeed_model", "misalignment_deg", "misalignment_2sigma_deg", "latency_s",
                "latency_2sigma_s"):
        if key in d:
            out[key] = d[key]
    if at is not None:
        out["wind_miss_kt"] = float(mps_to_kt(np.hypot(d["wind_n_mps"] - at["wind_n_mps"],
                                                       d["wind_e_mps"] - at["wind_e_mps"])))
        out["oat_minus_sonde_k"] = d["oat_k"] - at["temp_k"]
    return out


def _curve_at(spe, mach):
    """(Δp_p/p_s, 2σ) of a curve's points interpolated at `mach` (NaN outside them)."""
    m = np.array([s["mach_ic"] for s in spe])
    if m.size < 2:
        return np.full(len(mach), np.nan), np.full(len(mach), np.nan)
    order = np.argsort(m)
    vals = [np.interp(mach, m[order], np.array([s.get(k, np.nan) for s in spe])[order], left=np.nan,
                      right=np.nan) for k in ("dpp_ps", "dpp_ps_2sigma")]
    return vals[0], vals[1]


def compare_with_jmoss(entry, jmoss):
    """Each method's Δp_p/p_s minus JMOSS's on `COMPARE_MACH_IC`, and whether it lies within
    the method's 2σ (JMOSS's own band is not a usable bound: docs/measured.md)."""
    jm, _ = _curve_at(jmoss["spe"], COMPARE_MACH_IC)
    out = {}
    for method, d in (("output_error", entry), ("self_survey", entry["self_survey"])):
        ours, two_s = _curve_at(d["spe"], COMPARE_MACH_IC)
        ok = np.isfinite(ours) & np.isfinite(jm)
        out[method] = {"mach_ic": [m for m, k in zip(COMPARE_MACH_IC, ok) if k],
                       "minus_jmoss": [float(v) for v in (ours - jm)[ok]],
                       "two_sigma": [float(v) for v in two_s[ok]],
                       "within_2sigma": bool(np.all(np.abs(ours - jm)[ok] <= two_s[ok]))}
    return out


def _jmoss_entries(data_dir, out_dir):
    """JMOSS's results by point from ``jmoss.json`` (bench_jmoss.py's --out), or {}."""
    for folder in (data_dir, out_dir):
        path = Path(folder) / "jmoss.json"
        if path.exists():
            raw = json.loads(path.read_text())
            return {name: _jmoss_entry(v.get("jmoss", v)) for name, v in raw.items()
                    if isinstance(v, dict) and "wind_ned_kt" in v.get("jmoss", v)}
    return {}


def _jmoss_entry(j):
    return {"wind_n_kt": j["wind_ned_kt"][0], "wind_e_kt": j["wind_ned_kt"][1],
            "oat_k": j["oat_k"], "recovery": j["eta"],
            "spe": [{"mach_ic": s["mach_ic"], "dpp_ps": s["dpp_ps"]} for s in j["spe_model"]]}


@dataclass(frozen=True)
class JetsStudy:
    """The `jets` study (module notes): one run, in process."""

    name: str = NAME
    description: str = ("real jet test points (the folder's CLASS*.csv) through Mach 1: output "
                        "error with a Mach-dependent static error and the probe's recovery, "
                        "and the self-survey, against the radiosonde and JMOSS")

    def collect(self, settings):
        if settings.data_dir is None:
            raise PitotcalError("study jets needs `data_dir`, the folder of the CLASS*.csv "
                                "test points", param="data_dir")
        data = Path(settings.data_dir)
        files = sorted(data.glob("CLASS*.csv"))
        if not files:
            raise PitotcalError(f"`data_dir` {data} has no CLASS*.csv test point",
                                param="data_dir")
        custom = data / "columns.toml"
        mapping = custom if custom.exists() else _default_mapping()
        sonde = read_sounding(data / "WB.txt") if (data / "WB.txt").exists() else None
        points = []
        try:
            for i, path in enumerate(files):
                points.append(calibrate_point(path, mapping, sonde))
                if settings.progress:
                    settings.progress(i + 1, len(files))
        except KeyboardInterrupt:
            raise RunsInterrupted(_rows(points), len(points), len(files)) from None
        return Collected(rows=_rows(points), n_runs=len(files),
                         details={"points": points, "data_dir": str(data)},
                         columns=_COLUMNS)

    def report(self, collected, out_dir):
        points = collected.details["points"]
        jmoss = _jmoss_entries(collected.details["data_dir"], out_dir)
        for p in points:
            if p["name"] in jmoss:
                p["jmoss"] = jmoss[p["name"]]
                if "radiosonde" in p:
                    s = p["radiosonde"]
                    p["jmoss"]["wind_miss_kt"] = float(np.hypot(
                        p["jmoss"]["wind_n_kt"] - s["wind_n_kt"],
                        p["jmoss"]["wind_e_kt"] - s["wind_e_kt"]))
                    p["jmoss"]["oat_minus_sonde_k"] = p["jmoss"]["oat_k"] - s["temp_k"]
                p["versus_jmoss"] = compare_with_jmoss(p, p["jmoss"])
        path = plot_jets(out_dir, f"{NAME}.png", points)
        return {"points": points, "compare_mach_ic": list(COMPARE_MACH_IC)}, [path]

    def headline(self, summary):
        parts = []
        for p in summary.get("points", []):
            miss = p.get("wind_miss_kt")
            sonde = "" if miss is None else (f", wind {miss:.1f} kt and OAT "
                                             f"{p['oat_minus_sonde_k']:+.1f} K from the sonde")
            parts.append(f"{p['name']} r {p['recovery']:.3f}{sonde}")
        return "; ".join(parts) or "no test point"

    def repeat(self, settings, run_index):
        return self.collect(settings).rows[2 * run_index:2 * run_index + 2]


def _default_mapping():
    """`TPS_EXPORT_MAP` and `TPS_ATTITUDE_MAP` as the reader's mapping dict: key -> (column,
    unit)."""
    import tomllib

    return {k: (v["column"], v["unit"])
            for k, v in tomllib.loads(TPS_EXPORT_MAP + TPS_ATTITUDE_MAP).items()}


def _rows(points):
    """The table: one row per point and method, the curve at `COMPARE_MACH_IC`."""
    rows = []
    for p in points:
        for method, d in (("output_error", p), ("self_survey", p["self_survey"])):
            row = {"point": p["name"], "method": method,
                   **{k: d.get(k) for k in _COLUMNS[2:]}}
            values, two_s = _curve_at(d["spe"], COMPARE_MACH_IC)
            for m, v, s in zip(COMPARE_MACH_IC, values, two_s):
                row[f"dpp_ps_{m:.2f}"] = None if np.isnan(v) else float(v)
                row[f"dpp_ps_2sigma_{m:.2f}"] = None if np.isnan(s) else float(s)
            rows.append(row)
    return rows


STUDY = JetsStudy()
