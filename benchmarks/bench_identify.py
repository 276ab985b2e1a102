"""Benchmark of the output-error identification (issue 2: N = 16,000 solve + covariance <= 50 ms,
N = 1e6 <= 3 s and <= 1 GB; `pitotcal identify` <= 1.5x a plain scipy/numpy script).

Run: ``python benchmarks/bench_identify.py [--repeats 5] [--sizes 1000 16000 100000 1000000]``.
Each N runs in a fresh subprocess so its peak memory (max RSS; tracemalloc cannot see CasADi's
C++ allocations) is its own. Prints a markdown table of medians; the machine is shared and
noisy (+-2x).
"""

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# The plain script the CLI is compared with: read the CSV, least_squares, print the answer.
PLAIN_SCRIPT = r"""
import sys, numpy as np
from scipy.optimize import least_squares
d = np.genfromtxt(sys.argv[1], delimiter=",", names=True, comments="#")
q, vn, ve, rho = d["qc_pa"], d["gps_vn_mps"], d["gps_ve_mps"], d["rho_kgm3"]
def res(x):
    k1, k2, wn, we = x[0] * 0.01, x[1] * 10.0, x[2], x[3]
    return q - 0.5 * rho * (1 - k1 - k2 / q) * ((vn - wn) ** 2 + (ve - we) ** 2)
def jac(x):
    k1, k2, wn, we = x[0] * 0.01, x[1] * 10.0, x[2], x[3]
    v2 = (vn - wn) ** 2 + (ve - we) ** 2
    a = 0.5 * rho * (1 - k1 - k2 / q)
    return np.column_stack([0.005 * rho * v2, 5.0 * rho * v2 / q, 2 * a * (vn - wn), 2 * a * (ve - we)])
s = least_squares(res, np.zeros(4), jac=jac, method="lm")
r = s.fun; J = s.jac
cov = r @ r / (r.size - 4) * np.linalg.inv(J.T @ J)
print(s.x, np.sqrt(np.diag(cov)))
"""


def _flight(n, seed=0):
    sys.path.insert(0, str(ROOT / "tests"))
    from synthetic import synthetic_flight
    return synthetic_flight(seed=seed, n=n, gps_rate_hz=5.0, gps_noise_mps=0.05, qc_noise_pa=0.5)[0]


def _scipy_fit(flight):
    """Yardstick: least_squares (lm, analytic Jacobian) on the same residual and start."""
    import numpy as np
    from pitotcal.estimation.identification.oe import start_values
    from scipy.optimize import least_squares

    from pitotcal.core.models import get_model

    q, vn, ve, rho = flight.qci_pa, flight.gps_vn_mps, flight.gps_ve_mps, flight.rho_kgm3
    scale = np.array([0.01, 10.0, 1.0, 1.0])

    def res(x):
        k1, k2, wn, we = x * scale
        return q - 0.5 * rho * (1 - k1 - k2 / q) * ((vn - wn) ** 2 + (ve - we) ** 2)

    def jac(x):
        k1, k2, wn, we = x * scale
        v2 = (vn - wn) ** 2 + (ve - we) ** 2
        a = 0.5 * rho * (1 - k1 - k2 / q)
        return np.column_stack([0.5 * rho * v2 * scale[0], 0.5 * rho * v2 / q * scale[1],
                                2 * a * (vn - wn), 2 * a * (ve - we)])

    x0 = start_values(get_model("inverse"), q, vn, ve, rho) / scale
    sol = least_squares(res, x0, jac=jac, method="lm")
    r, j = sol.fun, sol.jac
    return sol.x * scale, r @ r / (r.size - 4) * np.linalg.inv(j.T @ j)


def worker(n, repeats):
    """One N in this process: prints a JSON line of medians and the peak RSS."""
    from pitotcal.estimation.identification.oe import OutputErrorProblem

    flight = _flight(n)
    problem = OutputErrorProblem("inverse")
    t0 = time.perf_counter()
    problem._build(n, False)
    build = time.perf_counter() - t0
    solves, covs, iters = [], [], []
    for _ in range(repeats):
        result = problem.solve(flight)
        solves.append(result.timing_s["solve"])
        covs.append(result.timing_s["covariance"])
        iters.append(result.iterations)
    scipy_times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        _scipy_fit(flight)
        scipy_times.append(time.perf_counter() - t0)
    print(json.dumps({
        "n": n, "build_s": build, "solve_s": statistics.median(solves),
        "covariance_s": statistics.median(covs), "iterations": statistics.median(iters),
        "scipy_s": statistics.median(scipy_times), "success": bool(result.success),
        "max_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }))


def _time_command(cmd, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--sizes", type=int, nargs="+", default=[1000, 16000, 100000, 1000000])
    parser.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        sys.path.insert(0, str(ROOT))
        return worker(args.worker, args.repeats)

    rows = []
    for n in args.sizes:
        repeats = args.repeats if n < 1_000_000 else max(1, min(args.repeats, 3))
        out = subprocess.run([sys.executable, __file__, "--worker", str(n), "--repeats", str(repeats)],
                             check=True, capture_output=True, text=True, cwd=ROOT)
        rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
    print("| N | build s | solve s | covariance s | solve+cov s | IPOPT iter | scipy lm s | peak RSS MB |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['n']:,} | {r['build_s']:.3f} | {r['solve_s']:.3f} | {r['covariance_s']:.3f} | "
              f"{r['solve_s'] + r['covariance_s']:.3f} | {r['iterations']:.0f} | {r['scipy_s']:.3f} | "
              f"{r['max_rss_mb']:.0f} |")

    # whole command on a 16,000-sample CSV vs a plain scipy/numpy script doing the same
    sys.path.insert(0, str(ROOT))
    from pitotcal.io import write_flight_csv
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "flight.csv"
        write_flight_csv(_flight(16000), csv)
        script = Path(tmp) / "plain.py"
        script.write_text(PLAIN_SCRIPT)
        out = str(Path(tmp) / "o.json")
        # `python -m pitotcal`: the venv's command, whether or not its bin/ is on PATH
        command = [sys.executable, "-m", "pitotcal", "identify", str(csv), "--json", out]
        cli = _time_command(command + ["--no-budget"], args.repeats)
        full = _time_command(command, args.repeats)
        plain = _time_command([sys.executable, str(script), str(csv)], args.repeats)
    print()
    print("| command (16,000-sample CSV) | wall s |")
    print("|---|---:|")
    print(f"| `pitotcal identify FLIGHT.csv --json OUT.json --no-budget` | {cli:.2f} |")
    print(f"| plain script (numpy.genfromtxt + scipy least_squares + covariance) | {plain:.2f} |")
    print(f"| ratio (target <= 1.5) | {cli / plain:.2f} |")
    print(f"| the default command, with the GUM budget's re-solves (issue 9) | {full:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
