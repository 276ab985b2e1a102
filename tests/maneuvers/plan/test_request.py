"""PlanRequest: plan_maneuver's request as one frozen object, each field checked when it is made
(naming the field); keywords, the old positional order and a request plan the same maneuver."""

import dataclasses

import numpy as np
import pytest

from pitotcal.core.errors import PitotcalError, PlanInfeasibleError
from pitotcal.core.scenario import T2_PLAN
from pitotcal.maneuvers import DesignOptions, PlanRequest, plan_maneuver


def test_defaults_are_the_t2_case():
    r = PlanRequest()
    for name, value in T2_PLAN.items():
        assert getattr(r, name) == value, name
    assert (r.roll_rate_max_dps, r.accel_max_mps2, r.levels, r.turn, r.dt_s, r.max_iter,
            r.design, r.design_options) == (10.0, 1.0, 4, "right", 1.0, 300, "paper", None)
    assert PlanRequest(roll_rate_max_dps=None).roll_rate_max_dps == 10.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.radius_m = 500.0


@pytest.mark.parametrize("fields, param, message", [
    ({"profile": "zigzag"}, "profile", "profile 'zigzag' is not one of"),
    ({"cas_min_kt": 100, "cas_max_kt": 90}, "cas_min_kt",
     "cas_min_kt 100 must be below the top of the airspeed range, 90 KCAS"),
    ({"radius_m": 0}, "radius_m", "radius_m 0 must be > 0"),
    ({"altitude_m": 40000}, "altitude_m", "altitude_m 40000 must be >= -400 and <= 32000"),
    ({"duration_s": 20000}, "duration_s", "duration_s 20000 must be <= 14400 s"),
    ({"bank_max_deg": 90}, "bank_max_deg", "bank_max_deg 90 must be > 0 and <= 75"),
    ({"wind_from_deg": 400}, "wind_from_deg", "wind_from_deg 400 must be >= 0 and < 360"),
    ({"roll_rate_max_dps": 0}, "roll_rate_max_dps", "roll_rate_max_dps 0 must be > 0"),
    ({"levels": 1}, "levels", "levels 1 must be >= 2"),
    ({"turn": "up"}, "turn", "turn 'up' is not one of right, left, both"),
    ({"dt_s": 200}, "dt_s", "dt_s 200 must be > 0 and <= 120"),
    ({"margin_m": 1000}, "margin_m", "margin_m 1000 must be >= 0 and <= 926"),
    ({"max_iter": 0}, "max_iter", "max_iter 0 must be >= 1"),
    ({"design": "best"}, "design", "design 'best' is not one of paper, optimal"),
    ({"design_options": {"stall_kt": 50}}, "stall_kt", "stall_kt is for design optimal"),
    ({"design": "optimal", "design_options": {"check_fraction": 0.7}}, "check_fraction",
     "check_fraction 0.7 must be >= 0 and < 0.5"),
])
def test_each_bad_field_is_refused_when_made_naming_it(fields, param, message):
    with pytest.raises(PitotcalError, match=message) as info:
        PlanRequest(**fields)
    assert info.value.param == param
    if param == "cas_min_kt":
        assert isinstance(info.value, PlanInfeasibleError)


def test_design_options_checked_into_the_object():
    r = PlanRequest(design="optimal", design_options={"turbulence_mps": 1.0})
    assert r.design_options == DesignOptions(turbulence_mps=1.0)


def test_request_keywords_and_positional_plan_the_same_maneuver():
    by_request = plan_maneuver(PlanRequest(profile="two-speed", radius_m=700.0), turn="left")
    by_keywords = plan_maneuver(profile="two-speed", radius_m=700.0, turn="left")
    by_position = plan_maneuver("two-speed", 70.0, 100.0, 700.0, turn="left")
    for other in (by_keywords, by_position):
        assert other.settings == by_request.settings
        assert np.array_equal(other.north_m, by_request.north_m)
    assert by_request.settings["radius_m"] == 700.0 and by_request.settings["turn"] == "left"


def test_overrides_win_over_the_request_which_is_not_changed():
    base = PlanRequest(radius_m=500.0)
    plan = plan_maneuver(base, radius_m=800.0)
    assert plan.settings["radius_m"] == 800.0 and base.radius_m == 500.0


@pytest.mark.parametrize("call, message", [
    (lambda: plan_maneuver(radius=800.0), "unexpected keyword argument 'radius'"),
    (lambda: plan_maneuver("two-speed", 70.0, profile="continuous"),
     "multiple values for argument 'profile'"),
    (lambda: plan_maneuver(*["continuous"] * 10), "at most 9 positional arguments"),
    (lambda: plan_maneuver(PlanRequest(), 70.0), "a PlanRequest or the positional form"),
])
def test_malformed_calls_are_type_errors(call, message):
    with pytest.raises(TypeError, match=message):
        call()


def test_a_request_of_the_wrong_type_names_it():
    with pytest.raises(PitotcalError, match="request must be a PlanRequest") as info:
        plan_maneuver({"radius_m": 800.0})
    assert info.value.param == "request"
