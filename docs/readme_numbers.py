"""Regenerate the numbers README.md quotes from fresh runs of its own examples.

Each quoted result sits between ``<!-- readme-numbers:NAME -->`` and
``<!-- /readme-numbers:NAME -->`` (on one line for a value, around a block for a table or an
output excerpt). This script runs the example behind each NAME through the command line, as a
reader would, and writes what it printed between the markers::

    python docs/readme_numbers.py             # rewrite README.md (deterministic examples) and
                                              # copy the figures they make into docs/figures
    python docs/readme_numbers.py --check     # exit 1 naming each block that differs
    python docs/readme_numbers.py --timings   # also the wall-clock numbers (this machine)
    python docs/readme_numbers.py --tests     # also time the lean test suite (~90 s alone)
    python docs/readme_numbers.py --studies   # also the studies' tables (~1 min each)
    python docs/readme_numbers.py --bench     # also the speed race against the peers (~5 min:
                                              # benchmarks/bench_peers_speed.py)
    python docs/readme_numbers.py --bench-from RUN.json   # the same from a saved run's --json
    python docs/readme_numbers.py --afbench   # also accuracy and time against AirspeedFit
                                              # (~15 min: benchmarks/bench_airspeedfit.py)
    python docs/readme_numbers.py --afbench-from DIR      # the same from a saved run's --out
    python docs/readme_numbers.py --only legs-flight,studies-usage

The real-log example reads the ArduPlane SITL log from $PITOTCAL_SHARED_DATA (else the nearest
``shared/data`` above this checkout) and is left as it is, with a line saying so, when the log
is absent. tests/test_readme_numbers.py checks the deterministic blocks.
"""

import argparse
import contextlib
import io
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
_BLOCK = re.compile(r"<!-- readme-numbers:(?P<name>[\w-]+) -->(?P<body>.*?)"
                    r"<!-- /readme-numbers:(?P=name) -->", re.S)


def shared_data():
    """$PITOTCAL_SHARED_DATA, else the nearest shared/data above this checkout (or None)."""
    if "PITOTCAL_SHARED_DATA" in os.environ:
        return Path(os.environ["PITOTCAL_SHARED_DATA"])
    return next((p / "shared" / "data" for p in ROOT.parents if (p / "shared" / "data").is_dir()),
                None)


def _cli(*args):
    """Run `pitotcal ARGS` in this process; its stdout (warnings silenced)."""
    import warnings

    from pitotcal.cli import main

    out = io.StringIO()
    with warnings.catch_warnings(), contextlib.redirect_stdout(out), \
            contextlib.redirect_stderr(io.StringIO()):
        warnings.simplefilter("ignore")
        status = main([str(a) for a in args])
    if status != 0:
        raise RuntimeError(f"pitotcal {' '.join(map(str, args))} exited {status}")
    return out.getvalue()


# ---- deterministic examples -------------------------------------------------------------------

def demo_table(tmp):
    """`pitotcal demo` (seed 0): the calibration table it prints, as it prints it."""
    text = _cli("demo", "--out", tmp / "demo").splitlines()
    head = next(i for i, line in enumerate(text) if line.lstrip().startswith("V_i kt"))
    end = next(i for i in range(head, len(text)) if not text[i].strip())
    return "\n".join(["", "", "```", *text[head:end], "```", "", ""])

def studies_cell(_):
    from pitotcal.studies import STUDY_NAMES

    return ", ".join(f"`{n}`" for n in STUDY_NAMES)


COMPRESSIBLE_PLAN = ("--cas-min-kt", 90, "--cas-max-kt", 150, "--altitude-m", 2438,
                     "--radius-m", 2000, "--duration-s", 300)


