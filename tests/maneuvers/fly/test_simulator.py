"""Flight simulator: determinism, truth, tracking, sensors, and identification back to truth.

The command (`pitotcal simulate`) is tested in tests/cli/test_simulate.py."""

import dataclasses
import json

import numpy as np
import pytest
from pitotcal.maneuvers.fly.sensors import first_order_lag, gps_velocity_sensor, impact_pressure_sensor
from pitotcal.maneuvers.fly.simulator import References, references, simulate
from pitotcal.maneuvers.fly.truth import tracking_warnings, truth_path_for, write_truth_json
from plans import circle_plan

from pitotcal.core.errors import PitotcalError
from pitotcal.core.scenario import true_k
from pitotcal.core.units import isa_density_kgm3, mps_to_kt


@pytest.fixture(scope="module")
def plan():
    return circle_plan()


@pytest.fixture(scope="module")
def flown(plan):
    return simulate(plan, seed=11, keep_history=True)


# --- determinism and output ------------------------------------------------------------------

def test_same_seed_same_flight_other_seed_differs(plan):
    a, ta = simulate(plan, seed=5)
    b, tb = simulate(plan, seed=5)
    c, _ = simulate(plan, seed=6)
    for name in ("time_s", "qci_pa", "gps_vn_mps", "gps_ve_mps", "gps_vd_mps", "rho_kgm3"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert ta == tb
    assert not np.array_equal(a.qci_pa, c.qci_pa)


def test_flight_columns_rate_and_density(plan, flown):
    flight, truth = flown
    assert flight.n == 240 * 50 + 1
    np.testing.assert_allclose(np.diff(flight.time_s), 0.02)
    np.testing.assert_allclose(flight.rho_kgm3, isa_density_kgm3(244.0), rtol=1e-6)
    np.testing.assert_allclose(flight.alt_m, 244.0, atol=0.5)
    assert truth.seed == 11 and truth.model == "inverse"
    assert set(truth.options) >= {"turbulence_mps", "gps_rate_hz", "qc_noise_pa", "k",
                                     "wind_drift_mps2", "gps_latency_s", "pneumatic_lag_s"}


# --- truth -------------------------------------------------------------------------------------

def test_truth_wind_is_time_average_of_wind_flown(flown):
    flight, truth = flown
    h = truth.history
    # Reconstruct the wind from the true ground velocity minus the air velocity.
    wn = h["gps_true_mps"][:, 0] - h["tas_mps"] * np.cos(h["heading_rad"])
    we = h["gps_true_mps"][:, 1] - h["tas_mps"] * np.sin(h["heading_rad"])
    assert truth.wind_n_mps == pytest.approx(wn.mean(), abs=1e-9)
    assert truth.wind_e_mps == pytest.approx(we.mean(), abs=1e-9)
    speed = np.hypot(wn.mean(), we.mean())
    assert truth.parameters["wind_speed_mps"] == pytest.approx(speed, abs=1e-9)
    assert truth.parameters["wind_from_deg"] == pytest.approx(
        np.degrees(np.arctan2(-we.mean(), -wn.mean())) % 360, abs=1e-7)
    # turbulence makes it differ from the process mean, which is kept separately
    assert truth.wind_mean_process == {"speed_mps": 5.0, "from_deg": 270.0,
                                          "drift_mps2": [0.0, 0.0]}
    assert truth.parameters["wind_speed_mps"] != 5.0
    assert abs(truth.parameters["wind_speed_mps"] - 5.0) < 0.5


def test_wind_overrides_and_drift_about_the_middle(plan):
    _, truth = simulate(plan, seed=2, turbulence_mps=0.0, wind_speed_mps=8.0, wind_from_deg=45.0,
                        wind_drift_mps2=(0.004, -0.002), keep_history=True)
    assert truth.parameters["wind_speed_mps"] == pytest.approx(8.0, abs=1e-6)
    assert truth.parameters["wind_from_deg"] == pytest.approx(45.0, abs=1e-6)
    wn = truth.history["wind_n_mps"]
    assert wn[-1] - wn[0] == pytest.approx(0.004 * 240.0, rel=1e-6)


def test_write_truth_json_beside_flight(tmp_path, flown):
    _, truth = flown
    path = write_truth_json(truth, tmp_path / "f.csv")
    assert path == tmp_path / "f.truth.json" == truth_path_for(tmp_path / "f.csv")
    data = json.loads(path.read_text())
    assert "history" not in data
    assert data["parameters"]["k1"] == 0.02 and data["parameters"]["k2"] == -15.0
    assert write_truth_json(truth, tmp_path / "t.json") == tmp_path / "t.json"


# --- tracking ----------------------------------------------------------------------------------

def test_tracking_radius_bank_roll_rate_altitude_and_cas(plan, flown):
    _, truth = flown
    h = truth.history
    radius = np.hypot(h["north_m"], h["east_m"])
    assert radius.max() < plan.settings["radius_m"] * 1.05
    assert np.degrees(np.abs(h["bank_rad"])).max() <= 30.0 + 1e-9
    roll_rate = np.degrees(np.abs(np.diff(h["bank_rad"]))) / 0.02
    assert roll_rate.max() <= 10.0 + 1e-6
    assert np.abs(h["alt_m"] - 244.0).max() < 15.24
    cas_err = mps_to_kt(h["cas_mps"] - h["cas_ref_mps"])
    assert np.abs(cas_err).max() < 5.0
    assert truth.tracking.max_cas_error_kt == pytest.approx(np.abs(cas_err).max())


def test_wrong_wind_still_tracked_approximately(plan):
    # the plan was made for 5 m/s from 270; fly it in 8 m/s from 200
    _, truth = simulate(plan, seed=3, wind_speed_mps=8.0, wind_from_deg=200.0)
    assert truth.tracking.max_radius_m < plan.settings["radius_m"] * 1.15
    assert truth.tracking.max_cas_error_kt < 5.0


# --- sensors -----------------------------------------------------------------------------------

def test_quantization_step_visible(plan):
    flight, _ = simulate(plan, seed=1, qc_quantization_pa=2.0)
    steps = flight.qci_pa / 2.0
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-6)
    assert np.min(np.abs(np.diff(flight.qci_pa))[np.diff(flight.qci_pa) != 0]) == pytest.approx(2.0)


