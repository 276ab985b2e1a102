"""Monte Carlo coverage of the 2-sigma bounds in turbulence with 5 Hz sample-and-hold GPS.

The corrected (colored-residual) bounds must cover 90-98% of the truths; the plain Hessian
bounds are stated for comparison (measured: ~8% at N = 16,000, ~13% at N = 4,000).
"""

import numpy as np
import pytest

from estimation import OutputErrorProblem
from synthetic import synthetic_flight

FLIGHT = dict(turbulence_mps=0.5, gps_rate_hz=5.0, gps_noise_mps=0.05, qc_noise_pa=0.5)


def _coverage(runs, n, seed0):
    problem = OutputErrorProblem("inverse")
    inside, inside_plain = [], []
    for seed in range(seed0, seed0 + runs):
        flight, truth = synthetic_flight(seed=seed, n=n, **FLIGHT)
        result = problem.solve(flight)
        assert result.success
        true = np.array(list(truth["k"]) + [truth["wind_n_mps"], truth["wind_e_mps"]])
        err = np.abs(result.internal_params - true)
        inside.append(err <= 2 * np.sqrt(np.diag(result.internal_covariance)))
        inside_plain.append(err <= 2 * np.sqrt(np.diag(result.internal_covariance_plain)))
    return float(np.mean(inside)), float(np.mean(inside_plain))


def test_coverage_lean():
    # 40 runs x 4 parameters (correlated within a run): a 95% coverage shows as 85-100%
    covered, covered_plain = _coverage(runs=40, n=4000, seed0=1000)
    assert 0.85 <= covered <= 1.0, covered
    assert covered_plain < 0.5, covered_plain
    assert covered - covered_plain > 0.4


@pytest.mark.slow
def test_coverage_full():
    covered, covered_plain = _coverage(runs=200, n=16000, seed0=5000)
    assert 0.90 <= covered <= 0.98, covered
    assert covered_plain < 0.3, covered_plain