def compressible_table(tmp):
    """The worked example of the compressible air data: plan, simulate, identify both ways."""
    import numpy as np

    from pitotcal.core import airdata as ad
    from pitotcal.core import units
    from pitotcal.core.models import delta_v_kt, get_model, qc_from_qci_pa
    from pitotcal.io import read_flight

    _cli("plan", *COMPRESSIBLE_PLAN, "--no-figures", "-o", tmp / "p.csv")
    _cli("simulate", tmp / "p.csv", "-o", tmp / "f.csv", "--seed", 0, "--air-data",
         "compressible")
    _cli("identify", tmp / "f.csv", "--no-budget", "--json", tmp / "r.json")
    _cli("identify", tmp / "f.csv", "--air", "incompressible", "--no-budget", "--json",
         tmp / "ri.json")
    res, inc = (json.loads((tmp / n).read_text()) for n in ("r.json", "ri.json"))
    truth = json.loads((tmp / "f.truth.json").read_text())
    model = get_model(truth["model"])
    k = [truth["parameters"][p] for p in model.params]
    rows = res["airspeed_correction"]
    pick = [rows[0], *(r for r in rows if r["vi_kt"] in (100.0, 130.0)), rows[-1]]
    vi = np.array([r["vi_kt"] for r in pick])
    dv_true = delta_v_kt(model, k, vi, "compressible")
    ps = float(np.median(read_flight(tmp / "f.csv").ps_pa))
    qci = ad.qc_from_cas_pa(units.kt_to_mps(vi))
    dp = qc_from_qci_pa(model, k, qci) - qci
    dh_true = units.m_to_ft(ad.pressure_altitude_m(ps - dp) - ad.pressure_altitude_m(ps))
    inc_rows = inc["airspeed_correction"]
    alt = res["static_source"]["pressure_altitude_ic_ft"]
    out = ["", f"| V_ic kt | M_ic | ΔV_pc kt ± 2σ | true | ΔH_pc ft ± 2σ ({alt:,.0f} ft) | true | "
               "`--air incompressible` ΔV |",
           "|--------:|-----:|--------------:|-----:|-------------------------:|-----:|"
           "--------------------------:|"]
    for r, t, h in zip(pick, dv_true, dh_true):
        # the nearest row of the incompressible table (its V_i is √(2 q_ci / ρ0), its ends
        # fall a little apart)
        i = min(inc_rows, key=lambda x: abs(x["vi_kt"] - r["vi_kt"]))
        other = f"{_sign(i['dv_kt'])} ± {i['dv_2sigma_kt']:.2f}"
        out.append(f"| {r['vi_kt']:5.1f} | {r['mach_i']:.3f} | {_sign(r['dv_kt'])} ± "
                   f"{r['dv_2sigma_kt']:.2f} | {_sign(t)} | {_sign(r['dh_ft'], 1)} ± "
                   f"{r['dh_2sigma_ft']:.1f} | {_sign(h, 1)} | {other} |")
    return "\n".join(out) + "\n\n"


def _sign(x, digits=2):
    """+0.51 / −0.26 (a real minus, as the README's tables)."""
    return f"{x:+.{digits}f}".replace("-", "−")


BUDGET_SIM = ("--seed", 1, "--turbulence-mps", 0, "--air-data", "compressible",
              "--probe-arm-m", -1, "--oat-bias-k", 1)


def budget_example(tmp):
    """The budget's worked example: calm T-2 flight, a wingtip probe and a warm OAT probe."""
    from pitotcal.core.models import delta_v_kt, get_model

    _cli("plan", "--no-figures", "-o", tmp / "plan.csv")
    _cli("simulate", tmp / "plan.csv", "-o", tmp / "ex.csv", *BUDGET_SIM)
    _cli("identify", tmp / "ex.csv", "--probe-arm-m", -1, "--json", tmp / "ex.json",
         "--plot", tmp / "ex.png")
    res = json.loads((tmp / "ex.json").read_text())
    truth = json.loads((tmp / "ex.truth.json").read_text())
    model = get_model(truth["model"])
    k = [truth["parameters"][p] for p in model.params]
    rows = res["airspeed_correction"]
    pick = [rows[0], *(r for r in rows if r["vi_kt"] in (82.0, 94.0)), rows[-1]]
    out = ["", "", "| KIAS | true ΔV | estimated ΔV | error | ±2σ | ±U |",
           "|---:|---:|---:|---:|---:|---:|"]
    ratios = []
    for r in pick:
        true = float(delta_v_kt(model, k, [r["vi_kt"]], "compressible")[0])
        err = r["dv_kt"] - true
        ratios.append(abs(err) / r["dv_2sigma_kt"])
        out.append(f"| {r['vi_kt']:.1f} | {_sign(true)} | {_sign(r['dv_kt'])} | {_sign(err)} | "
                   f"{r['dv_2sigma_kt']:.2f} | {r['dv_U_kt']:.2f} |")
    inside = all(abs(r["dv_kt"] - float(delta_v_kt(model, k, [r["vi_kt"]], "compressible")[0]))
                 <= r["dv_U_kt"] for r in pick)
    out += ["", f"The error is {min(ratios):.0f}–{max(ratios):.0f}× the 2σ band and "
                f"{'inside' if inside else 'NOT inside'} U.\n"]
    return "\n".join(out)