def test_pneumatic_lag_delays_a_ramp_by_tau():
    dt, tau = 0.02, 0.5
    t = np.arange(0, 20, dt)
    y = first_order_lag(100.0 + 3.0 * t, dt, tau)
    assert y[0] == 100.0                                  # starts settled
    late = t > 10 * tau
    # delay tau to within one sample (the filter uses the current input: tau - dt/2)
    np.testing.assert_allclose(y[late], 100.0 + 3.0 * (t[late] - tau), atol=3.0 * dt)
    step = first_order_lag(np.r_[0.0, np.ones(t.size - 1)], dt, tau)
    assert step[int(round(tau / dt))] == pytest.approx(1 - np.exp(-1), abs=0.02)


def test_lag_in_simulated_flight_shows_as_delay(plan):
    quiet = dict(turbulence_mps=0.0, qc_noise_pa=0.0, gps_noise_mps=0.0)
    a, _ = simulate(plan, seed=1, **quiet)
    b, _ = simulate(plan, seed=1, pneumatic_lag_s=1.0, **quiet)
    # on the slow ramp the lagged reading equals the unlagged one 1 s earlier
    lagged, ref = b.qci_pa[1000:], a.qci_pa[1000 - 50:-50]
    assert np.abs(lagged - ref).max() < 0.3
    assert np.abs(b.qci_pa[1000:] - a.qci_pa[1000:]).max() > 2.0


def test_scale_error_and_bias():
    qc = np.linspace(800.0, 1600.0, 100)
    rng = np.random.default_rng(0)
    base = impact_pressure_sensor(qc, 0.02, rng, model="constant", k=(0.02,))
    np.testing.assert_allclose(base, 0.98 * qc)
    got = impact_pressure_sensor(qc, 0.02, rng, model="constant", k=(0.02,), scale_error=0.01,
                                 bias_pa=3.0)
    np.testing.assert_allclose(got, 1.01 * 0.98 * qc + 3.0)


def test_gps_sample_and_hold_at_5_hz(flown):
    flight, _ = flown
    changes = np.flatnonzero(np.diff(flight.gps_vn_mps) != 0) + 1
    assert changes.size > 1000
    assert np.all(changes % 10 == 0)                      # 50 Hz / 5 Hz: new value every 10
    assert np.all(np.diff(changes) == 10)


