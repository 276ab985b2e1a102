"""The everyday 15-minute flight: seeded, flown as planned, in the wind it was given."""

import numpy as np
import pytest

from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import mps_to_kt, wind_polar
from pitotcal.maneuvers.fly.everyday import (
    DRIFTING_WIND,
    EVERYDAY_FLIGHT,
    everyday_flight,
    everyday_plan,
    wind_at,
)


@pytest.fixture(scope="module")
def drifting():
    return everyday_flight(seed=4, drifting=True)


def test_the_flight_is_fifteen_minutes_at_ten_hertz_over_the_envelope(drifting):
    flight, truth = drifting
    assert flight.n == 9001 and flight.time_s[-1] == pytest.approx(900.0)
    cas_kt = mps_to_kt(np.asarray(truth.history["cas_mps"]))
    assert np.percentile(cas_kt, 2) < 73 and np.percentile(cas_kt, 98) > 97
    assert truth.tracking.max_path_error_m < 30 and truth.tracking.max_bank_deg <= 30.0 + 1e-9


def test_the_wind_drifts_from_start_to_end(drifting):
    """The flown wind, averaged over the first and last 30 s, is the stated start and end
    (within the gusts' average, 0.5 m/s turbulence), 3 m/s and 40° apart."""
    _, truth = drifting
    h = truth.history
    t, wn, we = (np.asarray(h[k]) for k in ("time_s", "wind_n_mps", "wind_e_mps"))
    for when, (speed, from_deg) in ((t < 30, DRIFTING_WIND["start"]),
                                    (t > 870, DRIFTING_WIND["end"])):
        got_speed, got_from = wind_polar(wn[when].mean(), we[when].mean())
        assert abs(got_speed - speed) < 0.5 and abs(got_from - from_deg) < 4.0
    assert np.allclose(wind_at(np.array([0.0, 900.0])),
                       np.array([[0.0, -7.7135], [9.0, 9.1925]]), atol=1e-3)


def test_the_same_seed_flies_the_same_flight_and_another_differs():
    a, b, c = everyday_plan(5), everyday_plan(5), everyday_plan(6)
    assert np.array_equal(a.north_m, b.north_m) and np.array_equal(a.tas_mps, b.tas_mps)
    assert not np.array_equal(a.tas_mps, c.tas_mps)
    # every heading is flown: the pattern turns through 360° several times
    assert np.ptp(a.heading_deg) > 3 * 360


def test_a_bad_setting_is_refused_by_name():
    with pytest.raises(PitotcalError, match="radius_m"):
        everyday_plan(0, radius_m=-1.0)
    with pytest.raises(PitotcalError, match="unknown everyday-flight setting 'radius'"):
        everyday_plan(0, radius=800.0)
    assert set(EVERYDAY_FLIGHT) >= {"duration_s", "cas_min_kt", "cas_max_kt", "radius_m"}