# ---- studies (seeded, deterministic, but a minute or more each: only with --studies) -----------

BUDGET_TERMS = ("statistical", "oat", "humidity", "gps_velocity_bias", "gps_latency",
                "probe_lever_arm", "qc_scale", "qc_offset", "static_pressure")


def budget_study(tmp):
    """`pitotcal study budget --runs 5 --seed 0`: each term beside the statistical part."""
    _cli("study", "budget", "--runs", 5, "--seed", 0, "--workers", 0, "--out", tmp)
    levels = json.loads((tmp / "budget.json").read_text())["by_turbulence_mps"]
    out = ["", "", "| turbulence | 2σ | U (k = 2) | u stat | u OAT | u humidity | u GPS bias | "
                   "u latency | u probe arm | u gain | u offset | u static |",
           "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for level, row in sorted(levels.items(), key=lambda kv: float(kv[0])):
        calm = float(level) == 0
        two = f"{row['two_sigma_kt']:.3f}" if calm else f"{row['two_sigma_kt']:.2f}"
        terms = " | ".join(f"{row['u_dv_kt'][t]:.3f}" for t in BUDGET_TERMS)
        out.append(f"| {float(level):g} m/s | {two} | {row['U_kt']:.2f} | {terms} |")
    calm = levels["0"]
    stat = calm["u_dv_kt"]["statistical"]
    least = min(calm["u_dv_kt"][t] for t in ("oat", "humidity", "probe_lever_arm"))
    out += ["", f"In calm air U is {calm['U_over_2sigma']:.0f}× the statistical 2σ: the OAT, an "
                f"unknown humidity and a 1 m probe arm\nalone are each over {int(least / stat)}× "
                "the statistical σ.", ""]
    return "\n".join(out)


def monitor_example(tmp):
    """The monitor figure's flight: the monitor study's calibration, T-2 flight seed 0 in
    0.5 m/s turbulence with a 4 kt/min icing ramp from 60 s."""
    import warnings

    from pitotcal.estimation.monitor.monitoring import monitor
    from pitotcal.maneuvers import Fault, apply_fault
    from pitotcal.studies.engine.common import get_flight
    from pitotcal.studies.monitor.study import calibration

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        flight, truth = get_flight(None, {"turbulence_mps": 0.5}, 0)
        res = monitor(apply_fault(flight, truth, Fault("icing", 60.0, 4.0, seed=0)),
                      calibration())
        res.plot(tmp / "monitor-example.png")
    first = res.alarms[0]
    return (f"flagged at {first['start_s']:.1f} s by the {first['statistic']} test, classified "
            f"`{first['kind']}`, {_sign(first['size'])} {first['size_unit']}, the\nchange dated "
            f"from ~{first['onset_s']:.0f} s")


LEGS_MAKE = ("from pitotcal.maneuvers.fly.legs import simulate_leg_flight as s; \\\n"
             "  from pitotcal.io.flight_csv import write_flight_csv as w; "
             "w(s(seed=3, rate_hz=5)[0], 'legflight.csv')")


def _leg_flight(tmp):
    from pitotcal.io.flight_csv import write_flight_csv
    from pitotcal.maneuvers.fly.legs import simulate_leg_flight

    flight, truth, _ = simulate_leg_flight(seed=3, rate_hz=5)
    write_flight_csv(flight, tmp / "legflight.csv")
    return truth


def legs_truth(tmp):
    return ", ".join(_sign(v) for v in _leg_flight(tmp).dv_kt)


def legs_flight(tmp):
    """The `pitotcal legs FLIGHT` example: its time-series legs and the ΔV comparison."""
    _leg_flight(tmp)
    text = _cli("legs", tmp / "legflight.csv", "--legs-out", tmp / "legs.csv", "--json",
                tmp / "legs.json", "--plot", tmp / "legs.png").splitlines()
    head = next(i for i, line in enumerate(text) if line.startswith("Legs from the time series"))
    dv = next(i for i, line in enumerate(text) if line.startswith("ΔV at each point"))
    excerpt = [*text[head:head + 4], "  ...", *text[dv:dv + 6]]
    return "\n".join(["", "", "```", f'$ python -c "{LEGS_MAKE}"',
                      "$ pitotcal legs legflight.csv --legs-out legs.csv --json legs.json "
                      "--plot legs.png", "...", *excerpt, "```", "", ""])


# ---- the real log ---------------------------------------------------------------------------

def _sitl_log():
    """The ArduPlane SITL log of the shared data folder (None when absent)."""
    data = shared_data()
    log = None if data is None else data / "ardupilot" / "arduplane_sitl.log"
    return log if log is not None and log.is_file() else None


def _sitl_params(tmp, log):
    """(ARSPD_RATIO, its 2σ, the log's value) that `identify LOG --oat-c 15 --params` writes."""
    _cli("identify", log, "--oat-c", 15, "--no-budget", "--params", tmp / "sitl.parm")
    text = (tmp / "sitl.parm").read_text()
    value, two = map(float, re.search(r"ARSPD_RATIO = ([\d.]+) \+/- ([\d.]+)", text).groups())
    return value, two, float(re.search(r"current value ([\d.]+)", text).group(1))


def sitl_ratio(tmp):
    """`pitotcal identify arduplane_sitl.log --oat-c 15 --params`: the ratio it recommends."""
    log = _sitl_log()
    if log is None:
        return None
    value, two, current = _sitl_params(tmp, log)
    return (f"{value:.4f} ± {two:.4f} against the simulator's {current:.4f} "
            f"({_sign(100 * (value / current - 1), 2)} %)")


def sitl_k1(tmp):
    """`pitotcal identify arduplane_sitl.log --oat-c 15 --model constant`, both air data, and
    the ratio `--params` recommends from it."""
    log = _sitl_log()
    if log is None:
        return None
    k = {}
    for air in ("compressible", "incompressible"):
        _cli("identify", log, "--oat-c", 15, "--model", "constant", "--air", air, "--no-budget",
             "--json", tmp / f"{air}.json")
        k1 = json.loads((tmp / f"{air}.json").read_text())["parameters"]["k1"]
        k[air] = (k1["value"], 2 * k1["std"])
    ratio, two, _ = _sitl_params(tmp, log)
    return (f"k1 = {k['compressible'][0]:.4f} ± {k['compressible'][1]:.4f} with the default "
            f"compressible calibration ({k['incompressible'][0]:.4f} with\n  `--air "
            f"incompressible`, ArduPilot's own convention), i.e. ratio {ratio:.3f} ± {two:.3f}")


# ---- wall-clock numbers of this machine -------------------------------------------------------

def _wall(cmd, cwd, runs=3):
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(cmd, cwd=cwd, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _machine():
    """The cores and the load the times were measured under (other work slows them)."""
    return f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}"


def demo_time(tmp):
    s = _wall([sys.executable, "-m", "pitotcal", "demo", "--out", str(tmp / "demo")], tmp)
    return f"~{s:.0f} s on {_machine()}"


def identify_time(tmp):
    """`pitotcal identify` end to end (import, read, fit, budget, write) on 16,001 samples."""
    _cli("plan", "--duration-s", 320, "--no-figures", "-o", tmp / "p320.csv")
    _cli("simulate", tmp / "p320.csv", "-o", tmp / "f320.csv", "--seed", 0, "--air-data",
         "compressible")
    cmd = [sys.executable, "-m", "pitotcal", "identify", str(tmp / "f320.csv")]
    full, bare = _wall(cmd, tmp), _wall([*cmd, "--no-budget"], tmp)
    return (f"{full:.1f} s end to end on 16,001 samples ({bare:.2f} s with `--no-budget`; "
            f"{_machine()})")


PEERS_BENCH = ROOT / "benchmarks" / "bench_peers_speed.py"
PEERS_SAVED = {}          # {"path": a saved --json of the benchmark}, set by --bench-from


def _peer_ratio(r, peer):
    pairs = [a / b for a, b in zip(r["all_wall_s"]["identify"], r["all_wall_s"][peer])]
    return (f"{r['wall_s']['identify'] / r['wall_s'][peer]:.2f} "
            f"({min(pairs):.2f}–{max(pairs):.2f})")


def peers_speed(tmp):
    """benchmarks/bench_peers_speed.py: whole-process identify against the scipy script and
    AirspeedFit, medians of interleaved runs, with the machine they ran on."""
    saved = PEERS_SAVED.get("path")
    if saved is None:
        saved = tmp / "peers.json"
        subprocess.run([sys.executable, str(PEERS_BENCH), "--no-profile", "--json", str(saved)],
                       check=True, capture_output=True)
    run = json.loads(Path(saved).read_text())
    rows = ["| flight (samples) | runs | `pitotcal identify` | scipy script | AirspeedFit (node) "
            "| identify / scipy (runs' range) | identify / AirspeedFit (runs' range) |",
            "|---|---:|---:|---:|---:|---:|---:|"]
    for label, r in run["results"].items():
        wall, peak = r["wall_s"], r["peak_mb"]
        cell = [f"{wall[k]:.2f} s, {peak[k]:.0f} MB" if k in wall else "—"
                for k in ("identify", "scipy", "AirspeedFit")]
        ratio = [_peer_ratio(r, k) if k in wall else "—" for k in ("scipy", "AirspeedFit")]
        rows.append(f"| {label} | {r['runs']} | " + " | ".join(cell + ratio) + " |")
    note = (f"\nAirspeedFit skipped: {run['skipped']}\n" if run["skipped"] else "")
    return (f"\nWall time and peak memory of the whole process, medians of interleaved runs; "
            f"{run['machine']}.\n\n" + "\n".join(rows) + "\n" + note)


AF_BENCH = ROOT / "benchmarks" / "bench_airspeedfit.py"
AF_SAVED = {}             # {"path": a saved --out folder of the benchmark}, set by --afbench-from


def airspeedfit_bench(tmp):
    """benchmarks/bench_airspeedfit.py: ΔV error, coverage, wind and time against AirspeedFit
    on the same simulated flights and the SITL log (its table, as the benchmark wrote it)."""
    saved = AF_SAVED.get("path")
    if saved is None:
        saved, env = tmp, dict(os.environ)
        data = shared_data()
        if data is not None:
            env.setdefault("PITOTCAL_SHARED_DATA", str(data))
        subprocess.run([sys.executable, str(AF_BENCH), "--out", str(tmp)], check=True,
                       capture_output=True, env=env)
    run = json.loads((Path(saved) / "airspeedfit.json").read_text(encoding="utf-8"))
    return f"\n{run['table']}\n"


def tests_time(_):
    s = _wall([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"], ROOT, runs=1)
    return f"about {10 * round(s / 10):.0f} s on {_machine()}"


# name -> (kind, generator); kinds beyond "fixed" run only when asked
GENERATORS = {
    "demo-table": ("fixed", demo_table),
    "budget-example": ("fixed", budget_example),
    "budget-study": ("studies", budget_study),
    "monitor-example": ("fixed", monitor_example),
    "studies-cell": ("fixed", studies_cell),
    "studies-usage": ("fixed", studies_cell),
    "compressible-table": ("fixed", compressible_table),
    "legs-truth": ("fixed", legs_truth),
    "legs-flight": ("fixed", legs_flight),
    "sitl-ratio": ("data", sitl_ratio),
    "sitl-k1": ("data", sitl_k1),
    "demo-time": ("timings", demo_time),
    "identify-time": ("timings", identify_time),
    "tests-time": ("tests", tests_time),
    "peers-speed": ("bench", peers_speed),
    "airspeedfit-bench": ("afbench", airspeedfit_bench),
}


# name -> ((file its example wrote, relative to its folder), README figure); copied into docs/
# when the README is rewritten, so the figure shows the numbers the block quotes
FIGURES = {
    "demo-table": (("demo/calibration.png", "docs/figures/demo-calibration.png"),
                   ("demo/plan.png", "docs/figures/demo-plan.png")),
    "budget-example": (("ex.png", "docs/figures/budget-calibration.png"),),
    "budget-study": (("budget.png", "docs/figures/budget.png"),),
    "monitor-example": (("monitor-example.png", "docs/figures/monitor-example.png"),),
}


def blocks(text):
    """{name: body} of the marked blocks of `text` (a name may appear more than once)."""
    return {m["name"]: m["body"] for m in _BLOCK.finditer(text)}


def generate(names, figures=False):
    """{name: fresh body} for `names` (None: the example could not run here); with `figures`,
    also copy each example's figures (FIGURES) into docs/figures."""
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            work = Path(tmp) / name
            work.mkdir()
            out[name] = GENERATORS[name][1](work)
            for made, dest in FIGURES.get(name, ()):
                if figures and (work / made).is_file():
                    shutil.copyfile(work / made, ROOT / dest)
    return out


def rewrite(text, fresh):
    """`text` with each marked block's body replaced by its fresh one (None: left as is)."""
    def body(m):
        new = fresh.get(m["name"])
        return m[0] if new is None else (f"<!-- readme-numbers:{m['name']} -->{new}"
                                         f"<!-- /readme-numbers:{m['name']} -->")
    return _BLOCK.sub(body, text)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--check", action="store_true", help="compare only; exit 1 on a difference")
    p.add_argument("--timings", action="store_true", help="also the wall-clock numbers")
    p.add_argument("--tests", action="store_true", help="also time the lean test suite")
    p.add_argument("--studies", action="store_true",
                   help="also the studies' tables (seeded; a minute or more each)")
    p.add_argument("--bench", action="store_true",
                   help="also the speed race against the peers (benchmarks/bench_peers_speed.py)")
    p.add_argument("--bench-from", default=None, metavar="RUN.json",
                   help="the peers' speed block from a saved `bench_peers_speed.py --json` run")
    p.add_argument("--afbench", action="store_true",
                   help="also accuracy and time against AirspeedFit "
                        "(benchmarks/bench_airspeedfit.py, ~15 min)")
    p.add_argument("--afbench-from", default=None, metavar="DIR",
                   help="the AirspeedFit block from a saved `bench_airspeedfit.py --out DIR`")
    p.add_argument("--only", default=None, help="comma-separated block names")
    args = p.parse_args(argv)
    if args.bench_from:
        PEERS_SAVED["path"] = args.bench_from
    if args.afbench_from:
        AF_SAVED["path"] = args.afbench_from
    kinds = {"fixed", "data"} | ({"timings"} if args.timings else set()) \
        | ({"tests"} if args.tests else set()) | ({"studies"} if args.studies else set()) \
        | ({"bench"} if args.bench or args.bench_from else set()) \
        | ({"afbench"} if args.afbench or args.afbench_from else set())
    text = README.read_text(encoding="utf-8")
    present = blocks(text)
    names = [n for n in GENERATORS if n in present and GENERATORS[n][0] in kinds]
    if args.only:
        names = [n for n in args.only.split(",") if n in present]
    fresh = generate(names, figures=not args.check)
    for name, new in fresh.items():
        if new is None:
            print(f"{name}: left as it is (its data is absent: set PITOTCAL_SHARED_DATA)")
    differ = [n for n, new in fresh.items() if new is not None and new != present[n]]
    if args.check:
        for name in differ:
            print(f"{name}: README says {present[name]!r}, a fresh run gives {fresh[name]!r}")
        return 1 if differ else 0
    README.write_text(rewrite(text, fresh), encoding="utf-8")
    print(f"README.md: {len(differ)} of {len(fresh)} blocks rewritten ({', '.join(differ)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
