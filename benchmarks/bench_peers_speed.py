"""Speed against the peers: the whole `pitotcal identify` process (default options, budget on)
against a plain scipy script doing the same fit (`peer_scipy_fit.py`) and against ArduPilot's
AirspeedFit under node (`peer_airspeedfit.js`), on the same flights, with their answers.

Run: ``python benchmarks/bench_peers_speed.py [--sizes 16000 100000 1000000] [--repeats 5]
[--repeats-large 3] [--no-profile] [--json OUT.json]``.
Each size is a seeded synthetic flight (tests/synthetic.py: 50 Hz, 5 Hz held GPS with 0.05 m/s
noise, 0.5 Pa pressure noise, k = (0.02, -15 Pa), 5 m/s wind from 270 deg, 70-100 kt) written
as a pitotcal CSV; the ArduPlane SITL log is added when the shared data holds it
(the folder PITOTCAL_SHARED_DATA names). The three commands alternate in fresh processes
(interleaved, so load changes hit all three alike); each child's wall time is timed here and its peak RSS
comes from /usr/bin/time. Medians of `--repeats` runs (`--repeats-large` above 200,000 samples). The
AirspeedFit core comes from $PITOTCAL_WEBTOOLS (a WebTools checkout), else the cache
~/.cache/pitotcal/webtools, filled from a local git mirror of ArduPilot/WebTools
(/work/.mirror) or a shallow clone; without node or the core that column is skipped, saying why.
Then one cProfile run of identify per size: its top 10 functions by cumulative time.
"""

import argparse
import json
import math
import os
import pstats
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HERE = Path(__file__).resolve().parent
RHO0_KGM3 = 1.225
CORE = "AirspeedFit/airspeedfit_core.js"
MATRIX = "modules/build/matrix/matrix.umd.js"
WEBTOOLS_URL = "https://github.com/ArduPilot/WebTools"
LARGE_N = 200_000


def _cache():
    return Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "pitotcal" / "webtools"


def find_airspeedfit(fetch=True):
    """(path of airspeedfit_core.js, None) or (None, why it is unavailable); without `fetch`
    only a given, cached or mirrored copy is used, never a clone."""
    if shutil.which("node") is None:
        return None, "node is not installed"
    given = os.environ.get("PITOTCAL_WEBTOOLS")
    if given:
        core = Path(given) / CORE
        return (core, None) if core.is_file() else (None, f"PITOTCAL_WEBTOOLS={given} has no {CORE}")
    cache = _cache()
    if (cache / CORE).is_file() and (cache / MATRIX).is_file():
        return cache / CORE, None
    cache.mkdir(parents=True, exist_ok=True)
    mirrors = sorted(Path("/work/.mirror").glob("ArduPilot+WebTools/repo"))
    for mirror in mirrors:
        archive = subprocess.run(["git", "-C", str(mirror), "archive", "HEAD", CORE, MATRIX],
                                 capture_output=True)
        if archive.returncode == 0:
            subprocess.run(["tar", "-x", "-C", str(cache)], input=archive.stdout, check=True)
            return cache / CORE, None
    if not fetch:
        return None, "not cached and --no-fetch given"
    try:
        clone = subprocess.run(["git", "clone", "-q", "--depth", "1", WEBTOOLS_URL,
                                str(cache / "clone")], capture_output=True, timeout=120)
    except subprocess.TimeoutExpired:
        return None, f"cloning {WEBTOOLS_URL} timed out and no local mirror"
    if clone.returncode == 0 and (cache / "clone" / CORE).is_file():
        return cache / "clone" / CORE, None
    return None, f"{WEBTOOLS_URL} unreachable and no local mirror: {clone.stderr.decode()[-200:]}"


def sitl_log():
    base = os.environ.get("PITOTCAL_SHARED_DATA")
    log = Path(base) / "ardupilot" / "arduplane_sitl.log" if base else None
    return log if log is not None and log.is_file() else None


def write_flights(sizes, tmp):
    """{label: (csv path, truth dict or None)}."""
    sys.path.insert(0, str(ROOT / "tests"))
    from synthetic import synthetic_flight

    from pitotcal.io import write_flight_csv
    flights = {}
    for n in sizes:
        flight, truth = synthetic_flight(seed=0, n=n, gps_rate_hz=5.0, gps_noise_mps=0.05,
                                         qc_noise_pa=0.5)
        path = Path(tmp) / f"flight_{n}.csv"
        write_flight_csv(flight, path)
        flights[f"{n:,}"] = (path, truth)
    log = sitl_log()
    if log is not None:
        path = Path(tmp) / "sitl.csv"
        subprocess.run([sys.executable, "-m", "pitotcal", "convert", str(log), "-o", str(path),
                        "--oat-c", "15"], check=True, capture_output=True)
        flights["SITL log"] = (path, None)
    return flights


