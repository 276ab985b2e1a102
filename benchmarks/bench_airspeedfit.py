"""Accuracy, honesty of the stated bounds and speed against ArduPilot's AirspeedFit, on the same
simulated flights and the same arrays.

Run: ``python benchmarks/bench_airspeedfit.py [--flights 100] [--constant-flights 20] [--quick]
[--no-fetch] [--no-sitl] [--identify-args "..."] [--out DIR]``.

Flights (seeded, `pitotcal.maneuvers.fly.everyday`): the default calibration plan flown in its
constant 5 m/s wind (`default_plan_flight`, 240 s at 50 Hz), and the 15-minute everyday
survey/loiter flight with speed changes in a wind drifting from 9 m/s from 270° to 12 m/s from
310° (`everyday_flight`, 10 Hz), and the same in a constant 9 m/s from 270°; all in 0.5 m/s
Dryden turbulence, 5 Hz GPS with 0.05 m/s noise, compressible air data with the true static
pressure and OAT in the CSV. Each is written as a
pitotcal CSV and given, whole, to four commands, each a fresh process timed from start to end:

- ``python -m pitotcal identify FLIGHT.csv --json OUT --model inverse`` and ``--model constant``
  (default options otherwise: noise model, robustness, budget);
- ``node peer_airspeedfit.js CORE FLIGHT.csv constant`` and ``... drifting``: AirspeedFit's core
  (ArduPilot/WebTools ``AirspeedFit/airspeedfit_core.js``) as its page runs it on the CSV's
  arrays (u = sqrt(dp) EAS2TAS with EAS2TAS from the CSV's density, the page's automatic
  window): its constant-wind fit ``calibrate`` and its time-varying-wind fit
  ``calibrate_combined`` at the page's default wind process noise (q = 10^-1.5).

Scores against the simulator's truth, on 7 indicated airspeeds spanning the 2-98 % range of
those flown: max |ΔV error| (kt), whether the stated 2σ covers the truth at every one of them
(pitotcal: the statistical 2σ of its ΔV table; AirspeedFit: twice its ratio's standard error
through ΔV = sqrt(r q_ci) − V_i), the wind (the rms over the flight of the vector error against
the true process wind, mean + drift, and the error of the mean wind against the mean flown
through) and the wall time. Then the ArduPlane SITL log (``$PITOTCAL_SHARED_DATA``
/ardupilot/arduplane_sitl.log; skipped when absent): ``identify LOG --oat-c 15 --params`` and
AirspeedFit on ``pitotcal convert LOG --oat-c 15``'s CSV, each ratio against the simulator's
ARSPD_RATIO 1.9936. The AirspeedFit core is found as in bench_peers_speed.py (never vendored);
without node or the core its rows are skipped, saying why.
"""

import argparse
import json
import math
import os
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from bench_peers_speed import find_airspeedfit, machine, run_child, sitl_log  # noqa: E402

SITL_RATIO = 1.9936           # ARSPD_RATIO of the ArduPlane SITL run that made the log
TOOLS = ("pitotcal inverse", "pitotcal constant", "AirspeedFit constant",
         "AirspeedFit drifting")
SCENARIOS = {"constant": "default plan, constant wind (240 s)",
             "everyday-constant": "15-min everyday flight, constant wind",
             "drifting": "15-min everyday flight, wind drifting 3 m/s and 40°"}


def truth_of(flight, truth):
    """What the scoring needs of a simulated flight: the true ΔV law and the process wind."""
    process = truth.wind_mean_process
    wn0, we0 = _vector(process["speed_mps"], process["from_deg"])
    dn, de = process["drift_mps2"]
    t = np.asarray(flight.time_s, dtype=float)
    t_mid = 0.5 * (t[0] + t[-1])
    return {"truth": truth, "t_mid": t_mid, "mean": (wn0, we0), "drift": (dn, de),
            "flown_mean": (float(truth.wind_n_mps), float(truth.wind_e_mps)),
            "time_s": t, "qci_pa": np.asarray(flight.qci_pa, dtype=float)}


def _vector(speed_mps, from_deg):
    from pitotcal.core.units import wind_vector_mps
    return tuple(float(w) for w in wind_vector_mps(speed_mps, from_deg))


