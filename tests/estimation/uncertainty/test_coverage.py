"""Monte Carlo coverage of the 2-sigma bounds in turbulence with 5 Hz sample-and-hold GPS.

The corrected (colored-residual) bounds must cover 90-98% of the truths; the plain Hessian
bounds are stated for comparison (measured: ~8% at N = 16,000, ~13% at N = 4,000).
"""

import numpy as np
import pytest
from pitotcal.estimation import OutputErrorProblem
from synthetic import synthetic_flight

FLIGHT = {"turbulence_mps": 0.5, "gps_rate_hz": 5.0, "gps_noise_mps": 0.05, "qc_noise_pa": 0.5}


def _coverage(runs, n, seed0, per_parameter=False):
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
    if per_parameter:
        return np.mean(inside, axis=0), np.mean(inside_plain, axis=0)
    return float(np.mean(inside)), float(np.mean(inside_plain))


def test_coverage_lean():
    # 40 runs x 4 parameters (correlated within a run): a 95% coverage shows as 85-100%
    covered, covered_plain = _coverage(runs=40, n=4000, seed0=1000)
    assert 0.85 <= covered <= 1.0, covered
    assert covered_plain < 0.5, covered_plain
    assert covered - covered_plain > 0.4


@pytest.mark.slow
def test_coverage_full():
    """k1 and k2 inside 90-98% (measured 96.5/97.5%). The wind bounds are conservative against
    this truth, the realized mean of the wind flown through, which absorbs the slow turbulence
    that the bounds count as error (measured 99-100%); they must cover at least 90%. The
    simulator-based `pitotcal study coverage` asserts 90-98% over all parameters
    (tests/studies, measured 96.1%)."""
    covered, covered_plain = _coverage(runs=200, n=16000, seed0=5000, per_parameter=True)
    assert np.all((0.90 <= covered[:2]) & (covered[:2] <= 0.98)), covered
    assert np.all(covered[2:] >= 0.90), covered
    assert np.mean(covered_plain) < 0.3, covered_plain
