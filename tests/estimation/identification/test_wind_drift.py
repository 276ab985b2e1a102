"""The drifting wind (estimation.identification.wind_drift): its basis, its choice by the data,
its recovery of known truth on simulated 15-minute flights, the record and the options."""

import json

import numpy as np
import pytest
from driftflights import WIND_END, WIND_START, loiter_flight, scored, true_wind_mps
from plans import circle_plan

from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import wind_vector_mps
from pitotcal.estimation import identify
from pitotcal.estimation.identification.wind_drift import drift_basis
from pitotcal.maneuvers import simulate


def test_basis_is_centred_and_holds_a_linear_drift():
    t = np.linspace(0.0, 900.0, 9001)
    basis = drift_basis(t, None, 300.0)
    b = basis.rows(t)
    assert b.shape == (t.size, 3)                       # 4 knots, one dropped by centring
    np.testing.assert_allclose(b.mean(axis=0), 0.0, atol=1e-12)
    ramp = 0.01 * (t - t.mean())
    coef = np.linalg.lstsq(b, ramp, rcond=None)[0]
    np.testing.assert_allclose(b @ coef, ramp, atol=1e-9)


def test_each_window_keeps_a_wind_of_its_own():
    t = np.concatenate([np.linspace(0.0, 300.0, 301), np.linspace(1000.0, 1300.0, 301)])
    seg = np.repeat([0, 1], 301)
    b = drift_basis(t, seg, 300.0).rows(t, seg)
    step = np.where(seg == 1, 1.0, -1.0)               # one constant offset per window
    coef = np.linalg.lstsq(b, step, rcond=None)[0]
    np.testing.assert_allclose(b @ coef, step, atol=1e-9)


@pytest.fixture(scope="module")
def drifting():
    import dataclasses

    flight, truth = loiter_flight(seed=1)
    flight = dataclasses.replace(flight, source="loiter.csv")
    return flight, truth, identify(flight)


def test_drift_is_chosen_warned_and_recovered(drifting):
    """Measured, seed 1: max|ΔV error| 0.37 kt inside its 2σ of 0.42 kt (the constant-wind fit
    of the same flight: 1.08 kt); the wind track within 2σ of the true drifting wind."""
    flight, truth, result = drifting
    assert result.wind_model["kind"] == "drifting"
    assert result.wind_model["test"]["p_value"] < 1e-6
    note = [w for w in result.warnings if "the wind drifted" in w]
    assert len(note) == 1 and "fitted as a drifting wind" in note[0]
    assert note[0].startswith("loiter.csv: the wind drifted")      # the flight's name
    true_k = [truth.parameters[p] for p in ("k1", "k2")]
    z = (result.coefficients - true_k) / np.sqrt(np.diag(result.internal_covariance)[:2])
    assert np.all(np.abs(z) < 2.5), z
    track = result.wind_track
    wn, we = true_wind_mps(truth, track["time_s"])
    speed = np.hypot(wn, we)
    assert np.all(np.abs(np.array(track["speed_mps"]) - speed)
                  < 1.5 * np.array(track["speed_2sigma_mps"]) + 0.2)
    start, end = (np.hypot(*wind_vector_mps(*w)) for w in (WIND_START, WIND_END))
    assert track["speed_mps"][0] == pytest.approx(start, abs=1.0)
    assert track["speed_mps"][-1] == pytest.approx(end, abs=1.0)
    assert track["from_deg"][-1] - track["from_deg"][0] == pytest.approx(40.0, abs=8.0)


def test_drift_beats_the_constant_wind_on_a_drifting_flight(drifting):
    flight, truth, result = drifting
    from pitotcal.studies.engine.common import score

    constant = identify(flight, wind="constant")
    assert constant.wind_model == {"kind": "constant", "knot_s": None, "test": None,
                                   "chosen_by": "option"}
    err_drift = score(result, truth, flight)["dv_err_max_kt"]
    err_const = score(constant, truth, flight)["dv_err_max_kt"]
    assert err_drift < 0.5 < err_const


