"""Benchmark of `plan --design optimal` (issue 13: planning the default optimal design <= 2 s).

Run: ``python benchmarks/bench_design.py [--repeats 5]``. Prints a markdown table of medians:
the schedule design alone (scoring every candidate), the whole optimal plan in process cold
(the OCP built) and warm (built problem reused), with a target 2σ, and the whole
`pitotcal plan --design optimal` command beside the reference import (as bench_plan.py).
"""

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_plan import command_ratio
from timing import median_result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    r = args.repeats

    import casadi  # noqa: F401  (import time is not planning time)
    import numpy as np
    from pitotcal.maneuvers.plan import planner
    from pitotcal.maneuvers.plan.design import default_noise, design_schedule
    from pitotcal.maneuvers.plan.planner import plan_maneuver

    from pitotcal.core.units import wind_vector_mps

    rows = []
    noise = default_noise(0.5, 244.0, [44.0])
    t, d = median_result(lambda: design_schedule(
        70.0, 100.0, 240.0, altitude_m=244.0, accel_max_mps2=1.0, dt_s=1.0,
        bank_max_rad=np.radians(30.0), radius_m=926.0, wind_ne_mps=wind_vector_mps(5, 270),
        noise=noise, coverage_rad=2 * np.pi + np.radians(15.0)), r)
    rows.append(("schedule design alone (240 s)", t, f"{d.candidates} candidates scored"))

    def cold():
        planner._problem.cache_clear()
        return plan_maneuver(design="optimal")

    t_cold, plan = median_result(cold, r)
    rows.append(("default optimal plan, cold (design + OCP build + solve)", t_cold,
                 f"{plan.iterations} iterations, success={plan.success}"))
    t, plan = median_result(lambda: plan_maneuver(design="optimal"), r)
    rows.append(("default optimal plan, warm", t, f"{plan.iterations} iterations"))
    t, plan = median_result(lambda: plan_maneuver(design="optimal",
                                            design_options={"target_2sigma_kt": 0.6}), r)
    rows.append(("optimal plan for target 0.6 kt", t, f"{plan.time_s[-1]:.0f} s flight"))
    t_plan, t_ref, ratio = command_ratio(r, ("--design", "optimal"))
    rows.append(("`pitotcal plan --design optimal` (whole command, files)", t_plan, ""))
    rows.append(("reference `python -c 'import numpy, casadi, matplotlib.pyplot'`", t_ref,
                 f"ratio {ratio:.2f}"))
    print("| step | median s | note |\n|---|---:|---|")
    for name, sec, note in rows:
        print(f"| {name} | {sec:.3f} | {note} |")
    print(f"\nplanning the default optimal design, cold: {t_cold:.3f} s (target <= 2 s): "
          f"{'PASS' if t_cold <= 2.0 else 'FAIL'}")
    print(f"whole `pitotcal plan --design optimal`: {t_plan:.3f} s, {ratio:.2f}x the reference "
          f"import ({t_ref:.3f} s)")


if __name__ == "__main__":
    main()