def process_wind(case, time_s):
    t = np.asarray(time_s, dtype=float) - case["t_mid"]
    return (case["mean"][0] + case["drift"][0] * t, case["mean"][1] + case["drift"][1] * t)


def make_flights(kind, seeds, tmp):
    """[(csv path, scoring case)] of seeded simulated flights of one scenario."""
    from pitotcal.io import write_flight_csv
    from pitotcal.maneuvers.fly.everyday import default_plan_flight, everyday_flight

    out = []
    for seed in seeds:
        flight, truth = (default_plan_flight(seed) if kind == "constant"
                         else everyday_flight(seed, drifting=kind == "drifting"))
        path = Path(tmp) / f"{kind}_{seed}.csv"
        write_flight_csv(flight, path)
        case = truth_of(flight, truth)
        if kind == "drifting":          # the oracle's flight: the true drift taken out
            case["oracle_csv"] = Path(tmp) / f"{kind}_{seed}_oracle.csv"
            write_flight_csv(without_true_drift(flight, case), case["oracle_csv"])
        out.append((path, case))
    return out


def without_true_drift(flight, case):
    """`flight` with the true process wind's drift (about its mean) taken out of the GPS
    velocity: a constant wind is then exact, so a constant-wind fit of it is what the best
    wind model could give (the oracle row)."""
    import dataclasses

    pn, pe = process_wind(case, flight.time_s)
    return dataclasses.replace(flight, gps_vn_mps=flight.gps_vn_mps - (pn - pn.mean()),
                               gps_ve_mps=flight.gps_ve_mps - (pe - pe.mean()))


# The drifting flights' oracle: `pitotcal identify --model inverse` told the true wind track
ORACLE = "oracle: inverse, true wind track"


def commands(csv, out_json, core, identify_args=()):
    py = [sys.executable, "-m", "pitotcal", "identify", str(csv), "--json", str(out_json),
          *identify_args]
    cmds = {"pitotcal inverse": [*py, "--model", "inverse"],
            "pitotcal constant": [*py, "--model", "constant"]}
    if core is not None:
        node = ["node", str(HERE / "peer_airspeedfit.js"), str(core), str(csv)]
        cmds["AirspeedFit constant"] = [*node, "constant"]
        cmds["AirspeedFit drifting"] = [*node, "drifting"]
    return cmds


def dv_pitotcal(d, grid_kt):
    """(ΔV, its 2σ) in kt at `grid_kt` from identify's JSON ΔV table."""
    table = d["airspeed_correction"]
    vi = np.array([a["vi_kt"] for a in table])
    return (np.interp(grid_kt, vi, [a["dv_kt"] for a in table]),
            np.interp(grid_kt, vi, [a["dv_2sigma_kt"] for a in table]))


def dv_ratio(ratio, ratio_stderr, grid_kt):
    """(ΔV, 2σ) in kt of an ArduPilot ratio: the corrected airspeed sqrt(r q_ci) (EAS, which
    is CAS to ~0.01 kt near sea level) at the q_ci whose standard CAS is V_i."""
    from pitotcal.core.airdata import qc_from_cas_pa
    from pitotcal.core.units import kt_to_mps, mps_to_kt

    vi = kt_to_mps(np.asarray(grid_kt, dtype=float))
    root_q = np.sqrt(qc_from_cas_pa(vi))
    dv = mps_to_kt(math.sqrt(ratio) * root_q - vi)
    return dv, mps_to_kt(root_q / (2 * math.sqrt(ratio)) * 2 * ratio_stderr)


def wind_pitotcal(d):
    """(time_s or None, wind_n, wind_e) of identify's JSON: its wind track when it writes one
    (``wind_track`` with time_s and wind_n_mps/wind_e_mps or speed_mps/from_deg), else its
    one wind."""
    track = d.get("wind_track")
    if isinstance(track, dict) and "time_s" in track:
        if "wind_n_mps" in track:
            return (np.asarray(track["time_s"]), np.asarray(track["wind_n_mps"]),
                    np.asarray(track["wind_e_mps"]))
        wn, we = _vectors(track["speed_mps"], track["from_deg"])
        return np.asarray(track["time_s"]), wn, we
    p = d["parameters"]
    wn, we = _vector(p["wind_speed_mps"]["value"], p["wind_from_deg"]["value"])
    return None, np.array([wn]), np.array([we])


