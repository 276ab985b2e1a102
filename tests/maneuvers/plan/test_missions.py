"""maneuvers.plan.missions: exported missions read back (pymavlink's loader, the .plan JSON) against
the plan they come from; the loiter's refusals name values that work."""

import dataclasses
import json
import math
import re

import numpy as np
import pytest
from pitotcal.maneuvers.plan.missions import (
    build_mission,
    check_loiter,
    export_mission,
    loiter_plan,
    mission_path,
    speed_levels,
)
from pitotcal.maneuvers.plan.planner import plan_maneuver
from pitotcal.maneuvers.plan.profiles import make_schedule

from pitotcal.core.airdata import cas_from_qc_mps
from pitotcal.core.errors import PitotcalError, PlanInfeasibleError
from pitotcal.core.plan import Plan
from pitotcal.core.units import G0_MPS2, kt_to_mps, mps_to_kt

CENTER = (47.397742, 8.545594)


@pytest.fixture(scope="module")
def two_speed():
    return plan_maneuver("two-speed", radius_m=600.0)


@pytest.fixture(scope="module")
def continuous():
    # the T-2 sweep at the radius and duration the refusal below names
    return plan_maneuver("continuous", radius_m=575.0, duration_s=290.0)


def test_ardupilot_two_speed_read_back_by_pymavlink(two_speed, tmp_path):
    from pymavlink import mavwp

    path = mission_path(tmp_path / "plan.csv", "ardupilot")
    assert path.name == "plan.waypoints"
    export_mission(two_speed, path, "ardupilot", *CENTER)
    loader = mavwp.MAVWPLoader()
    assert loader.load(str(path)) == 5
    wps = [loader.wp(i) for i in range(5)]
    assert [w.command for w in wps] == [16, 178, 19, 178, 19]
    speeds = [w.param2 for w in wps if w.command == 178]
    assert speeds == pytest.approx(kt_to_mps([70.0, 100.0]), abs=1e-4)
    assert all(w.param1 == 0 and w.param3 == -1 for w in wps if w.command == 178)
    loiters = [w for w in wps if w.command == 19]
    for w in loiters:
        assert (w.x, w.y) == pytest.approx(CENTER, abs=1e-6)
        assert (w.z, w.frame, w.param3) == (244.0, 0, 600.0)     # AMSL, clockwise (right)
    # level 1 is held from the end of the low dwell (its ramp flown in its loiter) to the end
    low = np.isclose(two_speed.qc_pa, two_speed.qc_pa[0])
    ramp_start = two_speed.time_s[np.flatnonzero(low)[-1]]
    assert [w.param1 for w in loiters] == [round(ramp_start), 240 - round(ramp_start)] == [112,
                                                                                          128]


def test_px4_continuous_staircase_left_agl(continuous, tmp_path):
    plan = dataclasses.replace(continuous, settings={**continuous.settings, "turn": "left"})
    mission = export_mission(plan, tmp_path / "p.plan", "px4", *CENTER, altitude_ref="agl")
    items = json.loads((tmp_path / "p.plan").read_text())["mission"]["items"]
    assert len(items) == 16 and [i["command"] for i in items] == [178, 19] * 8
    speeds = [i["params"][1] for i in items if i["command"] == 178]
    assert np.all(np.diff(speeds) > 0) and speeds == pytest.approx(mission.cas_mps)
    loiters = [i for i in items if i["command"] == 19]
    assert {(i["params"][2], i["frame"], i["AltitudeMode"], i["Altitude"]) for i in loiters} == {
        (-575.0, 3, 1, 244.0)}                                    # counter-clockwise, AGL
    assert [i["params"][4:6] for i in loiters] == [list(CENTER)] * 8
    # 290 s in 8 equal steps, in whole seconds (ArduPilot stores loiter time as an integer)
    times = [i["params"][0] for i in loiters]
    assert sum(times) == 290 and set(times) == {36, 37} and mission.loiter_s == tuple(times)
    # each step within 2.5 kt (half the pilot's ±5) of the ramp it replaces
    edges = np.r_[0.0, np.cumsum([i["params"][0] for i in loiters])]
    step = np.clip(np.searchsorted(edges, plan.time_s, side="right") - 1, 0, 7)
    error = mps_to_kt(np.abs(plan.cas_mps - np.asarray(speeds)[step]))
    assert error.max() <= 2.5 and mission.staircase_error_kt == pytest.approx(2.24, abs=0.01)