def test_record_carries_the_wind_model_and_track(drifting):
    _, _, result = drifting
    rec = json.loads(json.dumps(result.to_dict()))
    assert rec["wind_model"]["kind"] == "drifting" and rec["wind_model"]["knot_s"] == 300.0
    track = rec["wind_track"]
    assert set(track) == {"time_s", "speed_mps", "from_deg", "speed_2sigma_mps",
                          "from_2sigma_deg"}
    assert len(track["time_s"]) == 19 and track["time_s"][-1] == pytest.approx(900.0)
    assert "wind_speed_mps" in rec["parameters"]       # the mean wind stays where it was
    assert "wind drifting" in result.summary()


def test_two_windows_share_the_calibration_and_keep_their_own_wind():
    """The loiter cut into two windows (`Flight.segment`), 120 s apart: a linear drift in
    each, the track per window within its 2σ of the true wind (measured, seed 2: 0.11-0.17 m/s
    low against 2σ of 0.38-0.73 m/s)."""
    import dataclasses

    flight, truth = loiter_flight(seed=2)
    two = flight.select((flight.time_s < 400.0) | (flight.time_s > 520.0))
    two = dataclasses.replace(two, segment=(two.time_s > 520.0).astype(int))
    result = identify(two)
    track = result.wind_track
    assert result.wind_model["kind"] == "drifting"
    assert sorted(set(track["segment"])) == [0, 1]
    assert not any(400.0 < t < 520.0 for t in track["time_s"])
    wn, we = true_wind_mps(truth, track["time_s"])
    assert np.all(np.abs(np.array(track["speed_mps"]) - np.hypot(wn, we))
                  < np.array(track["speed_2sigma_mps"]))


@pytest.mark.parametrize("seed", [0, 1])
def test_constant_wind_flights_keep_a_constant_wind(seed):
    """Default demo flights (240 s, 0.5 m/s turbulence): constant chosen, record unchanged."""
    from pitotcal.maneuvers import plan_maneuver

    flight, _ = simulate(plan_maneuver(), seed=seed)
    auto = identify(flight)
    constant = identify(flight, wind="constant")
    assert auto.wind_model["kind"] == "constant"
    assert auto.wind_model["test"]["p_value"] > 0.01
    np.testing.assert_array_equal(auto.params, constant.params)
    np.testing.assert_array_equal(auto.covariance, constant.covariance)
    assert len(auto.wind_track["time_s"]) == 2


@pytest.mark.parametrize("options, match", [
    ({"wind": "gusty"}, "wind 'gusty' is not one of auto, constant, drifting"),
    ({"wind_knot_s": 5.0}, "wind_knot_s"),
    ({"wind_knot_s": float("nan")}, "wind_knot_s"),
])
def test_bad_wind_options_name_the_argument(options, match):
    flight, _ = simulate(circle_plan(duration_s=60.0), seed=0, rate_hz=5.0)
    with pytest.raises(PitotcalError, match=match):
        identify(flight, **options)


@pytest.mark.slow
def test_drifting_flights_error_and_coverage():
    """100 simulated 15-minute flights, wind drifting 9 -> 11 m/s and 270 -> 310 deg, 0.5 m/s
    turbulence, GPS noise 0.1 m/s (docs/measured.md, "Drifting wind")."""
    rows = [scored(seed) for seed in range(100)]
    assert sum(r["kind"] == "drifting" for r in rows) >= 98
    assert np.median([r["dv_err_max_kt"] for r in rows]) < 0.35
    assert sum(r["covered"] for r in rows) >= 80


@pytest.mark.slow
def test_constant_wind_is_chosen_on_constant_wind_flights():
    """60 default demo flights and 40 of the 15-minute loiter in its mean wind."""
    from pitotcal.maneuvers import plan_maneuver

    plan = plan_maneuver()
    kinds = [identify(simulate(plan, seed=seed)[0]).wind_model["kind"] for seed in range(60)]
    kinds += [scored(seed, drifting=False)["kind"] for seed in range(40)]
    assert kinds.count("constant") >= 90


