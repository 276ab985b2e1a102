"""The benchmarks' one timing helper (the scripts run from this folder, so it imports as
`timing`)."""

import statistics
import time


def median_s(fun, repeats):
    """Median wall time of `repeats` calls of `fun()`, seconds."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fun()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def median_result(fun, repeats):
    """(median wall time of `repeats` calls of `fun()`, seconds; the last call's result)."""
    times, out = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        out = fun()
        times.append(time.perf_counter() - start)
    return statistics.median(times), out
