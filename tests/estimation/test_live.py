"""`estimation.live.LiveIdentifier`: the warm-started live update gives the cold solve's answer
(the same optimum), the truth within its bounds, and `identify`'s answer on a clean record."""

import numpy as np
import pytest
from pitotcal.estimation import identify
from pitotcal.estimation.live import LiveIdentifier
from synthetic import synthetic_flight


@pytest.fixture(scope="module")
def flight_truth():
    return synthetic_flight(seed=2, n=6000, rate_hz=50.0, turbulence_mps=0.5,
                            gps_noise_mps=0.1)


def test_warm_update_equals_cold_and_offline(flight_truth):
    flight, truth = flight_truth
    live = LiveIdentifier("inverse", air="incompressible")
    first = live.update(flight.window(None, flight.time_s[-1] - 10.0))
    assert first.success and live.start is not None
    warm = live.update(flight)
    cold = LiveIdentifier("inverse", air="incompressible").update(flight, warm=False)
    offline = identify(flight, air="incompressible")
    assert warm.success and cold.success
    # the same optimum from either start (IPOPT tol 1e-6 on the scaled unknowns)
    np.testing.assert_allclose(warm.params, cold.params, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(warm.std, cold.std, rtol=1e-4)
    np.testing.assert_allclose(warm.params, offline.params, rtol=1e-5, atol=1e-6)
    for i, name in enumerate(("k1", "k2")):
        assert abs(warm.params[i] - truth["parameters"][name]) < 3 * warm.std[i]


def test_auto_updates_are_identify():
    flight, _ = synthetic_flight(seed=3, n=3000, rate_hz=50.0)
    live = LiveIdentifier("auto", air="incompressible")
    got = live.update(flight)
    assert live.problem is None
    np.testing.assert_allclose(got.params, identify(flight, model="auto",
                                                    air="incompressible").params)


def test_a_stated_gps_error_reaches_the_live_bounds(flight_truth):
    """The receiver's stated slow error (issue 11) counts in every live update as offline, and a
    bad one is refused naming its parameter before any stream is read."""
    from pitotcal.core.errors import PitotcalError

    flight, _ = flight_truth
    stated = {"gps_error_sigma_mps": 1.0, "gps_error_tau_s": 60.0}
    live = LiveIdentifier("inverse", air="incompressible", gps_error=stated).update(flight)
    offline = identify(flight, air="incompressible", **stated)
    plain = identify(flight, air="incompressible")
    np.testing.assert_allclose(live.std, offline.std, rtol=1e-4)
    assert live.std[2] > 1.1 * plain.std[2]            # the wind's bound grows
    with pytest.raises(PitotcalError, match="gps_error_sigma_mps"):
        LiveIdentifier("inverse", gps_error={"gps_error_sigma_mps": float("nan"),
                                             "gps_error_tau_s": 30.0})
