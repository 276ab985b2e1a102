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


def test_samples_the_first_sensor_cut_inside_a_window_go_too():
    """The first sensor (1 Hz) cut 40-49 s inside its window 30-79 s (a steep turn); a second
    sensor at 4 Hz, 0.1 s later, keeps 30-39 s and 50-79 s, nothing of the cut but its edge."""
    first = _flight()
    first = first.select((first.time_s >= 30) & (first.time_s <= 79)
                         & ((first.time_s < 40) | (first.time_s > 49)))
    other = _flight(400)
    other = Flight(time_s=other.time_s / 4.0 + 0.1, qci_pa=other.qci_pa,
                   gps_vn_mps=other.gps_vn_mps, gps_ve_mps=other.gps_ve_mps,
                   rho_kgm3=other.rho_kgm3)
    got = in_windows(other, [{"start_s": 30.0, "end_s": 79.0}], first=first)
    assert not np.any((got.time_s > 40.0) & (got.time_s < 49.0))
    assert np.any((got.time_s > 34.0) & (got.time_s < 36.0)) and got.time_s[-1] == 78.85
    assert got.n == 40 + 120         # 30.1-39.85 s and 49.1-78.85 s (within 1 s of 50 s)