def run_child(cmd):
    """(wall s, peak RSS MB, stdout) of one child process.

    The peak comes from /usr/bin/time (GNU time's %M): the child is forked from that small
    process, because a child forked from this one would report this process's RSS at the fork
    as its own high-water mark. Without /usr/bin/time: RUSAGE_CHILDREN's, an upper bound."""
    timer = shutil.which("time", path="/usr/bin:/bin")
    with tempfile.NamedTemporaryFile("r", suffix=".rss") as rss:
        full = [timer, "-q", "-f", "%M", "-o", rss.name, *cmd] if timer else cmd
        start = time.perf_counter()
        proc = subprocess.Popen(full, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        out, err = proc.communicate()
        wall = time.perf_counter() - start
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(map(str, cmd))} failed: {err.decode()[-500:]}")
        kb = float(rss.read().split()[-1]) if timer else resource.getrusage(
            resource.RUSAGE_CHILDREN).ru_maxrss
    return wall, kb / 1024.0, out.decode()


def speeds_kt(out_json):
    """Three speeds of identify's ΔV table (first, middle, last): where all tools are compared."""
    grid = [a["vi_kt"] for a in json.loads(Path(out_json).read_text())["airspeed_correction"]]
    return [grid[0], grid[len(grid) // 2], grid[-1]]


def commands(csv, out_json, core, speeds):
    cmds = {"identify": [sys.executable, "-m", "pitotcal", "identify", str(csv), "--json",
                         str(out_json)],
            "scipy": [sys.executable, str(HERE / "peer_scipy_fit.py"), str(csv),
                      *map(str, speeds)]}
    if core is not None:
        cmds["AirspeedFit"] = ["node", str(HERE / "peer_airspeedfit.js"), str(core), str(csv)]
    return cmds


def answers(name, stdout, out_json, speeds):
    """{dv_kt: [...], wind_mps, wind_from_deg} of one tool at `speeds` (kt)."""
    if name == "identify":
        d = json.loads(Path(out_json).read_text())
        table = {round(a["vi_kt"], 1): a["dv_kt"] for a in d["airspeed_correction"]}
        p = d["parameters"]
        return {"dv_kt": [table.get(round(v, 1), float("nan")) for v in speeds],
                "wind_mps": p["wind_speed_mps"]["value"],
                "wind_from_deg": p["wind_from_deg"]["value"]}
    d = json.loads(stdout.strip().splitlines()[-1])
    if name == "scipy":
        return {"dv_kt": d["dv_kt"], "wind_mps": d["wind_speed_mps"],
                "wind_from_deg": d["wind_from_deg"]}
    wn, we = d["wind_ne_mean"]                     # ratio only: V_c = V_i sqrt(ratio rho0 / 2)
    scale = (d["ratio"] * RHO0_KGM3 / 2) ** 0.5 - 1
    return {"dv_kt": [v * scale for v in speeds], "wind_mps": float((wn * wn + we * we) ** 0.5),
            "wind_from_deg": float(_from_deg(wn, we)), "ratio": d["ratio"]}


def _from_deg(wn, we):
    return math.degrees(math.atan2(-we, -wn)) % 360


def truth_answers(truth, speeds):
    if truth is None:
        return None
    k1, k2 = truth["k"]
    dv = []
    for v in speeds:
        qi = 0.5 * RHO0_KGM3 * (v * 1852 / 3600) ** 2
        dv.append(v * ((1 - k1 - k2 / qi) ** -0.5 - 1))
    p = truth["parameters"]
    return {"dv_kt": dv, "wind_mps": p["wind_speed_mps"], "wind_from_deg": p["wind_from_deg"]}


def profile(csv, tmp, top=10):
    """The top functions of one identify run by cumulative time: [(seconds, name)]."""
    prof = Path(tmp) / "identify.prof"
    subprocess.run([sys.executable, "-m", "cProfile", "-o", str(prof), "-m", "pitotcal",
                    "identify", str(csv), "--json", str(Path(tmp) / "prof.json")],
                   check=True, capture_output=True)
    stats = pstats.Stats(str(prof)).stats
    rows, imports = [], 0.0
    for (file, line, func), (_, _, _, cum, _) in stats.items():
        if func == "_find_and_load":                 # recursive: cumtime counts the outermost
            imports = max(imports, cum)
        if file.startswith(str(ROOT)) and "/cli/" not in file and func != "<module>":
            rows.append((cum, f"{Path(file).relative_to(ROOT)}:{line} {func}"))
    total = max(cum for (_, _, _, cum, _) in stats.values())
    own = sorted(((tt, f"{Path(file).name}:{line} {func}")
                  for (file, line, func), (_, _, tt, _, _) in stats.items()), reverse=True)
    return total, imports, sorted(rows, reverse=True)[:top], own[:top]


def bench(flights, repeats, repeats_large, core, tmp):
    results = {}
    for label, (csv, truth) in flights.items():
        n_runs = repeats_large if csv.stat().st_size > LARGE_N * 50 else repeats
        out_json = Path(tmp) / f"{csv.stem}.json"
        run_child(commands(csv, out_json, None, ())["identify"])      # its ΔV grid, and a warm-up
        speeds = speeds_kt(out_json)
        cmds = commands(csv, out_json, core, speeds)
        times = {k: [] for k in cmds}
        peak = {k: 0.0 for k in cmds}
        found = {}
        for _ in range(n_runs):
            for name, cmd in cmds.items():
                wall, rss, stdout = run_child(cmd)
                times[name].append(wall)
                peak[name] = max(peak[name], rss)
                found[name] = answers(name, stdout, out_json, speeds)
        results[label] = {"runs": n_runs, "wall_s": {k: statistics.median(v) for k, v in times.items()},
                          "all_wall_s": times, "peak_mb": peak, "answers": found,
                          "truth": truth_answers(truth, speeds), "speeds_kt": speeds}
    return results


def _ratio(r, peer):
    """The ratio of the medians, and the range of the runs' own ratios (each run's identify
    and peer ran back to back)."""
    pairs = [a / b for a, b in zip(r["all_wall_s"]["identify"], r["all_wall_s"][peer])]
    return (f"{r['wall_s']['identify'] / r['wall_s'][peer]:.2f} "
            f"({min(pairs):.2f}–{max(pairs):.2f})")


def report(results, skipped, profiles, machine):
    lines = [f"Machine: {machine}", ""]
    names = ["identify", "scipy", "AirspeedFit"]
    lines.append("| flight | runs | identify s, MB | scipy script s, MB | AirspeedFit s, MB | "
                 "identify / scipy (runs' range) | identify / AirspeedFit (runs' range) |")
    lines.append("|---|---:|---:|---:|---:|---:|---:|")
    for label, r in results.items():
        cells = [f"{r['wall_s'][k]:.2f}, {r['peak_mb'][k]:.0f}" if k in r["wall_s"] else "—"
                 for k in names]
        ratio = [_ratio(r, k) if k in r["wall_s"] else "—" for k in names[1:]]
        lines.append(f"| {label} | {r['runs']} | " + " | ".join(cells + ratio) + " |")
    if skipped:
        lines += ["", f"AirspeedFit skipped: {skipped}"]
    lines += ["", "Answers: ΔV (kt) at three speeds of identify's table; wind m/s from deg", "",
              "| flight | tool | ΔV kt at the speeds | wind |", "|---|---|---|---|"]
    for label, r in results.items():
        rows = dict(r["answers"], **({"truth": r["truth"]} if r["truth"] else {}))
        at = "/".join(f"{v:g}" for v in r["speeds_kt"])
        for name, a in rows.items():
            dv = ", ".join(f"{x:+.3f}" for x in a["dv_kt"]) + f" (at {at} kt)"
            lines.append(f"| {label} | {name} | {dv} | {a['wind_mps']:.2f} from "
                         f"{a['wind_from_deg']:.1f} |")
    for label, (total, imports, rows, own) in profiles.items():
        lines += ["", f"identify profile, {label} (cProfile, {total:.2f} s in all, of which "
                  f"imports {imports:.2f} s, lazy ones inside functions included): the "
                  "package's top 10 by cumulative time, then everything's top 10 by own time", ""]
        lines += [f"    {cum:7.3f} s  {name}" for cum, name in rows] + [""]
        lines += [f"    {tt:7.3f} s  {name}" for tt, name in own]
    return "\n".join(lines)


def machine():
    cpu = next((line.split(":", 1)[1].strip() for line in
                Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("model name")),
               "unknown CPU")
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    return (f"{when}, {len(os.sched_getaffinity(0))} cores (nproc; {cpu}), "
            f"load {os.getloadavg()[0]:.1f}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[16000, 100000, 1000000])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--repeats-large", type=int, default=3)
    parser.add_argument("--no-profile", action="store_true")
    parser.add_argument("--no-sitl", action="store_true", help="leave out the SITL log")
    parser.add_argument("--no-fetch", action="store_true",
                        help="use AirspeedFit only if cached or mirrored: never clone it")
    parser.add_argument("--json", default=None, help="also write the numbers to this file")
    args = parser.parse_args(argv)
    core, skipped = find_airspeedfit(fetch=not args.no_fetch)
    load_before = machine()
    with tempfile.TemporaryDirectory() as tmp:
        flights = write_flights(args.sizes, tmp)
        if args.no_sitl:
            flights.pop("SITL log", None)
        results = bench(flights, args.repeats, args.repeats_large, core, tmp)
        profiles = {} if args.no_profile else {
            label: profile(csv, tmp) for label, (csv, _) in flights.items()}
    where = f"{load_before}; after: load {os.getloadavg()[0]:.1f}"
    if sitl_log() is None:
        where += "; the ArduPlane SITL log is absent (set PITOTCAL_SHARED_DATA)"
    text = report(results, skipped, profiles, where)
    print(text)
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": where, "skipped": skipped,
                                               "results": results, "report": text}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
