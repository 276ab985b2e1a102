"""Benchmark of the uncertainty budget (issue 9): its cost against one identification.

Run: ``python benchmarks/bench_budget.py [--repeats 5] [--sizes 4000 16000 100000]``.
For each N, a synthetic flight (5 Hz held GPS with a vertical channel, 0.05 m/s GPS noise,
0.5 Pa pressure noise, light turbulence): the median time of `identify` (the baseline, its
solver cached) and of `uncertainty_budget` with the default inputs and a 1 m probe arm (every
source re-solved: 14 solves), and their ratio, measured in the same run; then the whole
`pitotcal identify` command with and without the budget, alternating. Prints markdown tables.
"""

import argparse
import statistics
import sys
import time
from pathlib import Path

from timing import median_s

ROOT = Path(__file__).resolve().parents[1]



def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--sizes", type=int, nargs="+", default=[4000, 16000, 100000])
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT / "tests"))
    from pitotcal.estimation import identify
    from pitotcal.estimation.identification.budget import BudgetInputs, uncertainty_budget
    from synthetic import synthetic_flight

    inputs = BudgetInputs(probe_arm_m=1.0)
    print("| N | identify s | budget s | solves | budget / identify |")
    print("|---:|---:|---:|---:|---:|")
    for n in args.sizes:
        flight, _ = synthetic_flight(seed=1, n=n, gps_rate_hz=5.0, gps_noise_mps=0.05,
                                     qc_noise_pa=0.5, turbulence_mps=0.3, vertical=True)
        result = identify(flight)                      # builds and caches the solver
        t_id = median_s(lambda f=flight: identify(f), args.repeats)
        t_b = median_s(lambda f=flight, r=result: uncertainty_budget(f, r, inputs),
                        args.repeats)
        print(f"| {n:,} | {t_id:.3f} | {t_b:.3f} | 14 | {t_b / t_id:.1f} |")
    _command(synthetic_flight, args.repeats)


def _command(synthetic_flight, repeats):
    """`pitotcal identify` on a 16,000-sample CSV with and without the budget (alternating)."""
    import subprocess
    import tempfile

    from pitotcal.io import write_flight_csv

    with tempfile.TemporaryDirectory() as tmp:
        flight, _ = synthetic_flight(seed=1, n=16000, gps_rate_hz=5.0, gps_noise_mps=0.05,
                                     qc_noise_pa=0.5, turbulence_mps=0.3)
        path = write_flight_csv(flight, Path(tmp) / "flight.csv")
        base = [sys.executable, "-m", "pitotcal", "identify", str(path), "--json",
                str(Path(tmp) / "out.json")]
        times = {"with budget": [], "--no-budget": []}
        for _ in range(repeats):
            for label, extra in (("with budget", []), ("--no-budget", ["--no-budget"])):
                start = time.perf_counter()
                subprocess.run(base + extra, check=True, capture_output=True)
                times[label].append(time.perf_counter() - start)
    print("\n| `pitotcal identify FLIGHT.csv --json OUT.json` (16,000 samples) | wall s |")
    print("|---|---:|")
    for label, values in times.items():
        print(f"| {label} | {statistics.median(values):.2f} |")


if __name__ == "__main__":
    main()
