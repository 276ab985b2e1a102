"""A log's further airspeed sensors keep the first sensor's calibration windows."""

import numpy as np

from pitotcal.core.flight import Flight
from pitotcal.io.sensors import in_windows


def _flight(n=100):
    t = np.arange(n, dtype=float)
    ones = np.ones(n)
    return Flight(time_s=t, qci_pa=300.0 * ones, gps_vn_mps=20.0 * ones, gps_ve_mps=0 * ones,
                  rho_kgm3=1.2 * ones)


def test_samples_outside_the_windows_are_left_out_and_each_window_is_a_segment():
    windows = [{"start_s": 10.0, "end_s": 29.0}, {"start_s": 60.0, "end_s": 69.0}]
    got = in_windows(_flight(), windows)
    assert got.n == 30
    assert got.time_s[0] == 10.0 and got.time_s[-1] == 69.0
    assert np.array_equal(np.unique(got.segment), [0, 1])
    assert (got.segment[got.time_s < 30] == 0).all() and (got.segment[got.time_s > 50] == 1).all()


def test_one_window_has_no_segments_and_no_windows_keeps_the_flight():
    one = in_windows(_flight(), [{"start_s": 5.0, "end_s": 14.0}])
    assert one.n == 10 and one.segment is None
    flight = _flight()
    assert in_windows(flight, None) is flight
