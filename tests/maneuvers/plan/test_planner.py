"""Planner: every constraint at every sample, q uniformity, levels, heading coverage, refusals."""

import numpy as np
import pytest
from pitotcal.maneuvers.plan.ocp import Layout, rk4_step
from pitotcal.maneuvers.plan.planner import (
    ManeuverProblem,
    check_converged,
    plan_maneuver,
    wind_vector_mps,
)
from pitotcal.maneuvers.plan.profiles import make_schedule

from pitotcal.core.dynamics import Limits, rhs
from pitotcal.core.errors import PitotcalError, PlanInfeasibleError
from pitotcal.core.plan import Plan
from pitotcal.core.scenario import T2_PLAN
from pitotcal.core.units import kt_to_mps

CASES = {
    "continuous": {"profile": "continuous"},
    "continuous-return": {"profile": "continuous", "return_leg": True},
    "step-pause": {"profile": "step-pause"},
    "two-speed": {"profile": "two-speed"},
    "continuous-left-crosswind": {"profile": "continuous", "turn": "left", "wind_speed_mps": 8.0,
                                  "wind_from_deg": 45.0, "radius_m": 800.0},
}


@pytest.fixture(scope="module", params=sorted(CASES))
def planned(request):
    kwargs = CASES[request.param]
    return request.param, kwargs, plan_maneuver(**kwargs)


def _request(kwargs):
    return {**T2_PLAN, **kwargs}


def _fly(plan, wind_ne, substeps=20):
    """Fly the plan's bank through the shared dynamics with fine RK4 steps (bank linear in
    each interval); return positions at the nodes and the largest distance between them."""
    t = plan.time_s
    x = np.array([plan.north_m[0], plan.east_m[0], plan.alt_m[0],
                  np.radians(plan.heading_deg[0]), plan.tas_mps[0]])
    nodes, r_max = [x[:2].copy()], 0.0
    for k in range(plan.n - 1):
        h = (t[k + 1] - t[k]) / substeps
        accel = (plan.tas_mps[k + 1] - plan.tas_mps[k]) / (t[k + 1] - t[k])
        rate = np.radians(plan.bank_deg[k + 1] - plan.bank_deg[k]) / (t[k + 1] - t[k])

        def f(x, tau, k=k, accel=accel, rate=rate):
            bank = np.radians(plan.bank_deg[k]) + rate * tau
            return np.array(rhs(x, (bank, accel, 0.0), wind_ne))

        for j in range(substeps):
            tau = j * h
            k1 = f(x, tau)
            k2 = f(x + h / 2 * k1, tau + h / 2)
            k3 = f(x + h / 2 * k2, tau + h / 2)
            k4 = f(x + h * k3, tau + h)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            r_max = max(r_max, np.hypot(x[0], x[1]))
        nodes.append(x[:2].copy())
    return np.array(nodes), r_max


def test_limits_hold_at_every_sample(planned):
    name, kwargs, plan = planned
    req = _request(kwargs)
    limits = Limits()
    assert plan.success, plan.message
    assert np.all(np.hypot(plan.north_m, plan.east_m) <= req["radius_m"])
    assert np.all(np.abs(plan.bank_deg) <= req["bank_max_deg"] + 1e-6)
    roll_dps = np.diff(plan.bank_deg) / np.diff(plan.time_s)
    assert np.all(np.abs(roll_dps) <= limits.roll_rate_max_dps + 1e-6)
    assert np.all(np.abs(plan.alt_m - req["altitude_m"]) <= limits.alt_tolerance_m)
    cas_kt = plan.cas_mps / kt_to_mps(1.0)
    assert np.all((cas_kt >= req["cas_min_kt"] - 1e-9) & (cas_kt <= req["cas_max_kt"] + 1e-9))
    accel = np.diff(plan.tas_mps) / np.diff(plan.time_s)
    assert np.all(np.abs(accel) <= limits.accel_max_mps2 + 1e-9)
    assert plan.time_s[-1] == pytest.approx(req["duration_s"])


def test_track_is_the_ground_track_in_the_wind(planned):
    """Flying the plan's bank in the stated wind through the shared model reproduces the
    nodes, and stays inside the radius between nodes too (margin 1 m)."""
    name, kwargs, plan = planned
    req = _request(kwargs)
    wind = wind_vector_mps(req["wind_speed_mps"], req["wind_from_deg"])
    nodes, r_max = _fly(plan, wind)
    assert np.max(np.hypot(nodes[:, 0] - plan.north_m, nodes[:, 1] - plan.east_m)) < 0.5
    assert r_max <= req["radius_m"]
    # and without the wind the same bank would drift elsewhere: the wind is really in it
    still, _ = _fly(plan, (0.0, 0.0), substeps=2)
    assert np.max(np.hypot(still[:, 0] - plan.north_m, still[:, 1] - plan.east_m)) > 100


