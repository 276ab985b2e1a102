"""SimulationOptions: simulate's options as one frozen object, each field checked when it is
made (naming the field), resolved against the plan; keywords and options fly the same flight;
the engine is an option."""

import dataclasses

import numpy as np
import pytest
from plans import circle_plan

from pitotcal.core.errors import PitotcalError
from pitotcal.maneuvers import SimulationOptions, simulate, simulate_jsbsim
from pitotcal.maneuvers.fly.options import AirSensors


@pytest.fixture(scope="module")
def plan():
    return circle_plan(duration_s=30.0)


def test_defaults_are_the_documented_ones():
    o = SimulationOptions()
    assert (o.model, o.k, o.wind_speed_mps, o.wind_from_deg, o.wind_drift_mps2) == \
        ("inverse", None, None, None, (0.0, 0.0))
    assert (o.turbulence_mps, o.rate_hz, o.qc_noise_pa, o.gps_rate_hz, o.gps_noise_mps,
            o.gps_gm_tau_s) == (0.5, 50.0, 0.5, 5.0, 0.05, 30.0)
    assert (o.engine, o.aircraft, o.air_data, o.keep_history) == ("own", None, None, False)
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.rate_hz = 10.0


@pytest.mark.parametrize("fields, param, message", [
    ({"model": "cubic"}, "model", "model 'cubic' is not one of constant, linear, inverse"),
    ({"k": (0.01,)}, "k", "k needs 2 coefficients for model 'inverse', got 1"),
    ({"k": {"k2": float("nan")}}, "k2", "k2 nan must be a finite number"),
    ({"model": "constant", "k": {"k2": 3.0}}, "k2", "k2: model 'constant' has only 1"),
    ({"wind_speed_mps": -1}, "wind_speed_mps", "wind_speed_mps -1 must be >= 0"),
    ({"wind_from_deg": 360}, "wind_from_deg", "wind_from_deg 360 must be >= 0 and < 360"),
    ({"wind_drift_mps2": (0.0, 1.0)}, "wind_drift_e_mps2", "wind_drift_e_mps2 1 must be"),
    ({"wind_drift_mps2": 0.1}, "wind_drift_mps2", "wind_drift_mps2 must be (north, east)"),
    ({"rate_hz": 0}, "rate_hz", "rate_hz 0 must be > 0"),
    ({"gps_noise_mps": 10.5}, "gps_noise_mps", "gps_noise_mps 10.5 must be >= 0 and <= 10"),
    ({"gps_gm_tau_s": 0}, "gps_gm_tau_s", "gps_gm_tau_s 0 must be > 0"),
    ({"air_data": "ideal"}, "air_data", "air_data 'ideal' is not one of"),
    ({"air_sensors": {"rh_pct": 200}}, "rh_percent", "rh_percent 200 must be"),
    ({"vertical_gusts": "yes"}, "vertical_gusts", "vertical_gusts must be true or false"),
    ({"engine": "xplane"}, "engine", "engine 'xplane' is not one of own, jsbsim"),
    ({"aircraft": "c172x"}, "aircraft", "aircraft: only engine jsbsim flies"),
    ({"center_deg": (47.0, 8.0)}, "center_deg", "center_deg: only engine jsbsim"),
    ({"engine": "jsbsim", "air_data": "incompressible"}, "air_data",
     "air_data incompressible: JSBSim's impact pressure is its own"),
    ({"engine": "jsbsim", "turbulence_length_m": 300.0}, "turbulence_length_m",
     "turbulence_length_m: JSBSim's Milspec turbulence"),
    ({"engine": "jsbsim", "air_sensors": AirSensors(rh_pct=50.0)}, "air_sensors",
     "apply to engine own only"),
    ({"engine": "jsbsim", "center_deg": (91.0, 0.0)}, "lat_deg", "lat_deg 91 must be"),
    ({"limits": 30.0}, "limits", "limits must be a pitotcal.core.dynamics.Limits or None"),
    ({"speed_loop": "fast"}, "speed_loop", "speed_loop must be a"),
])
def test_each_bad_field_is_refused_when_made_naming_it(fields, param, message):
    with pytest.raises(PitotcalError, match=message.replace("(", r"\(").replace(")", r"\)")) \
            as info:
        SimulationOptions(**fields)
    assert info.value.param == param


def test_options_and_keywords_fly_the_same_flight_and_overrides_win(plan):
    base = SimulationOptions(turbulence_mps=1.0, rate_hz=10.0, gps_noise_mps=0.3)
    by_keywords, truth_k = simulate(plan, seed=3, turbulence_mps=1.0, rate_hz=10.0,
                                    gps_noise_mps=0.1, model="linear")
    by_options, truth_o = simulate(plan, base, seed=3, gps_noise_mps=0.1, model="linear")
    assert np.array_equal(by_keywords.qci_pa, by_options.qci_pa)
    assert np.array_equal(by_keywords.gps_vn_mps, by_options.gps_vn_mps)
    assert truth_o.options == truth_k.options
    assert truth_o.options["gps_noise_mps"] == 0.1 and truth_o.model == "linear"
    assert base.gps_noise_mps == 0.3                       # the object is not changed


def test_resolved_against_the_plan(plan):
    flight, truth = simulate(plan, SimulationOptions(k={"k2": -20.0}, rate_hz=5.0), seed=1)
    assert truth.k == (0.02, -20.0)                        # k1 the model's default
    assert truth.options["wind_speed_mps"] == plan.settings.get("wind_speed_mps", 0.0)
    assert truth.options["air_data"] == "incompressible"
    # the truth JSON's options keep their keys: no engine or run fields for the own engine
    assert not {"engine", "aircraft", "limits", "speed_loop", "keep_history"} & set(truth.options)


def test_plan_dependent_checks_still_name_the_field(plan):
    with pytest.raises(PitotcalError, match="gps_latency_s 40 must be shorter") as info:
        simulate(plan, SimulationOptions(gps_latency_s=40.0))
    assert info.value.param == "gps_latency_s"


def test_unknown_keyword_and_wrong_options_type():
    with pytest.raises(TypeError, match="simulate\\(\\) got an unexpected keyword argument "
                                        "'gps_noise'"):
        simulate(circle_plan(duration_s=20.0), gps_noise=0.1)
    with pytest.raises(PitotcalError, match="options must be a SimulationOptions") as info:
        simulate(circle_plan(duration_s=20.0), {"rate_hz": 10.0})
    assert info.value.param == "options"


def test_the_engine_is_an_option_of_simulate():
    plan = circle_plan(duration_s=20.0, cas_kt=(80.0, 85.0), radius_m=800.0)
    a, truth_a = simulate(plan, SimulationOptions(engine="jsbsim", turbulence_mps=0.0,
                                                  rate_hz=5.0), seed=2)
    b, truth_b = simulate_jsbsim(plan, seed=2, turbulence_mps=0.0, rate_hz=5.0)
    assert np.array_equal(a.qci_pa, b.qci_pa) and truth_a.options == truth_b.options
    assert truth_a.options["engine"] == "jsbsim" and truth_a.options["aircraft"] == "c172x"
    assert truth_a.air_data == truth_a.options["air_data"] == "compressible"