def _vectors(speed, from_deg):
    from pitotcal.core.units import wind_vector_mps
    wn, we = wind_vector_mps(np.asarray(speed, dtype=float), np.asarray(from_deg, dtype=float))
    return np.asarray(wn), np.asarray(we)


def answer(name, stdout, out_json):
    """{ratio?, dv(grid) function, wind track} of one tool's output."""
    if name.startswith("pitotcal") or name == ORACLE:
        d = json.loads(Path(out_json).read_text())
        t, wn, we = wind_pitotcal(d)
        return {"dv": lambda g, d=d: dv_pitotcal(d, g), "wind": (t, wn, we),
                "warnings": len(d.get("warnings", []))}
    d = json.loads(stdout.strip().splitlines()[-1])
    track = d.get("wind_track")
    wind = ((np.asarray(track["time_s"]), np.asarray(track["wind_n_mps"]),
             np.asarray(track["wind_e_mps"])) if track else
            (None, np.array([d["wind_ne_mean"][0]]), np.array([d["wind_ne_mean"][1]])))
    return {"dv": lambda g, d=d: dv_ratio(d["ratio"], d["ratio_stderr"], g), "wind": wind,
            "ratio": d["ratio"], "ratio_stderr": d["ratio_stderr"],
            "warnings": len(d.get("warnings", []))}