def _q_groups(plan):
    """Sample masks of each third of the q range (two-speed: of each dwell)."""
    q = plan.qc_pa
    if plan.settings["profile"] == "two-speed":
        return [np.isclose(q, q.min()), np.isclose(q, q.max())]
    part = np.clip(np.floor(3 * (q - q.min()) / np.ptp(q) + 1e-9), 0, 2)
    return [part == j for j in range(3)]


def test_every_heading_sector_in_each_third_of_q(planned):
    name, kwargs, plan = planned
    for mask in _q_groups(plan):
        sectors = np.unique((np.mod(plan.heading_deg[mask], 360.0) // 30).astype(int))
        assert sectors.size == 12, f"{name}: sectors {sectors}"
    turning = np.sign(np.diff(plan.heading_deg))
    assert np.all(turning == (-1 if kwargs.get("turn") == "left" else 1))


@pytest.mark.parametrize("return_leg", [False, True])
def test_continuous_q_is_uniform(return_leg):
    plan = plan_maneuver("continuous", return_leg=return_leg)
    t = np.arange(0.0, plan.time_s[-1], 0.02)          # what a 50 Hz logger samples
    q = np.sort(np.interp(t, plan.time_s, plan.qc_pa))
    u = (q - plan.qc_pa.min()) / np.ptp(plan.qc_pa)
    ecdf = np.arange(1, u.size + 1) / u.size
    ks = max(np.max(ecdf - u), np.max(u - (ecdf - 1.0 / u.size)))
    assert ks < 0.05
    assert plan.cas_mps[0] == pytest.approx(kt_to_mps(70.0))
    assert np.max(plan.cas_mps) == pytest.approx(kt_to_mps(100.0))
    # CAS is non-linear in time (paper Fig. 9): it rises faster at the start
    rise = np.diff(plan.cas_mps[: plan.n // (2 if return_leg else 1)])
    assert rise[0] > 1.3 * rise[-1]


@pytest.mark.parametrize("levels", [3, 4, 5])
def test_step_pause_levels_equally_spaced_in_q(levels):
    plan = plan_maneuver("step-pause", levels=levels, duration_s=300.0)
    accel = np.diff(plan.tas_mps) / np.diff(plan.time_s)
    hold = np.abs(accel) < 1e-9
    level_q = np.unique(np.round(plan.qc_pa[1:][hold], 6))
    assert level_q.size == levels
    assert np.allclose(np.diff(level_q), np.ptp(level_q) / (levels - 1), rtol=0, atol=1e-5)
    # ramps fly at exactly the acceleration limit, dwells are equal
    assert np.allclose(accel[~hold], Limits().accel_max_mps2)
    dwell = [np.sum(np.diff(plan.time_s)[hold & np.isclose(plan.qc_pa[1:], q)]) for q in level_q]
    assert np.allclose(dwell, dwell[0], atol=1e-9)


def test_two_speed_dwells_at_both_ends():
    plan = plan_maneuver("two-speed", cas_min_kt=70, cas_max_kt=90, duration_s=320)
    kt = plan.cas_mps / kt_to_mps(1.0)
    assert set(np.round(kt[np.abs(np.gradient(kt)) < 1e-9], 6)) == {70.0, 90.0}
    assert np.mean(np.isclose(kt, 70)) == pytest.approx(np.mean(np.isclose(kt, 90)), abs=0.02)


def test_step_pause_ramp_corners_fall_on_nodes():
    sched = make_schedule("step-pause", kt_to_mps(70), kt_to_mps(100), 240.0, altitude_m=244.0)
    accel = sched.accel_mps2
    # piecewise constant: 0 in dwells, the limit in ramps, nothing in between
    assert set(np.round(accel, 9)) <= {0.0, 1.0}


INFEASIBLE = [
    # the last third of the q range starts at 91 KCAS: it must turn 360° at no less than that
    ({"radius_m": 150}, r"radius_m 150 m is below the 399 m turn radius at 91 KCAS and 30° bank; "
                        r"the smallest radius that fits this continuous maneuver in 5 m/s wind "
                        r"is 48\d m"),
    ({"radius_m": 150, "profile": "two-speed"},
     r"radius_m 150 m is below the 480 m turn radius at 100 KCAS and 30° bank"),
    ({"radius_m": 200, "bank_max_deg": 45},
     r"radius_m 200 m is below the 23\d m turn radius at 91 KCAS and 45° bank"),
    ({"duration_s": 10}, r"duration_s 10 s is too short for the 1 m/s\^2 acceleration limit: "
                         r"needs at least 20 s"),
    ({"profile": "step-pause", "duration_s": 15}, r"too short for 4 levels .* needs at least"),
    ({"duration_s": 60}, r"duration_s 60 s is too short to turn 360° in each third of the q "
                         r"range at 30° bank: needs at least 17\d s"),
    ({"profile": "two-speed", "duration_s": 60}, r"in each dwell .* needs at least"),
    ({"cas_min_kt": 100, "cas_max_kt": 90}, (r"cas_min_kt 100 must be below the top of the "
                                             r"airspeed range, 90 KCAS")),
    ({"wind_speed_mps": 40}, r"wind_speed_mps 40 is too strong .* below 32.8 m/s"),
]


@pytest.mark.parametrize("kwargs, match", INFEASIBLE)
def test_infeasible_requests_name_the_constraint(kwargs, match):
    with pytest.raises(PlanInfeasibleError, match=match) as info:
        plan_maneuver(**kwargs)
    # the parameter to change, for the command line to name its flag
    assert info.value.param in kwargs or info.value.param == "duration_s"


BAD_ARGS = [
    ({"profile": "zigzag"}, r"profile 'zigzag' is not one of"),
    ({"radius_m": -5}, r"radius_m -5 must be > 0"),
    ({"radius_m": "far"}, r"radius_m must be a number"),
    ({"bank_max_deg": 90}, r"bank_max_deg 90 must be > 0 and <= 75"),
    ({"wind_speed_mps": float("nan")}, r"wind_speed_mps nan must be"),
    ({"turn": "up"}, r"turn 'up' is not one of"),
    ({"levels": 1, "profile": "step-pause"}, r"levels 1 must be >= 2"),
    ({"levels": 2.5, "profile": "step-pause"}, r"levels 2.5 must be a whole number"),
    ({"wind_from_deg": float("inf")}, r"wind_from_deg inf must be a finite number"),
    # item 7 of issue 8: 400 was silently planned as 040°
    ({"wind_from_deg": 400}, r"wind_from_deg 400 must be >= 0 and < 360"),
    ({"wind_from_deg": -90}, r"wind_from_deg -90 must be >= 0 and < 360"),
    ({"dt_s": 0.01}, (r"dt_s 0.01 s over a 240 s maneuver gives 24000 plan nodes; the planner "
                      r"takes at most 3000 .*: use at least 0.08 s")),
    ({"max_iter": 0}, r"max_iter 0 must be >= 1"),
]


@pytest.mark.parametrize("kwargs, match", BAD_ARGS)
def test_bad_arguments(kwargs, match):
    with pytest.raises(PitotcalError, match=match) as info:
        plan_maneuver(**kwargs)
    assert info.value.param == next(iter(kwargs))


def test_too_small_radius_names_the_smallest_that_fits():
    """Past the analytic check the radius-minimising solve names a radius; it really works."""
    with pytest.raises(PlanInfeasibleError, match=r"smallest radius that fits") as info:
        plan_maneuver(radius_m=484)
    smallest = float(str(info.value).rsplit(":", 1)[1].split()[0])
    assert 480 < smallest < 520                      # MEASURED.md: 486 m
    plan = plan_maneuver(radius_m=smallest)
    assert plan.success
    assert np.hypot(plan.north_m, plan.east_m).max() <= smallest


def test_problem_object_is_reused_for_new_wind():
    sched = make_schedule("continuous", kt_to_mps(70), kt_to_mps(100), 240.0, altitude_m=244.0)
    problem = ManeuverProblem(sched.n_intervals)
    calm = problem.solve(sched, 926.0, (0.0, 0.0), np.radians(30), np.radians(10))
    windy = problem.solve(sched, 926.0, wind_vector_mps(10.0, 0.0), np.radians(30),
                          np.radians(10))
    assert calm.success and windy.success
    assert np.max(np.abs(windy.north_m - calm.north_m)) > 50
    smallest = problem.solve(sched, 926.0, (0.0, 0.0), np.radians(30), np.radians(10),
                             minimize_radius=True)
    # in still air less than the 480 m turn radius at 100 KCAS: only the last third must turn
    # 360°, and it starts at 91 KCAS (399 m)
    assert smallest.success and 399 < smallest.radius_m < 480


def test_settings_carry_the_request():
    plan = plan_maneuver("step-pause", wind_speed_mps=3, wind_from_deg=270)
    s = plan.settings
    assert s["profile"] == "step-pause" and s["levels"] == 4
    assert s["wind_from_deg"] == 270.0 and s["wind_speed_mps"] == 3.0
    assert s["radius_m"] == 926.0 and s["duration_s"] == 240.0


def test_step_pause_with_two_levels_is_planned_like_two_speed():
    """Two levels leave the middle third of q to the ramp alone, which no duration lengthens:
    the search for a long-enough duration ran out of memory (killed). Cover each dwell."""
    plan = plan_maneuver("step-pause", levels=2)
    assert plan.success
    two = make_schedule("two-speed", kt_to_mps(70), kt_to_mps(100), 240.0, altitude_m=244.0)
    assert plan.settings["coverage_runs"] == [[list(r) for r in runs] for runs in two.groups]
    for first, last in (runs[0] for runs in two.groups):
        turned = abs(plan.heading_deg[last] - plan.heading_deg[first])
        assert turned >= 360.0
    with pytest.raises(PlanInfeasibleError, match=r"turn 360° in each dwell .* needs at least"):
        plan_maneuver("step-pause", levels=2, duration_s=100)


def test_solver_failure_is_not_reported_as_infeasible():
    """Item 7 of issue 8: `plan --duration-s 4000 --dt-s 4` hit IPOPT's iteration limit (it
    needs ~440 iterations) and was told "try a longer duration_s than 4000 s". The same failure,
    quickly: an iteration limit of 3."""
    with pytest.raises(PitotcalError) as info:
        plan_maneuver(max_iter=3)
    assert not isinstance(info.value, PlanInfeasibleError)
    assert str(info.value) == (
        "the path optimiser stopped at its iteration limit, max_iter 3, on 241 nodes (and when "
        "minimising the radius): a solver limit, the request may well be feasible; raise the "
        "limit (e.g. to 6) or plan a shorter maneuver")
    assert info.value.param == "max_iter"


def test_check_converged_names_what_failed():
    good = plan_maneuver()
    assert check_converged(good) is good
    bad = Plan(**{c: getattr(good, c) for c in ("time_s", "north_m", "east_m", "alt_m",
                                                "heading_deg", "bank_deg", "tas_mps", "cas_mps",
                                                "qc_pa")},
               success=False, message="Restoration_Failed", iterations=57)
    with pytest.raises(PitotcalError, match=r"the path optimiser failed with Restoration_Failed "
                                            r"after 57 iterations on 241 nodes: a solver "
                                            r"failure, the request may well be feasible"):
        check_converged(bad)


def test_layout_names_the_slices_of_the_decision_vector():
    problem = ManeuverProblem(10)
    assert problem.x["north_km"] == slice(0, 11) and problem.x["roll"] == slice(44, 54)
    assert problem.x.index("r2_km2") == 54 == problem.x.size - 1
    assert problem.g["coverage"] == slice(40 + 11, 40 + 11 + 3)
    assert Layout(a=2, b=3)["b"] == slice(2, 5)


def test_rk4_step_is_a_named_casadi_function():
    """Straight flight at constant acceleration: RK4 is exact for the quadratic track."""
    step = rk4_step(3)
    assert step.name() == "rk4_step"
    assert step.name_in()[-2:] == ["wind_ne_mps", "h_s"] and step.name_out()[0] == "north_m_end"
    out = step(north_m=[0.0] * 3, east_m=[0.0] * 3, heading_rad=[0.0, np.pi / 2, 0.0],
               bank_rad=[0.0] * 3, tas_mps=[40.0] * 3, roll_rps=[0.0, 0.0, 0.1],
               accel_mps2=[1.0] * 3, wind_ne_mps=[0.0, 3.0], h_s=[2.0] * 3)
    north, east = np.asarray(out["north_m_end"]).ravel(), np.asarray(out["east_m_end"]).ravel()
    assert north[0] == pytest.approx(82.0) and east[1] == pytest.approx(82.0 + 6.0)
    assert np.asarray(out["tas_mps_end"]).ravel() == pytest.approx([42.0] * 3)
    assert np.asarray(out["bank_rad_end"]).ravel() == pytest.approx([0.0, 0.0, 0.2])


def test_ipopt_options_must_be_a_dict():
    with pytest.raises(PitotcalError, match="ipopt_options must be a dict, not list"):
        plan_maneuver(ipopt_options=["max_iter", 5])