def test_gps_latency_shifts_velocity():
    t = np.arange(0, 10, 0.02)
    v = np.column_stack([np.sin(t), np.cos(t)])
    out = gps_velocity_sensor(t, v, np.random.default_rng(0), rate_hz=0, noise_mps=0.0,
                              latency_s=0.3)
    np.testing.assert_allclose(out[15:], v[:-15], atol=1e-12)
    np.testing.assert_allclose(out[:15], np.tile(v[0], (15, 1)))


def test_gps_noise_level():
    t = np.arange(0, 200, 0.02)
    out = gps_velocity_sensor(t, np.zeros((t.size, 3)), np.random.default_rng(0), rate_hz=5.0,
                              noise_mps=0.1)
    updates = out[::10]
    assert updates.std() == pytest.approx(0.1, rel=0.05)


# --- argument errors ---------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, match", [
    ({"model": "cubic"}, "model 'cubic' is not one of"),
    ({"k": (0.02,)}, "k needs 2 coefficients"),
    ({"rate_hz": 0.0}, "rate_hz 0 must be > 0"),
    ({"turbulence_mps": -1.0}, "turbulence_mps -1 must be >= 0"),
    ({"wind_speed_mps": float("nan")}, "wind_speed_mps nan must be a finite number"),
    ({"wind_drift_mps2": (0.0,)}, "wind_drift_mps2 must be"),
    ({"wind_drift_mps2": (0.0, float("inf"))}, "wind_drift_e_mps2 inf must be a finite"),
    ({"gps_noise_mps": -0.1}, "gps_noise_mps -0.1 must be >= 0"),
    ({"seed": -3}, "seed -3 must be >= 0"),
    ({"seed": 1.5}, "seed 1.5 must be a whole number"),
    ({"turbulence_length_m": 0.0}, "turbulence_length_m 0 must be > 0"),
    # item 7 of issue 8: 400 was silently flown as 040°
    ({"wind_from_deg": 400.0}, r"wind_from_deg 400 must be >= 0 and < 360"),
    ({"wind_from_deg": -90.0}, r"wind_from_deg -90 must be >= 0 and < 360"),
])
def test_bad_arguments_refused(plan, kwargs, match):
    with pytest.raises(ValueError, match=match) as info:
        simulate(plan, **kwargs)
    if isinstance(info.value, PitotcalError):
        # the parameter travels with the error, for the command line to name its flag
        assert info.value.param == match.split()[0]


def test_not_a_plan_refused():
    with pytest.raises(PitotcalError, match=r"plan must be a pitotcal.core.plan.Plan "
                                            r"\(pitotcal.read_plan reads one\)"):
        simulate({"time_s": [0, 1]})


# --- the default plan identified back to truth ----------------------------------------------------

@pytest.mark.parametrize("profile", ["continuous", "step-pause", "two-speed"])
def test_default_plan_identified_back_within_3_sigma(profile):
    from pitotcal.estimation import identify
    from pitotcal.maneuvers.plan.planner import plan_maneuver

    plan = plan_maneuver(profile=profile)
    flight, truth = simulate(plan, seed=0)
    assert truth.tracking.max_cas_error_kt < 5.0
    result = identify(flight, "inverse")
    true = truth.parameters
    for i, name in enumerate(("k1", "k2", "wind_speed_mps", "wind_from_deg")):
        z = (result.params[i] - true[name]) / result.std[i]
        assert abs(z) < 3.0, f"{profile}: {name} {result.params[i]:.4g} vs {true[name]:.4g}, z={z:.2f}"


@pytest.mark.slow
def test_monte_carlo_default_plan_tracking_and_coverage():
    """20 seeds: always within +-5 KCAS and near the circle; truth inside 3 sigma >= 90 %."""
    from pitotcal.estimation import identify
    from pitotcal.maneuvers.plan.planner import plan_maneuver

    plan = plan_maneuver()
    inside, total = 0, 0
    for seed in range(20):
        flight, truth = simulate(plan, seed=seed)
        assert truth.tracking.max_cas_error_kt < 5.0
        assert truth.tracking.max_radius_m < plan.settings["radius_m"] * 1.03
        result = identify(flight, "inverse")
        true = truth.parameters
        for i, name in enumerate(("k1", "k2", "wind_speed_mps", "wind_from_deg")):
            inside += abs(result.params[i] - true[name]) < 3.0 * result.std[i]
            total += 1
    assert inside / total >= 0.9


