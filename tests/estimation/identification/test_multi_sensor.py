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


def test_windows_share_the_first_sensors_wind_model_in_the_record(two):
    """Two calibration windows (`Flight.segment`) of one wind: the first sensor's wind model
    (a wind per window, or a drift in each) is every sensor's, with its drift for the budget
    to take out of the flight, and the mean wind within its bounds."""
    import dataclasses

    fa, fb, truth = two
    fa, fb = (dataclasses.replace(f, segment=(f.time_s > 300.0).astype(int)) for f in (fa, fb))
    alone = identify(fa, air="incompressible", budget=None)
    assert alone.wind_model["kind"] != "constant"
    results = identify_sensors([fa, fb], air="incompressible")
    for res in results:
        assert res.drift is not None and res.wind_model["kind"] == alone.wind_model["kind"]
        assert res.wind_model["shared_by_sensors"] == 2
        assert res.wind_track["segment"][0] == 0 and res.wind_track["segment"][-1] == 1
        assert abs(res.value("wind_speed_mps") - truth["parameters"]["wind_speed_mps"]) \
            < 2.0 * res.stddev("wind_speed_mps")
    assert np.array_equal(results[0].drift[1], results[1].drift[1])
    assert results[0].wind_track == results[1].wind_track


def _window_winds(res):
    """The wind (north, east) of each window of the result's track, at its middle point."""
    track = res.wind_track
    seg = np.asarray(track["segment"])
    out = []
    for s in (0, 1):
        i = np.flatnonzero(seg == s)[len(np.flatnonzero(seg == s)) // 2]
        speed, frm = track["speed_mps"][i], np.radians(track["from_deg"][i])
        out.append((-speed * np.cos(frm), -speed * np.sin(frm), track["speed_2sigma_mps"][i]))
    return out


def test_two_windows_with_different_winds_keep_each_windows_wind():
    """Two windows 600 s apart, 5 m/s from 270° and 8 m/s from 300°, two sensors in 0.3 m/s
    turbulence: both calibrations within 2σ, each window's wind recovered within its 2σ (a
    single wind for both windows cannot: they are 4.4 m/s apart)."""
    from synthetic import two_window_sensor_flights

    fa, fb, truth = two_window_sensor_flights(seed=2, n=3000, rate_hz=10.0,
                                              turbulence_mps=0.3)
    results = identify_sensors([fa, fb], air="incompressible", wind="constant")
    for res, k in zip(results, (truth["k_a"], truth["k_b"])):
        assert res.converged and res.wind_model["kind"] == "constant per window"
        for name, true in zip(("k1", "k2"), k):
            assert abs(res.value(name) - true) < 2.0 * res.stddev(name), name
        for (wn, we, two_sigma), (tn, te) in zip(_window_winds(res), truth["windows"]):
            assert np.hypot(wn - tn, we - te) < max(two_sigma, 0.1)
    assert "one shared wind model (constant per window)" in results[1].warnings[-1]


def test_a_drifting_wind_is_shared_by_the_sensors():
    """900 s, the wind drifting 2.5 m/s in speed and 40° in direction (4.9 m/s of the vector;
    6 m/s from 280° in the middle): the first sensor's
    drift is every sensor's, fitted with all their residuals; both calibrations within 2σ."""
    from synthetic import two_sensor_flights, wind_vector

    w0, w1 = np.array(wind_vector(5.0, 260.0)), np.array(wind_vector(7.5, 300.0))
    fa, fb, truth = two_sensor_flights(seed=4, n=9000, rate_hz=10.0, turbulence_mps=0.3,
                                       wind_speed_mps=6.0, wind_from_deg=280.0,
                                       wind_drift_mps2=tuple((w1 - w0) / 900.0), turns=8.0)
    results = identify_sensors([fa, fb], air="incompressible", wind="drifting")
    for res, k in zip(results, (truth["k_a"], truth["k_b"])):
        assert res.converged and res.wind_model["kind"] == "drifting"
        assert res.drift is not None and res.wind_model["chosen_by"] == "option"
        for name, true in zip(("k1", "k2"), k):
            assert abs(res.value(name) - true) < 2.0 * res.stddev(name), name
        speed = np.asarray(res.wind_track["speed_mps"])
        assert speed[-1] - speed[0] > 1.5          # the drift is in the track


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
