"""Dryden's vertical gust flown (issue 11): the plunge response, and the flight it makes."""

import numpy as np
import pytest
from pitotcal.maneuvers.fly.simulator import simulate
from pitotcal.maneuvers.turbulence import LIFT_SLOPE_PER_RAD, WING_LOADING_NPM2, plunge_response
from plans import circle_plan

from pitotcal.core.errors import PitotcalError


def test_plunge_follows_an_updraft_with_its_time_constant_and_the_hold_returns():
    dt, v, rho = 0.01, 40.0, 1.2
    tau = 2 * WING_LOADING_NPM2 / (9.80665 * rho * v * LIFT_SLOPE_PER_RAD)
    w_down = np.full(3000, -1.0)                       # a 1 m/s updraft from t = 0
    dh, vz = plunge_response(w_down, dt, v, rho, k_alt_per_s=0.0)
    i = round(tau / dt)
    assert vz[i] == pytest.approx(1 - np.exp(-1), abs=0.02)     # 1 - 1/e after tau
    assert vz[-1] == pytest.approx(1.0, abs=1e-3)
    assert dh[-1] == pytest.approx(dt * 3000 - tau, rel=0.02)   # rides the air mass up
    dh_hold, _ = plunge_response(w_down, dt, v, rho, k_alt_per_s=0.2)
    assert dh_hold[-1] == pytest.approx(1.0 / 0.2, rel=0.05)   # hold: offset v_z / k_alt


def test_vertical_gusts_reach_altitude_gps_climb_and_airspeed_only():
    plan = circle_plan(duration_s=60.0)
    base, truth = simulate(plan, seed=4, rate_hz=10.0, turbulence_mps=1.0)
    vert, truth_v = simulate(plan, seed=4, rate_hz=10.0, turbulence_mps=1.0,
                             vertical_gusts=True)
    assert "vertical_gusts" not in truth.options and truth_v.options["vertical_gusts"]
    # the horizontal gusts are the same draws
    np.testing.assert_allclose(vert.gps_vn_mps, base.gps_vn_mps, atol=1e-9)
    assert 0.1 < np.std(vert.gps_vd_mps - base.gps_vd_mps) < 3.0
    assert 0.05 < np.std(vert.alt_m - base.alt_m) < 20.0
    # V_t changes by the square of the air-relative climb only: a fraction of a percent
    rel = np.abs(vert.qci_pa / base.qci_pa - 1)
    assert 0 < rel.max() < 0.01
    with pytest.raises(PitotcalError, match="vertical_gusts"):
        simulate(plan, seed=4, rate_hz=10.0, vertical_gusts="yes")
