"""Legs from a flight time series: steady segments detected where the simulated legs were
flown, per-point, leg-level global and time-series fits within 3σ of the simulated truth, the
windows given by hand, and the refusals."""

import numpy as np
import pytest
from pitotcal.estimation.legs.flight import (
    analyze_leg_flight,
    detect_segments,
    legs_from_flight,
    parse_windows,
    read_windows,
)
from pitotcal.maneuvers.fly.legs import LEGS_TRUE_K, simulate_leg_flight

from pitotcal.core.errors import FlightDataError, PitotcalError


@pytest.fixture(scope="module")
def flown():
    """Four points (70-160 KIAS) × four headings, 60 s legs, 0.5 m/s gusts, 5 Hz."""
    return simulate_leg_flight(seed=3, rate_hz=5.0)


def test_detected_segments_are_the_flown_legs(flown):
    flight, _, windows = flown
    spans = detect_segments(flight)
    assert len(spans) == len(windows) == 16
    for (lo, hi), (t0, t1, _) in zip(spans, windows):
        assert t0 <= lo and hi <= t1                      # never into a turn
        assert hi - lo >= 0.85 * (t1 - t0) - 5.0          # and most of each leg
    legs, _ = legs_from_flight(flight, [(lo, hi, None) for lo, hi in spans])
    assert legs.point == tuple(w[2] for w in windows)     # grouped by IAS as flown


def test_every_fit_within_3_sigma_of_truth(flown):
    flight, truth, _ = flown
    res = analyze_leg_flight(flight)
    for s, tas, dv in zip(res["points"], truth.tas_mps, truth.dv_kt):
        assert s.method == "4-leg" and s.bound == "samples"      # nothing was stated
        assert abs(s.tas_mps - tas) < 1.5 * s.tas_half_mps             # 3σ
        assert abs(s.dv_kt - dv) < 1.5 * s.dv_half_kt
        assert np.hypot(s.wind_n_mps - truth.wind_n_mps, s.wind_e_mps - truth.wind_e_mps) < 0.5
    fit = res["fit"]
    z = (fit.coefficients - np.array(LEGS_TRUE_K)) / np.sqrt(np.diag(fit.coef_cov))
    assert fit.converged and np.all(np.abs(z) < 3)
    series = res["series"]
    z_series = (series.coefficients - np.array(LEGS_TRUE_K)) / series.std[:2]
    assert series.converged and np.all(np.abs(z_series) < 3)
    dv, half = series.delta_v_kt(truth.ias_kt)
    assert np.all(np.abs(dv - truth.dv_kt) < 1.5 * half)


def test_given_windows_keep_their_points(flown):
    flight, _, windows = flown
    relabelled = [(t0 + 5, t1 - 5, f"P{p}") for t0, t1, p in windows]
    res = analyze_leg_flight(flight, relabelled)
    assert res["detection"] == "windows"
    assert [s.point for s in res["points"]] == ["P1", "P2", "P3", "P4"]
    assert np.allclose(res["spans"], [(a, b) for a, b, _ in relabelled])


def test_ground_speed_sd_is_that_of_the_leg_mean(flown):
    """The stated groundspeed_sd_kt against the actual error of each leg's mean velocity."""
    flight, truth, windows = flown
    legs, _ = legs_from_flight(flight, [(t0 + 5, t1 - 5, p) for t0, t1, p in windows])
    heading = np.radians(np.tile([0, 90, 180, 270], 4))
    tas = np.repeat(truth.tas_mps, 4)
    true_g = np.column_stack([tas * np.cos(heading) + truth.wind_n_mps,
                              tas * np.sin(heading) + truth.wind_e_mps])
    z = (legs.velocity_ne_mps() - true_g) / legs.groundspeed_sd_mps[:, None]
    assert 0.6 < np.sqrt(np.mean(z ** 2)) < 1.5                        # 32 components