def score(ans, case):
    """max |ΔV error| (kt), the signed error at the middle speed, covered (truth inside the
    stated 2σ at every grid speed), wind track rms error and mean-wind error (m/s)."""
    from pitotcal.studies.engine.common import truth_delta_v_kt, vi_grid_kt

    grid = vi_grid_kt(case["qci_pa"])
    dv, dv2 = ans["dv"](grid)
    signed = dv - np.asarray(truth_delta_v_kt(case["truth"], grid), dtype=float)
    err = np.abs(signed)
    t, wn, we = ans["wind"]
    if t is None:                       # one wind for the whole flight
        t, wn, we = case["time_s"], np.full(case["time_s"].size, wn[0]), \
            np.full(case["time_s"].size, we[0])
    pn, pe = process_wind(case, t)
    fn, fe = case["flown_mean"]
    return {"dv_err_max_kt": float(err.max()), "covered": bool(np.all(err <= dv2)),
            "dv_err_mid_kt": float(signed[grid.size // 2]),
            "dv_2sigma_max_kt": float(np.max(dv2)),
            "wind_track_rms_mps": float(np.sqrt(np.mean((wn - pn) ** 2 + (we - pe) ** 2))),
            "wind_mean_err_mps": float(math.hypot(np.mean(wn) - fn, np.mean(we) - fe)),
            "warnings": ans["warnings"]}


def bench_flights(flights, core, tmp, identify_args=()):
    """{tool: [row per flight]}: each command run once per flight, timed, scored."""
    rows = {}
    for csv, case in flights:
        out_json = Path(tmp) / f"{csv.stem}.json"
        cmds = commands(csv, out_json, core, identify_args)
        if "oracle_csv" in case:
            cmds[ORACLE] = [sys.executable, "-m", "pitotcal", "identify", str(case["oracle_csv"]),
                            "--json", str(out_json), "--model", "inverse", "--wind", "constant"]
        for name, cmd in cmds.items():
            try:
                wall, rss, stdout = run_child(cmd)
                ans = answer(name, stdout, out_json)
                if name == ORACLE:          # its wind: the fitted mean plus the true drift
                    pn, pe = process_wind(case, case["time_s"])
                    ans["wind"] = (case["time_s"], ans["wind"][1][0] + pn - pn.mean(),
                                   ans["wind"][2][0] + pe - pe.mean())
                row = {**score(ans, case), "wall_s": wall, "peak_mb": rss}
            except (RuntimeError, ValueError, KeyError) as exc:
                row = {"error": str(exc)[-300:]}
            rows.setdefault(name, []).append({"flight": csv.stem, **row})
    return rows


_COLUMNS = ("dv_err_max_kt", "dv_err_mid_kt", "dv_2sigma_max_kt", "wind_track_rms_mps",
            "wind_mean_err_mps", "wall_s")


def summarize(rows):
    """Per tool, over the flights that ran: medians (the 90th percentile of max |ΔV error|),
    the mean signed error at the middle speed with its standard error, counts."""
    out = {}
    for name, runs in rows.items():
        ok = [r for r in runs if "error" not in r]
        out[name] = {"n": len(runs), "n_ok": len(ok)}
        if not ok:
            continue
        col = {k: np.array([r[k] for r in ok], dtype=float) for k in _COLUMNS}
        mid = col["dv_err_mid_kt"]
        out[name].update({
            "dv_err_max_kt_median": float(np.median(col["dv_err_max_kt"])),
            "dv_err_max_kt_p90": float(np.percentile(col["dv_err_max_kt"], 90)),
            "dv_err_mid_kt_mean": float(mid.mean()),
            "dv_err_mid_kt_se": float(mid.std(ddof=1) / math.sqrt(mid.size)) if mid.size > 1
            else float("nan"),
            "covered": sum(r["covered"] for r in ok),
            "with_warnings": sum(r["warnings"] > 0 for r in ok),
            **{f"{k}_median": float(np.median(col[k])) for k in _COLUMNS
               if k not in ("dv_err_max_kt", "dv_err_mid_kt")}})
    return out


def bench_sitl(core, tmp):
    """The SITL log: identify (inverse, constant) on the log, AirspeedFit on its CSV."""
    log = sitl_log()
    if log is None:
        return None
    csv = Path(tmp) / "sitl.csv"
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "pitotcal", "convert", str(log), "-o", str(csv),
                    "--oat-c", "15"], check=True, capture_output=True)
    out = {"convert_s": time.perf_counter() - start, "tools": {}}
    for model in ("inverse", "constant"):
        parm = Path(tmp) / f"sitl_{model}.parm"
        wall, _, _ = run_child([sys.executable, "-m", "pitotcal", "identify", str(log),
                                "--oat-c", "15", "--model", model, "--params", str(parm)])
        ratio, two_sigma = _params_ratio(parm.read_text())
        out["tools"][f"pitotcal {model}"] = {"ratio": ratio, "ratio_2sigma": two_sigma,
                                             "wall_s": wall}
    if core is not None:
        for mode in ("constant", "drifting"):
            wall, _, stdout = run_child(["node", str(HERE / "peer_airspeedfit.js"), str(core),
                                         str(csv), mode])
            d = json.loads(stdout.strip().splitlines()[-1])
            out["tools"][f"AirspeedFit {mode}"] = {"ratio": d["ratio"],
                                                   "ratio_2sigma": 2 * d["ratio_stderr"],
                                                   "wall_s": wall}
    for r in out["tools"].values():
        r["error_percent"] = 100.0 * (r["ratio"] / SITL_RATIO - 1.0)
        r["covered"] = abs(r["ratio"] - SITL_RATIO) <= r["ratio_2sigma"]
    return out


def _params_ratio(text):
    """(ratio, 2σ) from the comment line `# pitotcal: ARSPD_RATIO = R +/- U (2 sigma)`."""
    for line in text.splitlines():
        if line.startswith("# pitotcal:") and "+/-" in line:
            value, rest = line.split("=", 1)[1].split("+/-")
            return float(value), float(rest.split()[0])
    raise ValueError("no ARSPD_RATIO line in the parameter file")