@pytest.mark.parametrize("dof", [2, 4, 6, 10])
def test_wald_p_value_is_the_chi_square_tail(dof):
    from scipy.stats import chi2

    from pitotcal.estimation.identification.wind_drift import wald_test

    for stat in (0.5, 3.0, 12.0, 60.0):
        d = np.zeros(dof)
        d[0] = np.sqrt(stat)
        got = wald_test(d, np.eye(dof))
        assert got["statistic"] == pytest.approx(stat)
        assert got["p_value"] == pytest.approx(chi2.sf(stat, dof), rel=1e-10)


def test_windows_keep_their_own_wind_with_a_constant_wind_in_each():
    """Two windows 600 s apart, each a constant wind of its own (5 m/s from 270°, 8 m/s from
    200°): with `wind="constant"` each window gets its wind, the calibration is shared."""
    import dataclasses

    from synthetic import synthetic_flight

    from pitotcal.core.flight import Flight

    one, truth = synthetic_flight(seed=3, n=8000, turbulence_mps=0.3, gps_noise_mps=0.05)
    two, _ = synthetic_flight(seed=4, n=8000, wind_speed_mps=8.0, wind_from_deg=200.0,
                              turbulence_mps=0.3, gps_noise_mps=0.05)
    two = dataclasses.replace(two, time_s=two.time_s + one.time_s[-1] + 600.0)
    both = Flight(**{name: np.concatenate([getattr(one, name), getattr(two, name)])
                     for name in ("time_s", "qci_pa", "gps_vn_mps", "gps_ve_mps", "rho_kgm3")},
                  segment=np.repeat([0, 1], [one.n, two.n]))
    result = identify(both, air="incompressible", wind="constant")
    assert result.wind_model["kind"] == "constant per window"
    track = result.wind_track
    assert track["segment"] == [0, 1]
    for speed, from_deg, got, u in zip((5.0, 8.0), (270.0, 200.0), zip(
            track["speed_mps"], track["from_deg"]), track["speed_2sigma_mps"]):
        assert abs(got[0] - speed) < max(1.5 * u, 0.1) and abs(got[1] - from_deg) < 2.0
    k1, k2 = truth["k"]
    assert abs(result.params[0] - k1) < 3 * result.stddev("k1")
    assert abs(result.params[1] - k2) < 3 * result.stddev("k2")
    assert "wind per calibration window" in result.summary()


def test_a_flight_cut_to_some_windows_keeps_their_numbers():
    """Windows 1 and 3 of three (`Flight.segment` 1 and 3, none 0 or 2), each a constant wind
    of its own (5 m/s from 270°, 8 m/s from 200°): one wind per window present, the track
    under their own numbers; window 3 alone is one window (a constant wind)."""
    import dataclasses

    from synthetic import synthetic_flight

    from pitotcal.core.flight import Flight

    one, truth = synthetic_flight(seed=3, n=4000, gps_noise_mps=0.05)
    two, _ = synthetic_flight(seed=4, n=4000, wind_speed_mps=8.0, wind_from_deg=200.0,
                              gps_noise_mps=0.05)
    two = dataclasses.replace(two, time_s=two.time_s + one.time_s[-1] + 600.0)
    both = Flight(**{name: np.concatenate([getattr(one, name), getattr(two, name)])
                     for name in ("time_s", "qci_pa", "gps_vn_mps", "gps_ve_mps", "rho_kgm3")},
                  segment=np.repeat([1, 3], [one.n, two.n]))
    result = identify(both, air="incompressible", wind="constant", budget=None)
    track = result.wind_track
    assert result.wind_model["kind"] == "constant per window" and track["segment"] == [1, 3]
    for speed, got, u in zip((5.0, 8.0), track["speed_mps"], track["speed_2sigma_mps"]):
        assert abs(got - speed) < max(1.5 * u, 0.1)
    assert abs(result.params[0] - truth["k"][0]) < 3 * result.stddev("k1")
    last = identify(both.select(both.segment == 3), air="incompressible", budget=None)
    assert last.wind_model["kind"] == "constant"
    assert abs(last.value("wind_speed_mps") - 8.0) < 0.1