def test_staircase_with_return_leg_is_even_and_symmetric():
    s = make_schedule("continuous", kt_to_mps(70.0), kt_to_mps(100.0), 240.0, altitude_m=244.0,
                      return_leg=True)
    zeros = np.zeros_like(s.time_s)
    plan = Plan(s.time_s, zeros, zeros, zeros, zeros, zeros, s.tas_mps, s.cas_mps, s.qc_pa,
                settings={"return_leg": True})
    cas, loiter_s, error = speed_levels(plan)
    assert len(cas) % 2 == 0 and cas == pytest.approx(cas[::-1]) and sum(loiter_s) == 240
    assert error <= 2.5 and cas[0] > cas_from_qc_mps(s.qc_pa[0])


def test_downwind_bank_refused_with_the_radius_that_works(two_speed):
    plan = dataclasses.replace(two_speed, settings={**two_speed.settings, "bank_max_deg": 20.0})
    with pytest.raises(PlanInfeasibleError, match=r"radius_m 600 m is too small for a loiter: "
                       r"circling it downwind at 57\.0 m/s ground speed .* banks 29°, over "
                       r"bank_max_deg 20°") as info:
        check_loiter(plan)
    assert info.value.param == "radius_m"
    need = int(re.search(r"radius_m at least (\d+) m", str(info.value))[1])
    vg = two_speed.tas_mps.max() + 5.0
    tan20 = math.tan(math.radians(20.0))
    assert vg ** 2 / (G0_MPS2 * need) <= tan20 < vg ** 2 / (G0_MPS2 * (need - 1))


def test_heading_coverage_refused_with_a_radius_range_that_works():
    with pytest.raises(PlanInfeasibleError, match=r"radius_m 926 m: a 926 m loiter circle "
                       r"turns only 223° of heading in one dwell; export a plan with radius_m "
                       r"575-640 m"):
        build_mission(plan_maneuver("two-speed"), *CENTER)
    mission = build_mission(plan_maneuver("two-speed", radius_m=640.0), *CENTER)
    assert 360.0 <= mission.heading_turn_deg < 365.0


def test_too_short_refused_with_radius_and_duration(continuous):
    with pytest.raises(PlanInfeasibleError, match=r"duration_s 240 s: a 926 m loiter circle "
                       r"turns only 161° .* export a plan with radius_m 575 m and duration_s "
                       r"290 s or more") as info:
        check_loiter(plan_maneuver())                   # the T-2 case as the paper flies it
    assert info.value.param == "duration_s"
    # the radius and duration it names work: the fixture
    assert build_mission(continuous, *CENTER).heading_turn_deg >= 360.0


@pytest.mark.parametrize("kwargs, message", [
    ({"center_lat_deg": 91.0}, "lat_deg 91 must be >= -90 and <= 90"),
    ({"center_lon_deg": 180.0}, "lon_deg 180 must be >= -180 and < 180"),
    ({"altitude_ref": "amsl"}, "altitude_ref 'amsl' is not one of msl, agl"),
])
def test_bad_arguments(two_speed, kwargs, message):
    args = {"center_lat_deg": CENTER[0], "center_lon_deg": CENTER[1], **kwargs}
    with pytest.raises(PitotcalError, match=message):
        build_mission(two_speed, args.pop("center_lat_deg"), args.pop("center_lon_deg"), **args)


@pytest.mark.parametrize("turn", ["right", "left"])
def test_exported_mission_flown_as_a_loiter_and_identified(two_speed, turn):
    """Item 4 of issue 13: the circle and speed steps the autopilot flies, flown by the
    simulator (0.5 m/s turbulence) and identified back within 3 sigma of the truth."""
    from pitotcal.estimation.identification.identify import identify
    from pitotcal.maneuvers.fly.simulator import simulate

    from pitotcal.core.scenario import true_k

    plan = dataclasses.replace(two_speed, settings={**two_speed.settings, "turn": turn})
    mission = build_mission(plan, *CENTER)
    flown = loiter_plan(plan, mission, start_deg=90.0)
    assert np.hypot(flown.north_m, flown.east_m) == pytest.approx(600.0)
    assert np.abs(flown.bank_deg).max() <= 30.0 and np.sign(flown.bank_deg).mean() == (
        1.0 if turn == "right" else -1.0)
    # each level reached by the end of its loiter
    ends = np.searchsorted(flown.time_s, np.cumsum(mission.loiter_s)) - 1
    assert flown.cas_mps[ends] == pytest.approx(mission.cas_mps)
    flight, truth = simulate(flown, seed=3)
    assert truth.tracking.max_path_error_m < 15.0
    result = identify(flight)
    z = (np.asarray(result.params[:2]) - true_k("inverse")) / np.asarray(result.std[:2])
    assert np.all(np.abs(z) < 3.0), z
