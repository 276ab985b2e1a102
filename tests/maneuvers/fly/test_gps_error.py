"""Gauss-Markov GPS velocity error (issue 11): its statistics, and flights without it unchanged."""

import numpy as np
import pytest
from pitotcal.maneuvers.fly.sensors import gauss_markov, gps_velocity_sensor
from pitotcal.maneuvers.fly.simulator import simulate
from plans import circle_plan

from pitotcal.core.errors import PitotcalError


def test_gauss_markov_has_its_sigma_and_correlation_time():
    t = np.arange(0.0, 20000.0, 1.0)
    x = gauss_markov(t, 2, np.random.default_rng(0), 0.05, 30.0)
    assert x.shape == (t.size, 2)
    np.testing.assert_allclose(x.std(axis=0), 0.05, rtol=0.1)
    rho30 = np.mean(x[30:] * x[:-30]) / np.mean(x * x)
    assert abs(rho30 - np.exp(-1.0)) < 0.08
    with pytest.raises(PitotcalError, match="gps_gm_tau_s"):
        gauss_markov(t, 2, np.random.default_rng(0), 0.05, 0.0)


def test_default_flight_unchanged_and_error_only_in_gps():
    plan = circle_plan(duration_s=60.0)
    base, truth = simulate(plan, seed=3, rate_hz=10.0)
    same, _ = simulate(plan, seed=3, rate_hz=10.0, gps_gm_sigma_mps=0.0)
    gm, truth_gm = simulate(plan, seed=3, rate_hz=10.0, gps_gm_sigma_mps=0.05, gps_gm_tau_s=30.0)
    np.testing.assert_array_equal(base.gps_vn_mps, same.gps_vn_mps)
    assert "gps_gm_sigma_mps" not in truth.options
    assert truth_gm.options["gps_gm_tau_s"] == 30.0
    np.testing.assert_array_equal(base.qci_pa, gm.qci_pa)
    diff = gm.gps_vn_mps - base.gps_vn_mps
    assert 0 < np.abs(diff).max() < 0.3
    # held at the GPS rate like the white noise
    held = gps_velocity_sensor(base.time_s, np.zeros((base.n, 1)), np.random.default_rng(1),
                               rate_hz=5.0, noise_mps=0.0, gm_sigma_mps=0.05)
    assert np.all(held[0:-1:2, 0] == held[1::2, 0])
