"""Benchmark: simulate a 320 s flight at 50 Hz (target <= 1 s; issue 3).

Run from the repository root:  python benchmarks/bench_simulate.py [--runs 5]
Plans with the planner (continuous profile, 320 s; planning is not timed), simulates with the
default options (0.5 m/s turbulence, 5 Hz GPS) and prints the median wall time of the runs and
the first call's (with the imports it triggers).
"""

import argparse
import statistics
import sys
import time


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--duration-s", type=float, default=320.0)
    parser.add_argument("--rate-hz", type=float, default=50.0)
    args = parser.parse_args(argv)

    from pitotcal.maneuvers.plan.planner import plan_maneuver
    from pitotcal.maneuvers.fly.simulator import simulate

    plan = plan_maneuver(duration_s=args.duration_s)
    t0 = time.perf_counter()
    simulate(plan, seed=0, rate_hz=args.rate_hz)               # first call: its imports too
    first_s = time.perf_counter() - t0
    times = []
    for seed in range(args.runs):
        t0 = time.perf_counter()
        flight, truth = simulate(plan, seed=seed, rate_hz=args.rate_hz)
        times.append(time.perf_counter() - t0)
    print(f"simulate {args.duration_s:.0f} s at {args.rate_hz:g} Hz ({flight.n} samples): "
          f"median {statistics.median(times):.3f} s, min {min(times):.3f} s, "
          f"max {max(times):.3f} s over {args.runs} runs (target <= 1 s)")
    print(f"first call (imports included): {first_s:.3f} s; python-control imported: "
          f"{'control' in sys.modules}")
    print(f"tracking: CAS error max {truth.tracking.max_cas_error_kt:.2f} kt, "
          f"max radius {truth.tracking.max_radius_m:.0f} m")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
