"""JMOSS as a peer: its static position error, wind and OAT on the shared jet test points, beside
pitotcal's self-survey and output-error fit and the radiosonde.

    python benchmarks/bench_jmoss.py [--data DIR] [--cache DIR] [--source URL] [--python PY]
                                     [--out OUT.json]

JMOSS (SaguaroAerospaceResearch/JMOSS, MIT; Jurado & McGehee, J. Aircraft 56(2), 2019) is cloned
at run time into the cache folder, never vendored, and run with the two one-line fixes it needs
for current numpy and matplotlib (`mach[index] = sol[0]`; `matplotlib.colormaps['tab20']`).
It reads pandas, so `--python` names an interpreter that has numpy, scipy, pandas and
matplotlib (default: this one). Only the test points named by `--points` (default CLASS55,
CLASS65) are read, from `--data` (default: the shared jmoss folder); JMOSS's own sample_data
folder is never read. Without a network (or git) the script says so and exits 0 (skipped).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from pitotcal.studies.jets.study import TPS_ATTITUDE_MAP, TPS_EXPORT_MAP

SOURCE = "https://github.com/SaguaroAerospaceResearch/JMOSS"
COMMIT = "8d5b162"
FIXES = (("JMOSS/utilities.py", "mach[index] = sol\n", "mach[index] = sol[0]\n"),
         ("JMOSS/visualization.py", "cm.get_cmap('tab20').colors",
          "__import__('matplotlib').colormaps['tab20'].colors"))
MAPPING = TPS_EXPORT_MAP + TPS_ATTITUDE_MAP
GRID = [0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 1.0]

# Run by the JMOSS interpreter: argv = repo, out.json, files...
DRIVER = r"""
import contextlib, io, json, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
from JMOSS.estimation import JmossEstimator
names = {'time': 'time_s', 'north velocity': 'north_vel_fps', 'east velocity': 'east_vel_fps',
         'down velocity': 'down_vel_fps', 'geometric height': 'height_ft',
         'total pressure': 'total_pres_psi', 'static pressure': 'static_pres_psi',
         'total temperature': 'total_temp_K', 'angle of attack': 'aoa_rad',
         'angle of slideslip': 'aos_rad', 'roll angle': 'roll_angle_rad',
         'pitch angle': 'pitch_angle_rad', 'true heading': 'true_heading_rad'}
grid = np.array(%s)
out = {}
with contextlib.redirect_stdout(io.StringIO()):
    est = JmossEstimator(names)
    for f in sys.argv[3:]:
        est.add_test_point(f)
    est.process_test_points()
    for label, r in est.spe_results.items():
        est.fit_model(labels=[label])
        top = float(r.mach_ic[~r.turn_idx].max())
        g = grid[(grid >= r.mach_ic[~r.turn_idx].min()) & (grid <= top)]
        spe, ci = est.spe_model.predict(mach_ic=g, alpha=0.0455)   # 2 sigma
        out[label] = {
            'wind_ned_kt': [float(v) for v in r.wind],
            'wind_sigma_kt': [float(r.sigmas[k]) for k in ('north wind', 'east wind', 'down wind')],
            'eta': float(r.eta), 'eta_sigma': float(r.sigmas['eta']),
            'oat_k': float(np.mean(r.oat)), 'oat_sigma_k': float(np.mean(r.sigmas['oat'])),
            'pa_bias_ft': float(r.pa_bias), 'mach_ic_max': float(r.mach_ic.max()),
            'spe_model': [{'mach_ic': float(m), 'dpp_ps': float(s), 'dpp_ps_2sigma': float(c)}
                          for m, s, c in zip(g, spe, ci)],
            'spe_sample_2sigma_median': float(2 * np.median(r.sigmas['spe ratio']))}