def table(summary, sitl, skipped, where, sitl_why="absent (set PITOTCAL_SHARED_DATA)"):
    """The markdown report: one row per scenario and tool, then the SITL log."""
    lines = [f"Machine: {where}", "",
             "| flights | tool / mode | max \\|ΔV error\\| kt, median (90th pct) | mean ΔV "
             "error at mid speed kt (± 2 se) | stated 2σ kt, median | 2σ covers truth | "
             "wind track rms m/s | mean-wind error m/s | flights warned | wall s (× pitotcal "
             "inverse) |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for kind, per_tool in summary.items():
        base = per_tool.get("pitotcal inverse", {}).get("wall_s_median")
        for name, s in per_tool.items():
            label = f"{SCENARIOS[kind]}, {s['n']}"
            if not s["n_ok"]:
                lines.append(f"| {label} | {name} | failed | | | | | | | |")
                continue
            ratio = f" ({s['wall_s_median'] / base:.2f}×)" if base else ""
            lines.append(
                f"| {label} | {name} | {s['dv_err_max_kt_median']:.3f} "
                f"({s['dv_err_max_kt_p90']:.3f}) | {s['dv_err_mid_kt_mean']:+.3f} "
                f"(± {2 * s['dv_err_mid_kt_se']:.3f}) | {s['dv_2sigma_max_kt_median']:.3f} | "
                f"{s['covered']}/{s['n_ok']} | {s['wind_track_rms_mps_median']:.2f} | "
                f"{s['wind_mean_err_mps_median']:.2f} | {s['with_warnings']}/{s['n_ok']} | "
                f"{s['wall_s_median']:.2f}{ratio} |")
    if skipped:
        lines += ["", f"AirspeedFit skipped: {skipped}"]
    if sitl is None:
        lines += ["", f"ArduPlane SITL log: {sitl_why}"]
        return "\n".join(lines)
    lines += ["", f"ArduPlane SITL log, `--oat-c 15`, true ARSPD_RATIO {SITL_RATIO} "
              f"(AirspeedFit on `pitotcal convert`'s CSV, {sitl['convert_s']:.2f} s to convert):",
              "", "| tool / mode | ARSPD_RATIO ± 2σ | error | 2σ covers truth | wall s |",
              "|---|---:|---:|---:|---:|"]
    for name, r in sitl["tools"].items():
        lines.append(f"| {name} | {r['ratio']:.4f} ± {r['ratio_2sigma']:.4f} | "
                     f"{r['error_percent']:+.2f} % | {'yes' if r['covered'] else 'no'} | "
                     f"{r['wall_s']:.2f} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flights", type=int, default=100,
                        help="drifting-wind 15-min flights (default 100)")
    parser.add_argument("--constant-flights", type=int, default=20,
                        help="constant-wind flights of each kind, the default plan and the "
                             "everyday flight (default 20)")
    parser.add_argument("--quick", action="store_true", help="3 flights of each kind")
    parser.add_argument("--no-fetch", action="store_true",
                        help="use AirspeedFit only if cached or mirrored: never clone it")
    parser.add_argument("--no-sitl", action="store_true", help="leave out the SITL log")
    parser.add_argument("--identify-args", default="",
                        help="more options for both `pitotcal identify` runs, one string "
                             "(e.g. a wind model's option)")
    parser.add_argument("--out", default="airspeedfit-bench",
                        help="folder for airspeedfit.md and airspeedfit.json")
    args = parser.parse_args(argv)
    n_drift, n_const = ((min(args.flights, 3), min(args.constant_flights, 3)) if args.quick
                        else (args.flights, args.constant_flights))
    core, skipped = find_airspeedfit(fetch=not args.no_fetch)
    before = machine()
    start = time.perf_counter()
    rows, summary = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        for kind, n in (("constant", n_const), ("everyday-constant", n_const),
                        ("drifting", n_drift)):
            if n > 0:
                rows[kind] = bench_flights(make_flights(kind, range(n), tmp), core, tmp,
                                           shlex.split(args.identify_args))
                summary[kind] = summarize(rows[kind])
        sitl = None if args.no_sitl else bench_sitl(core, tmp)
    where = (f"{before}; after: load {os.getloadavg()[0]:.1f}; "
             f"{time.perf_counter() - start:.0f} s in all")
    text = table(summary, sitl, skipped, where,
                 *(["left out (--no-sitl)"] if args.no_sitl else []))
    print(text)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "airspeedfit.md").write_text(text + "\n", encoding="utf-8")
    (out / "airspeedfit.json").write_text(json.dumps(
        {"machine": where, "skipped": skipped, "summary": summary, "sitl": sitl,
         "rows": rows, "table": text, "command": " ".join(["python",
                                                            "benchmarks/bench_airspeedfit.py",
                                                            *(argv or sys.argv[1:])])},
        indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
