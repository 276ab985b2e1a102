"""Benchmark of the maneuver planner (issue 3: the default 240 s continuous plan <= 5 s, aim 1 s;
issue 8 / issue 21: the whole default `pitotcal plan` <= 2x the bare import of what it needs).

Run: ``python benchmarks/bench_plan.py [--repeats 7]``. Prints a markdown table of medians
(a shared 2-core machine is noisy, +-2x): OCP build, cold plan (build + solve), warm plan (the
built problem reused), each profile, the refusal of a too-small radius (radius-minimising
solve), and the whole `pitotcal plan` command with its files, timed beside two baselines run in
the same loop (the commands alternate, each in a fresh process): the bare
``import numpy, casadi, matplotlib`` and ``import numpy, casadi, matplotlib.pyplot`` (the
figure machinery the PNGs need). Each command's wall time and its CPU time (user + system of
the process and the children it waits for: the forked figure process) are reported with their
ratios to the baselines; on a loaded machine the CPU ratio is the steadier one.
``--before DIR`` adds, to the same loop, the command run from another copy of the package
(``PYTHONPATH=DIR``, a folder holding a `pitotcal` package, e.g. an older commit laid out as
installed): a before/after comparison under the same load. The load average is printed.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from timing import median_s

BASELINES = {
    "bare": [sys.executable, "-c", "import numpy, casadi, matplotlib"],
    "pyplot": [sys.executable, "-c", "import numpy, casadi, matplotlib.pyplot"],
}


def _run(cmd, env=None):
    """(wall s, CPU s) of one fresh process, children included."""
    before = os.times()
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    wall = time.perf_counter() - t0
    after = os.times()
    return wall, (after.children_user - before.children_user
                  + after.children_system - before.children_system)


def command_ratios(repeats, extra=(), before=None):
    """Medians (wall, CPU) of the default `pitotcal plan` (plus `extra` flags) and of the
    baselines, run alternately in fresh processes: {name: (wall_s, cpu_s)}; with `before` (a
    PYTHONPATH folder) also the command from that copy of the package, as "before"."""
    with tempfile.TemporaryDirectory() as tmp:
        plan = [sys.executable, "-m", "pitotcal", "plan", "-o", str(Path(tmp) / "p.csv"),
                *extra]
        cmds = {name: (cmd, None) for name, cmd in BASELINES.items()}
        cmds["plan"] = (plan, None)
        if before is not None:
            cmds["before"] = (plan, {**os.environ, "PYTHONPATH": str(before)})
        runs = {name: [] for name in cmds}
        for _ in range(repeats):
            for name, (cmd, env) in cmds.items():
                runs[name].append(_run(cmd, env))
    return {name: (statistics.median(w for w, _ in r), statistics.median(c for _, c in r))
            for name, r in runs.items()}


def command_ratio(repeats, extra=()):
    """(plan wall s, pyplot-baseline wall s, ratio): `command_ratios` for bench_design."""
    med = command_ratios(repeats, extra)
    return med["plan"][0], med["pyplot"][0], med["plan"][0] / med["pyplot"][0]


def _ratio_note(med, name="plan"):
    wall, cpu = med[name]
    return ", ".join(f"{wall / med[b][0]:.2f}x wall / {cpu / med[b][1]:.2f}x CPU of {b}"
                     for b in BASELINES)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--before", type=Path, default=None, metavar="DIR",
                        help="also time `pitotcal plan` from this PYTHONPATH folder")
    parser.add_argument("--command-only", action="store_true",
                        help="time only the commands, not the planner's steps")
    args = parser.parse_args(argv)
    load = os.getloadavg()
    r = args.repeats

    import casadi  # noqa: F401  (import time is not planning time)
    from pitotcal.maneuvers.plan import planner
    from pitotcal.maneuvers.plan.planner import ManeuverProblem, plan_maneuver

    from pitotcal.core.errors import PlanInfeasibleError

    rows = []
    if args.command_only:
        return _commands(rows, r, args.before, load)
    rows.append(("OCP build, N = 240", median_s(lambda: ManeuverProblem(240, 3), r), ""))

    def cold():
        planner._problem.cache_clear()
        return plan_maneuver()

    plan = cold()
    t_cold = median_s(cold, r)
    rows.append(("default continuous plan, cold (build + solve)", t_cold,
                 f"{plan.iterations} iterations, success={plan.success}"))
    for profile, kwargs in (("continuous", {}), ("continuous", {"return_leg": True}),
                            ("step-pause", {}), ("two-speed", {})):
        plan = plan_maneuver(profile, **kwargs)               # build once
        t = median_s(lambda p=profile, k=kwargs: plan_maneuver(p, **k), r)
        label = profile + (" --return" if kwargs else "")
        rows.append((f"{label}, warm (solve only)", t, f"{plan.iterations} iterations"))
    plan = plan_maneuver(dt_s=0.5)
    t_fine = median_s(lambda: plan_maneuver(dt_s=0.5), max(3, r // 2))
    rows.append(("continuous at dt 0.5 s (N = 480)", t_fine, f"{plan.iterations} iterations"))

    def refuse():
        try:
            plan_maneuver(radius_m=484)
        except PlanInfeasibleError as exc:
            return str(exc)
        return "accepted?"

    msg = refuse()
    t_refuse = median_s(refuse, max(3, r // 2))
    rows.append(("refuse radius 484 m (main solve + radius-minimising solve)", t_refuse,
                 msg.rsplit(":", 1)[-1].strip()))

    verdict = "PASS" if t_cold <= 5.0 else "FAIL"
    _commands(rows, r, args.before, load)
    print(f"default 240 s continuous plan, cold: {t_cold:.3f} s (target <= 5 s, aim 1 s): "
          f"{verdict}")


def _commands(rows, r, before, load):
    """Time the commands beside the baselines and print `rows` and the ratios."""
    med = command_ratios(r, before=before)
    nofig = command_ratios(r, ["--no-figures"])
    for name, cmd in BASELINES.items():
        rows.append((f"`{' '.join(cmd[1:])}` (baseline)", med[name][0],
                     f"CPU {med[name][1]:.3f} s"))
    rows.append(("`pitotcal plan` (process, imports, plan, 5 files, check)", med["plan"][0],
                 f"CPU {med['plan'][1]:.3f} s; {_ratio_note(med)}"))
    if before is not None:
        rows.append(("`pitotcal plan` from --before", med["before"][0],
                     f"CPU {med['before'][1]:.3f} s; {_ratio_note(med, 'before')}"))
    rows.append(("`pitotcal plan --no-figures`", nofig["plan"][0],
                 f"CPU {nofig['plan'][1]:.3f} s; {_ratio_note(nofig)}"))

    print(f"| step (median of {r}) | wall s | note |\n|---|---:|---|")
    for name, t, note in rows:
        print(f"| {name} | {t:.3f} | {note} |")
    print()
    for b in BASELINES:
        ratio = med["plan"][0] / med[b][0]
        print(f"default `pitotcal plan`: {ratio:.2f}x the {b} import's wall time, "
              f"{med['plan'][1] / med[b][1]:.2f}x its CPU (target <= 2): "
              f"{'PASS' if ratio <= 2.0 else 'FAIL'}")
    print("load average (1, 5, 15 min) before: {:.2f} {:.2f} {:.2f}, after: {:.2f} {:.2f} "
          "{:.2f}".format(*load, *os.getloadavg()))


if __name__ == "__main__":
    main()