@pytest.mark.parametrize("kwargs, match", [
    ({"rate_hz": 1e9}, (r"rate_hz 1e\+09 gives 2.4e\+11 samples over the plan's 240 s; the "
                        r"simulator records at most 500,000: use at most 2083 Hz")),
    ({"gps_latency_s": 240.0}, r"gps_latency_s 240 must be shorter than the plan's 240 s"),
])
def test_impossible_sizes_refused_before_any_work(plan, kwargs, match):
    with pytest.raises(PitotcalError, match=match):
        simulate(plan, **kwargs)


def test_plan_below_sea_level_is_flown_in_turbulence():
    """The planner accepts altitude_m down to -400 m (ISA); the Dryden scales refused it."""
    from pitotcal.maneuvers.plan.autothrottle import check_autothrottle

    low = circle_plan(altitude_m=-100.0)
    flight, truth = simulate(low, seed=1, turbulence_mps=0.5)
    assert flight.n == 12001 and truth.tracking.max_cas_error_kt < 5.0
    np.testing.assert_allclose(flight.rho_kgm3, isa_density_kgm3(-100.0), rtol=1e-6)
    assert check_autothrottle(low, turbulence_mps=0.5).success


def test_the_flight_does_not_depend_on_the_logging_rate(plan):
    """The aircraft and autopilot step at >= 50 Hz whatever rate_hz is: a 10 Hz log samples the
    same flight as a 50 Hz one (before, the dynamics stepped at the logging rate)."""
    quiet = dict(seed=4, turbulence_mps=0.0, qc_noise_pa=0.0, gps_noise_mps=0.0, gps_rate_hz=0)
    slow, _ = simulate(plan, rate_hz=10.0, **quiet)
    fast, _ = simulate(plan, rate_hz=50.0, **quiet)
    assert np.allclose(slow.time_s, fast.time_s[::5])
    for name in ("qci_pa", "gps_vn_mps", "gps_ve_mps", "alt_m"):
        assert np.allclose(getattr(slow, name), getattr(fast, name)[::5], atol=1e-9), name


def test_references_step_the_dynamics_at_50_hz_or_faster(plan):
    """A 7 Hz log: 8 dynamics steps per sample (56 Hz), the samples on the grid."""
    refs = references(plan, 7.0)
    assert isinstance(refs, References) and refs.steps_per_sample == 8
    assert refs.dt_s == pytest.approx(1.0 / 56.0)
    np.testing.assert_allclose(refs.time_s[::8], refs.sample_time_s)
    assert refs.sample_time_s.size == 240 * 7 + 1
    np.testing.assert_allclose(refs.tas_mps, np.interp(refs.time_s, plan.time_s, plan.tas_mps))


def test_default_true_coefficients_follow_the_model(plan):
    """k defaults to the scenario's true coefficients of the model (linear: 0.03, -1e-5)."""
    _, truth = simulate(plan, seed=1, model="linear", turbulence_mps=0.0)
    assert truth.k == true_k("linear") == (0.03, -1.0e-5)
    _, truth = simulate(plan, seed=1, model="constant", turbulence_mps=0.0)
    assert truth.k == (0.02,) and truth.options["k"] == [0.02]


def test_tracking_warnings_name_the_breach(plan):
    _, calm = simulate(plan, seed=1, turbulence_mps=0.0)
    assert tracking_warnings(calm) == []
    _, rough = simulate(plan, seed=1, turbulence_mps=2.5)
    cas = rough.tracking.max_cas_error_kt
    assert cas > 5.0
    assert tracking_warnings(rough)[0] == (
        f"the simulated auto-throttle left the ±5 KCAS band (max {cas:.1f} kt): the paper's "
        f"criterion is not met in this turbulence")
    small = dataclasses.replace(calm, plan={**calm.plan, "radius_m": 500.0})
    assert tracking_warnings(small) == [
        f"the simulated track left the 500 m test area (max {calm.tracking.max_radius_m:.0f} m)"]
