"""Benchmark of the uncertainty budget: its cost against one identification, by sensitivities
and by re-solves, and how closely the two agree.

Run: ``python benchmarks/bench_budget.py [--repeats 5] [--sizes 4000 16000 100000]
[--no-resolve-above N]``. For each N, a synthetic flight (5 Hz held GPS with a vertical
channel, 0.05 m/s GPS noise, 0.5 Pa pressure noise, light turbulence): the median time of
`identify` (the baseline, its solver cached) and of `uncertainty_budget` with the default inputs
and a 1 m probe arm, by sensitivities (the default: no solve) and by
re-solves (`method="resolve"`: 14 solves), measured alternating in the same run, and the
largest relative difference of any term at any speed. Then the whole `pitotcal identify`
command on a 16,000-sample flight: the budget by sensitivities, by re-solves and
--no-budget, alternating. Prints markdown tables.
"""

import argparse
import statistics
import sys
import time
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]



def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--sizes", type=int, nargs="+", default=[4000, 16000, 100000])
    parser.add_argument("--no-resolve-above", type=int, default=10 ** 9,
                        help="time only the sensitivities above this N (re-solves take minutes)")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT / "tests"))
    from pitotcal.estimation import identify
    from pitotcal.estimation.identification.budget import BudgetInputs, uncertainty_budget
    from synthetic import synthetic_flight

    inputs = BudgetInputs(probe_arm_m=1.0)
    print("| N | identify s | budget by sensitivities s | by re-solves s | re-solves / "
          "sensitivities | largest difference |")
    print("|---:|---:|---:|---:|---:|---:|")
    for n in args.sizes:
        flight, _ = synthetic_flight(seed=1, n=n, gps_rate_hz=5.0, gps_noise_mps=0.05,
                                     qc_noise_pa=0.5, turbulence_mps=0.3, vertical=True)
        result = identify(flight)                      # builds and caches the solver
        times = {"identify": [], "sensitivity": [], "resolve": []}
        budgets = {}
        methods = ("sensitivity",) if n > args.no_resolve_above else ("sensitivity", "resolve")
        for _ in range(args.repeats):
            times["identify"].append(_timed(lambda f=flight: identify(f))[0])
            for method in methods:
                t, budgets[method] = _timed(lambda f=flight, r=result, m=method:
                                            uncertainty_budget(f, r, inputs, method=m))
                times[method].append(t)
        med = {k: statistics.median(v) if v else float("nan") for k, v in times.items()}
        diff = _difference(*budgets.values()) if len(budgets) == 2 else float("nan")
        print(f"| {n:,} | {med['identify']:.3f} | {med['sensitivity']:.3f} | "
              f"{med['resolve']:.3f} | {med['resolve'] / med['sensitivity']:.1f} | "
              f"{diff:.1e} |")
    _command(synthetic_flight, args.repeats)


def _timed(fun):
    start = time.perf_counter()
    out = fun()
    return time.perf_counter() - start, out


def _difference(a, b):
    """The largest relative difference of two budgets' terms (ΔV, ΔH, ΔM) at any speed."""
    import numpy as np

    pairs = [(a.terms_kt[k], b.terms_kt[k]) for k in a.terms_kt]
    pairs += [(a.products[p][k], b.products[p][k]) for p in a.products for k in a.products[p]]
    return max(float(np.nanmax(np.abs(x - y) / np.maximum(np.abs(y), 1e-12)))
               for x, y in pairs)


# The command with the budget by re-solves: the same entry point, its default method changed
_RESOLVE = ("import sys; from pitotcal.estimation.identification import budget; "
            "budget.uncertainty_budget.__kwdefaults__['method'] = 'resolve'; "
            "from pitotcal.cli import main; sys.exit(main(sys.argv[1:]))")


def _command(synthetic_flight, repeats):
    """`pitotcal identify` on a 16,000-sample CSV: the budget by sensitivities, by re-solves
    and --no-budget (alternating)."""
    import subprocess
    import tempfile

    from pitotcal.io import write_flight_csv

    with tempfile.TemporaryDirectory() as tmp:
        flight, _ = synthetic_flight(seed=1, n=16000, gps_rate_hz=5.0, gps_noise_mps=0.05,
                                     qc_noise_pa=0.5, turbulence_mps=0.3)
        path = write_flight_csv(flight, Path(tmp) / "flight.csv")
        args = ["identify", str(path), "--json", str(Path(tmp) / "out.json")]
        runs = {"budget by sensitivities (default)": [sys.executable, "-m", "pitotcal", *args],
                "budget by re-solves": [sys.executable, "-c", _RESOLVE, *args],
                "--no-budget": [sys.executable, "-m", "pitotcal", *args, "--no-budget"]}
        times = {label: [] for label in runs}
        for _ in range(repeats):
            for label, command in runs.items():
                start = time.perf_counter()
                subprocess.run(command, check=True, capture_output=True)
                times[label].append(time.perf_counter() - start)
    print("\n| `pitotcal identify FLIGHT.csv --json OUT.json` (16,000 samples) | wall s |")
    print("|---|---:|")
    for label, values in times.items():
        print(f"| {label} | {statistics.median(values):.2f} |")


if __name__ == "__main__":
    main()
