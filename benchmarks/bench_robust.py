"""Benchmark of issue 15's robustness in `identify` (gates, trimming, step-change test):
identification time at N = 16,000 with them and without (bypassed in the same process), so
the ratio is measured on one machine load. Target: <= 1.5x.

Run: ``python benchmarks/bench_robust.py [--repeats 9] [--n 16000]``. Prints medians.
"""

import argparse
import statistics
import sys
import time
from pathlib import Path
from unittest import mock

ROOT = Path(__file__).resolve().parents[1]


def _flight(n):
    sys.path.insert(0, str(ROOT / "tests"))
    from synthetic import synthetic_flight
    return synthetic_flight(seed=0, n=n, gps_rate_hz=5.0, gps_noise_mps=0.05, qc_noise_pa=0.5,
                            turbulence_mps=0.5)[0]


def _plain():
    """The robust steps bypassed: identify as before issue 15."""
    import numpy as np
    from pitotcal.estimation.robustness import consistency
    from pitotcal.estimation.robustness import gates as robust

    return (mock.patch.object(robust, "gate_flight", lambda f: (f, ())),
            mock.patch.object(robust, "outliers", lambda r: np.zeros(len(r), dtype=bool)),
            mock.patch.object(consistency, "check", lambda *a: ((), {})))


def _time(flight, bypass):
    from pitotcal.estimation import identify

    patches = _plain() if bypass else ()
    for p in patches:
        p.start()
    try:
        t0 = time.perf_counter()
        identify(flight, air="incompressible")
        return time.perf_counter() - t0
    finally:
        for p in patches:
            p.stop()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--n", type=int, default=16000)
    args = parser.parse_args(argv)
    flight = _flight(args.n)
    _time(flight, False)            # build and cache the solver
    before, after = [], []
    for _ in range(args.repeats):   # interleaved: both see the same load
        before.append(_time(flight, True))
        after.append(_time(flight, False))
    b, a = statistics.median(before), statistics.median(after)
    print("| N | identify before s | identify with robustness s | ratio |")
    print("|---:|---:|---:|---:|")
    print(f"| {args.n:,} | {b:.3f} | {a:.3f} | {a / b:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