json.dump(out, open(sys.argv[2], 'w'), indent=1)
""" % GRID


def fetch_jmoss(cache, source):
    """The patched JMOSS clone in `cache`, or None (with the reason) when it cannot be had."""
    repo = Path(cache) / "JMOSS"
    if not (repo / ".git").exists():
        run = subprocess.run(["git", "clone", "-q", source, str(repo)], capture_output=True,
                             text=True, check=False)
        if run.returncode != 0:
            return None, f"cannot clone {source}: {run.stderr.strip().splitlines()[-1:]}"
    subprocess.run(["git", "-C", str(repo), "checkout", "-q", "--force", COMMIT], check=True)
    for rel, old, new in FIXES:
        path = repo / rel
        text = path.read_text()
        if text.count(old) != 1:
            return None, f"{rel}: the line to fix ({old.strip()!r}) is not there once"
        path.write_text(text.replace(old, new))
    return repo, None


def run_jmoss(python, repo, files):
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "jmoss.json"
        env = {**os.environ, "MPLBACKEND": "Agg"}
        subprocess.run([python, "-c", DRIVER, str(repo), str(out), *map(str, files)],
                       check=True, env=env)
        return json.loads(out.read_text())


def run_pitotcal(files, sounding_path):
    """pitotcal's self-survey and output-error fit on each point, and the radiosonde there."""
    import warnings

    from pitotcal.core.units import mps_to_kt
    from pitotcal.estimation.identification.identify import identify
    from pitotcal.estimation.identification.mach_oe import identify_mach
    from pitotcal.estimation.survey import self_survey
    from pitotcal.io import read_flight
    from pitotcal.io.mapped_csv import read_attitude, read_mapped_csv
    from pitotcal.io.radiosonde import read_sounding

    sonde = read_sounding(sounding_path) if sounding_path.exists() else None
    out = {}
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mapping = Path(tmp) / "jmoss.toml"
        mapping.write_text(MAPPING)
        for path in files:
            survey = self_survey(read_mapped_csv(path, mapping))
            vector = self_survey(read_mapped_csv(path, mapping),
                                 attitude=read_attitude(path, mapping))
            flight = read_flight(path, columns=mapping)
            oe = identify(flight, model="inverse")
            mach = identify_mach(flight)
            wn, we = _wind_ne(oe)
            entry = {"self_survey": {**survey.to_dict(),
                                     "wind_ne_kt": [float(mps_to_kt(survey.wind_n_mps)),
                                                    float(mps_to_kt(survey.wind_e_mps))]},
                     "self_survey_vector": {**vector.to_dict(), "wind_ne_kt": [
                         float(mps_to_kt(vector.wind_n_mps)), float(mps_to_kt(vector.wind_e_mps))]},
                     "output_error": {"k1": oe.value("k1"), "k2": oe.value("k2"),
                                      "wind_ne_kt": [float(mps_to_kt(wn)), float(mps_to_kt(we))],
                                      "wind_speed_2sigma_kt": float(mps_to_kt(
                                          2 * oe.stddev("wind_speed_mps"))),
                                      "oat_k_assumed_r1": float(np.mean(flight.oat_k))},
                     "output_error_mach": {**mach.to_dict(), "wind_ne_kt": [
                         float(mps_to_kt(mach.wind_n_mps)), float(mps_to_kt(mach.wind_e_mps))]},
                     "h_ref_m": survey.h_ref_m}
            if sonde is not None:
                at = sonde.at(survey.h_ref_m)
                entry["radiosonde"] = {"wind_ne_kt": [float(mps_to_kt(at["wind_n_mps"])),
                                                      float(mps_to_kt(at["wind_e_mps"]))],
                                       "temp_k": at["temp_k"], "ps_pa": at["ps_pa"]}
            out[Path(path).stem] = entry
    return out


def _wind_ne(result):
    from pitotcal.core.units import wind_vector_mps
    return wind_vector_mps(result.value("wind_speed_mps"), result.value("wind_from_deg"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    shared = os.environ.get("PITOTCAL_SHARED_DATA")
    ap.add_argument("--data", type=Path, required=shared is None,
                    default=Path(shared) / "jmoss" if shared else None,
                    help="folder of the CLASS*.csv test points and WB.txt "
                         "(default: jmoss/ in $PITOTCAL_SHARED_DATA)")
    ap.add_argument("--points", nargs="+", default=["CLASS55", "CLASS65"])
    ap.add_argument("--cache", type=Path, default=Path.home() / ".cache" / "pitotcal")
    ap.add_argument("--source", default=SOURCE, help="JMOSS git URL (or a local clone)")
    ap.add_argument("--python", default=sys.executable,
                    help="interpreter with numpy, scipy, pandas, matplotlib for JMOSS")
    ap.add_argument("--out", type=Path, default=None, help="write all numbers as JSON")
    args = ap.parse_args(argv)
    files = [args.data / f"{p}.csv" for p in args.points]
    missing = [str(f) for f in files if not f.exists()]
    if missing:
        print(f"skipped: {', '.join(missing)} not found")
        return 0
    args.cache.mkdir(parents=True, exist_ok=True)
    repo, why = fetch_jmoss(args.cache, args.source)
    if repo is None:
        print(f"skipped: {why}")
        return 0
    ours = run_pitotcal(files, args.data / "WB.txt")
    peer = run_jmoss(args.python, repo, files)
    result = {name: {**ours[name], "jmoss": peer[name]} for name in ours}
    print(json.dumps(_summary(result), indent=1))
    if args.out:
        args.out.write_text(json.dumps(result, indent=1))
    return 0


def _summary(result):
    """Wind difference to the radiosonde (kt), OAT difference (K), and the SPE curves."""
    out = {}
    for name, r in result.items():
        sonde = r.get("radiosonde")
        row = {}
        for method, wind, oat in (("jmoss", r["jmoss"]["wind_ned_kt"][:2], r["jmoss"]["oat_k"]),
                                  ("self_survey", r["self_survey"]["wind_ne_kt"],
                                   r["self_survey"]["oat_k"]),
                                  ("self_survey_vector", r["self_survey_vector"]["wind_ne_kt"],
                                   r["self_survey_vector"]["oat_k"]),
                                  ("output_error", r["output_error"]["wind_ne_kt"],
                                   r["output_error"]["oat_k_assumed_r1"]),
                                  ("output_error_mach", r["output_error_mach"]["wind_ne_kt"],
                                   r["output_error_mach"]["oat_k"])):
            row[method] = {"wind_ne_kt": [round(w, 2) for w in wind], "oat_k": round(oat, 2)}
            if sonde:
                row[method]["wind_diff_kt"] = round(float(np.hypot(
                    wind[0] - sonde["wind_ne_kt"][0], wind[1] - sonde["wind_ne_kt"][1])), 2)
                row[method]["oat_minus_sonde_k"] = round(oat - sonde["temp_k"], 2)
        row["jmoss_spe"] = [(s["mach_ic"], round(s["dpp_ps"], 4), round(s["dpp_ps_2sigma"], 4))
                            for s in r["jmoss"]["spe_model"]]
        row["survey_spe"] = [(round(s["mach_ic"], 3), round(s["dpp_ps"], 4),
                              round(s["dpp_ps_2sigma"], 4)) for s in r["self_survey"]["spe"]]
        out[name] = row
    return out


if __name__ == "__main__":
    sys.exit(main())
