"""Benchmark of the maneuver planner (issue 3: the default 240 s continuous plan <= 5 s, aim 1 s;
issue 8: the whole default `pitotcal plan` <= 2x `python -c "import numpy, casadi,
matplotlib.pyplot"`).

Run: ``python benchmarks/bench_plan.py [--repeats 7]``. Prints a markdown table of medians
(a shared 2-core machine is noisy, +-2x): OCP build, cold plan (build + solve), warm plan (the
built problem reused), each profile, the refusal of a too-small radius (radius-minimising
solve), and the whole `pitotcal plan` command with its files, timed side by side with the
reference import (the two commands alternate, each in a fresh process; medians and ratio).
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _median(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


REFERENCE = [sys.executable, "-c", "import numpy, casadi, matplotlib.pyplot"]


def command_ratio(repeats, extra=()):
    """Medians of the default `pitotcal plan` (plus `extra` flags) and of the reference import,
    run alternately in fresh processes, and their ratio."""
    with tempfile.TemporaryDirectory() as tmp:
        plan = [sys.executable, "-m", "pitotcal", "plan", "-o", str(Path(tmp) / "p.csv"),
                *extra]
        times = {"plan": [], "reference": []}
        for _ in range(repeats):
            for name, cmd in (("reference", REFERENCE), ("plan", plan)):
                t0 = time.perf_counter()
                subprocess.run(cmd, check=True, capture_output=True)
                times[name].append(time.perf_counter() - t0)
    t_plan, t_ref = statistics.median(times["plan"]), statistics.median(times["reference"])
    return t_plan, t_ref, t_plan / t_ref


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args(argv)
    r = args.repeats

    import casadi  # noqa: F401  (import time is not planning time)
    from pitotcal.maneuvers.plan import planner
    from pitotcal.maneuvers.plan.planner import ManeuverProblem, plan_maneuver

    from pitotcal.core.errors import PlanInfeasibleError

    rows = []
    t_build, _ = _median(lambda: ManeuverProblem(240, 3), r)
    rows.append(("OCP build, N = 240", t_build, ""))

    def cold():
        planner._problem.cache_clear()
        return plan_maneuver()

    t_cold, plan = _median(cold, r)
    rows.append(("default continuous plan, cold (build + solve)", t_cold,
                 f"{plan.iterations} iterations, success={plan.success}"))
    for profile, kwargs in (("continuous", {}), ("continuous", {"return_leg": True}),
                            ("step-pause", {}), ("two-speed", {})):
        plan_maneuver(profile, **kwargs)               # build once
        t, plan = _median(lambda p=profile, k=kwargs: plan_maneuver(p, **k), r)
        label = profile + (" --return" if kwargs else "")
        rows.append((f"{label}, warm (solve only)", t, f"{plan.iterations} iterations"))
    t_fine, plan = _median(lambda: plan_maneuver(dt_s=0.5), max(3, r // 2))
    rows.append(("continuous at dt 0.5 s (N = 480), cold first", t_fine,
                 f"{plan.iterations} iterations"))

    def refuse():
        try:
            plan_maneuver(radius_m=484)
        except PlanInfeasibleError as exc:
            return str(exc)
        return "accepted?"

    t_refuse, msg = _median(refuse, max(3, r // 2))
    rows.append(("refuse radius 484 m (main solve + radius-minimising solve)", t_refuse,
                 msg.rsplit(":", 1)[-1].strip()))

    t_cli, t_ref, ratio = command_ratio(r)
    t_cli_nofig, t_ref2, ratio_nofig = command_ratio(r, ["--no-figures"])
    rows.append(("`python -c \"import numpy, casadi, matplotlib.pyplot\"` (reference)",
                 statistics.median([t_ref, t_ref2]), ""))
    rows.append(("`pitotcal plan` (process, imports, plan, 5 files, check)", t_cli,
                 f"{ratio:.2f}x the reference (target <= 2)"))
    rows.append(("`pitotcal plan --no-figures`", t_cli_nofig, f"{ratio_nofig:.2f}x"))

    print(f"| step (median of {r}) | seconds | note |\n|---|---:|---|")
    for name, t, note in rows:
        print(f"| {name} | {t:.3f} | {note} |")
    verdict = "PASS" if t_cold <= 5.0 else "FAIL"
    print(f"\ndefault 240 s continuous plan, cold: {t_cold:.3f} s (target <= 5 s, aim 1 s): "
          f"{verdict}")
    print(f"default `pitotcal plan`: {ratio:.2f}x the reference import (target <= 2): "
          f"{'PASS' if ratio <= 2.0 else 'FAIL'}")


if __name__ == "__main__":
    main()
