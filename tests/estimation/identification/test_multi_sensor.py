"""Two airspeed sensors, one shared wind (estimation.identification.multi_sensor): seeded
simulated flights with two known calibrations, recovered within their bounds."""

import numpy as np
import pytest
from synthetic import synthetic_flight, two_sensor_flights

from pitotcal.core.errors import PitotcalError
from pitotcal.estimation import identify
from pitotcal.estimation.identification.multi_sensor import identify_sensors


@pytest.fixture(scope="module")
def two():
    """600 s at 10 Hz in 0.5 m/s turbulence; sensor a k = (0.02, -15), b = (-0.03, 10)."""
    return two_sensor_flights(seed=11, n=6000, rate_hz=10.0, turbulence_mps=0.5)


def test_both_calibrations_within_their_bounds_and_one_wind(two):
    fa, fb, truth = two
    ra, rb = identify_sensors([fa, fb], air="incompressible")
    for res, k in ((ra, truth["k_a"]), (rb, truth["k_b"])):
        assert res.converged
        for name, true in zip(("k1", "k2"), k):
            assert abs(res.value(name) - true) < 2.0 * res.stddev(name), name
        assert "fitted jointly with the other sensors" in res.warnings[-1]
    # one wind: the same numbers in both results, the truth inside its bounds
    tw = truth["parameters"]
    for name in ("wind_speed_mps", "wind_from_deg"):
        assert ra.value(name) == rb.value(name)
        assert abs(ra.value(name) - tw[name]) < 2.0 * ra.stddev(name)
    # the common turbulence limits both: bounds of the size of the sensor's fit alone
    alone = identify(fa, air="incompressible")
    assert 0.7 < ra.stddev("k1") / alone.stddev("k1") < 1.5


def test_one_flight_is_refused():
    flight, _ = synthetic_flight(seed=1, n=2000, rate_hz=10.0)
    with pytest.raises(PitotcalError, match="`flights`: 1 given"):
        identify_sensors([flight])


def test_sensors_on_shifted_time_bases(two):
    """The second sensor sampled 30 ms after the first: the score still adds per time step."""
    import dataclasses

    fa, fb, truth = two
    shifted = dataclasses.replace(fb, time_s=fb.time_s + 0.03)
    ra, rb = identify_sensors([fa, shifted], air="incompressible")
    for name, true in zip(("k1", "k2"), truth["k_b"]):
        assert abs(rb.value(name) - true) < 2.0 * rb.stddev(name)
    assert np.isfinite(ra.covariance).all()