def test_north_east_south_legs_solved_without_a_time_series_fit():
    """Three legs N/E/S: each point solved; the time series turns only 180°, so identify
    refuses it and the result says why."""
    flight, _, _ = simulate_leg_flight(ias_kt=(80, 140), headings_deg=(0, 90, 180),
                                       rate_hz=2.0, seed=5)
    with pytest.warns(UserWarning, match="no time-series fit"):
        res = analyze_leg_flight(flight)
    assert [s.method for s in res["points"]] == ["3-leg", "3-leg"]
    assert res["series"] is None
    assert any(n.startswith("no time-series fit:") and "180" in n for n in res["notes"])


@pytest.mark.parametrize("text, match", [
    ("120-180,200", "'200' is not a window START-END"),
    ("180-120", "window 180-120: the end must come after the start"),
    ("a-b", "'a-b' is not a window"),
])
def test_bad_windows_named(text, match):
    with pytest.raises(PitotcalError, match=match):
        parse_windows(text)


def test_windows_csv(tmp_path):
    path = tmp_path / "w.csv"
    path.write_text("# legs\nstart_s,end_s,point\n10,70,A\n100,160,A\n")
    assert read_windows(path) == [(10.0, 70.0, "A"), (100.0, 160.0, "A")]
    path.write_text("start,end\n1,2\n")
    with pytest.raises(FlightDataError, match="missing column start_s"):
        read_windows(path)


def test_flight_without_static_pressure_refused(flown):
    from dataclasses import replace

    flight = replace(flown[0], ps_pa=None)
    with pytest.raises(FlightDataError, match="no ps_pa: the leg methods need"):
        analyze_leg_flight(flight)


def test_window_without_samples_refused(flown):
    with pytest.raises(FlightDataError, match="window 5000-5060 s holds 0 samples"):
        legs_from_flight(flown[0], [(5000.0, 5060.0, None)])


def test_detected_point_with_too_few_legs_left_out(flown):
    """A lone steady leg at another speed (here: the 160 KIAS point cut to two legs) is left
    out with a note instead of refusing the flight."""
    flight, _, windows = flown
    with pytest.warns(UserWarning, match="detected point 4 .160 KIAS. has 2 legs"):
        res = analyze_leg_flight(flight.window(None, windows[13][1] + 10.0))
    assert [s.point for s in res["points"]] == ["1", "2", "3"]
    assert res["notes"][0].startswith("detected point 4 (160 KIAS) has 2 legs (")
    assert len(res["spans"]) == 12


def test_no_steady_segment_says_what_to_do(flown):
    with pytest.raises(FlightDataError, match=r"no steady segment of 500 s or more \(track ±3°"):
        analyze_leg_flight(flown[0], min_leg_s=500.0)


@pytest.mark.filterwarnings("ignore:time-series fit")
def test_two_altitude_bands_warn_that_the_time_series_has_one_wind():
    from dataclasses import replace

    low, _, _ = simulate_leg_flight(ias_kt=(80, 140), rate_hz=1.0, seed=8)
    high, _, _ = simulate_leg_flight(ias_kt=(90, 150), pressure_alt_ft=8000.0, rate_hz=1.0,
                                     seed=9)
    fields = ("qci_pa", "gps_vn_mps", "gps_ve_mps", "rho_kgm3", "alt_m", "ps_pa", "oat_k")
    both = replace(low, time_s=np.r_[low.time_s, high.time_s + low.time_s[-1] + 60.0],
                   **{f: np.r_[getattr(low, f), getattr(high, f)] for f in fields})
    with pytest.warns(UserWarning, match="one wind for the record, but the legs span 2 altitude bands"):
        res = analyze_leg_flight(both)
    assert len(res["points"]) == 4 and len(res["fit"].group_labels) == 2
    assert res["leg_sd_own_mps"].shape == (16,)
    assert np.ptp(res["legs"].groundspeed_sd_mps) == 0.0         # pooled
