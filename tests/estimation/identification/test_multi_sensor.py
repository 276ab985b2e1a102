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


def test_windows_keep_one_shared_constant_wind_in_the_record(two):
    """Two calibration windows (`Flight.segment`): each sensor's own fit keeps a wind per
    window, the joint fit one wind; the record says the joint fit's wind, with no drift for
    the budget to take out of the flight."""
    import dataclasses

    fa, fb, truth = two
    fa, fb = (dataclasses.replace(f, segment=(f.time_s > 300.0).astype(int)) for f in (fa, fb))
    assert identify(fa, air="incompressible", budget=None).wind_model["kind"] != "constant"
    for res in identify_sensors([fa, fb], air="incompressible"):
        assert res.drift is None and res.wind_model["kind"] == "constant"
        assert res.wind_model["test"] is None
        assert res.wind_track["speed_mps"] == [res.value("wind_speed_mps")] * 2
        assert abs(res.value("wind_speed_mps") - truth["parameters"]["wind_speed_mps"]) \
            < 2.0 * res.stddev("wind_speed_mps")


def coverage(n_flights, **flight_kw):
    """(raw rms z of k1, k2 of both sensors and the wind; 2-sigma coverage of each; rms k1
    error joint and alone; median sigma(k1) joint / alone) over seeded two-sensor flights."""
    from pitotcal.estimation.identification.fit import fit

    z, err, ratio = [], [], []
    for seed in range(n_flights):
        fa, fb, truth = two_sensor_flights(seed=seed, **flight_kw)
        ra, rb = identify_sensors([fa, fb], air="incompressible")
        alone = fit(fa, air="incompressible")
        wind = [truth["wind_n_mps"], truth["wind_e_mps"]]

        def zs(r, k):
            return (r.internal_params - np.r_[k, wind]) / np.sqrt(np.diag(r.internal_covariance))

        z.append(np.r_[zs(ra, truth["k_a"]), zs(rb, truth["k_b"])[:2]])
        err.append([ra.internal_params[0] - truth["k_a"][0],
                    alone.internal_params[0] - truth["k_a"][0]])
        ratio.append(np.sqrt(ra.internal_covariance[0, 0] / alone.internal_covariance[0, 0]))
    z = np.array(z)
    return (np.sqrt(np.mean(z ** 2, axis=0)), np.mean(np.abs(z) < 2.0, axis=0),
            np.sqrt(np.mean(np.square(err), axis=0)), float(np.median(ratio)))


@pytest.mark.slow
@pytest.mark.parametrize("flight_kw", [
    {"turbulence_mps": 0.5},
    {"turbulence_mps": 1.0, "gps_rate_hz": 5.0, "gps_noise_mps": 0.1},
    {"turbulence_mps": 0.0},
])
def test_joint_bounds_cover_the_truth(flight_kw):
    """100 flights of 600 s at 10 Hz (docs/measured.md, two airspeed sensors)."""
    rms_z, covered, _, _ = coverage(100, n=6000, rate_hz=10.0, **flight_kw)
    assert np.all(rms_z < 1.15) and np.all(covered >= 0.9), (rms_z, covered)
