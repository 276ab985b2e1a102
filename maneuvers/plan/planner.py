"""Maneuver planner: a fixed q(t) schedule and an optimised lateral path inside the test area.

`plan_maneuver` runs three steps:

1. feasibility: every field of the `PlanRequest` checked (maneuvers.plan.request), then the analytic conditions a plan must meet -
   cas_min < cas_max, the acceleration limit against the duration, the turn available at full
   bank against 360 deg per coverage group, the wind against the slowest airspeed, the still-air
   turn radius against the test area - each refusal naming the value that works;
2. solve with fallback: the lateral-path OCP (maneuvers.plan.ocp) with IPOPT; when it fails, a
   radius-minimising solve tells an infeasible request (and the smallest radius that fits) from
   a solver failure, and a fitting smallest-radius path is the warm start of a second try;
3. build the `Plan`: the nodes, the request in `settings`, IPOPT's outcome.
"""

import logging
import warnings
from dataclasses import replace
from functools import lru_cache

import numpy as np
from .ocp import ManeuverProblem, PathSolution, turn_radius_m
from .request import (
    MAX_ITER,
    MAX_NODES,
    PlanRequest,
    check_node_count,
    plan_request,
    working_request,
)

from pitotcal.core.errors import PitotcalError, PlanInfeasibleError
from pitotcal.core.plan import Plan
from pitotcal.core.speeds import cas_from_tas_mps
from pitotcal.core.units import G0_MPS2, mps_to_kt, wind_vector_mps

__all__ = ["MAX_ITER", "MAX_NODES", "ManeuverProblem", "PathSolution", "PlanRequest",
           "check_converged", "plan_maneuver", "turn_radius_m", "wind_vector_mps"]

log = logging.getLogger(__name__)

# IPOPT statuses that say the constraints cannot be met (any other failure proves nothing)
_INFEASIBLE = ("Infeasible_Problem_Detected",)


def _turn_available(schedule, bank_max_rad):
    """Heading change each coverage group allows at full bank (roll-in ignored)."""
    rate = G0_MPS2 * np.tan(bank_max_rad) / schedule.tas_mps
    cum = np.r_[0.0, np.cumsum(np.diff(schedule.time_s) * 0.5 * (rate[1:] + rate[:-1]))]
    return min(sum(cum[b] - cum[a] for a, b in runs) for runs in schedule.groups)


def _where(schedule):
    # two groups: two-speed's dwells, or a designed schedule's end levels
    return "dwell" if len(schedule.groups) == 2 else "third of the q range"


def _check_turns(req, schedule):
    """Refuse a duration too short to turn 360° in each group at full bank, naming the
    shortest that is long enough (bisection on the analytic turn available)."""
    if _turn_available(schedule, req.bank_max_rad) >= req.coverage_rad:
        return
    lo, hi = req.duration_s, 2.0 * req.duration_s
    while _turn_available(req.schedule(hi), req.bank_max_rad) < req.coverage_rad:
        lo, hi = hi, 2.0 * hi
        if hi > 64.0 * req.duration_s:
            # a group whose time does not grow with the duration: no duration helps
            raise PlanInfeasibleError(
                f"no duration lets the track turn 360° in each {_where(schedule)} at "
                f"{req.bank_max_deg:g}° bank: try a larger bank_max_deg", param="bank_max_deg")
    while hi - lo > 0.5:
        mid = 0.5 * (lo + hi)
        ok = _turn_available(req.schedule(mid), req.bank_max_rad) >= req.coverage_rad
        lo, hi = (lo, mid) if ok else (mid, hi)
    raise PlanInfeasibleError(
        f"duration_s {req.duration_s:g} s is too short to turn 360° in each {_where(schedule)} "
        f"at {req.bank_max_deg:g}° bank: needs at least {np.ceil(hi):.0f} s", param="duration_s")


def _feasible_schedule(req, design=None):
    """The schedule of a request that passes the analytic checks (PlanInfeasibleError else),
    and the request; `design` (maneuvers.plan.design_request.DesignOptions): the designed schedule."""
    check_node_count(req)
    extra = {}
    if design is not None:
        from .design_request import optimal_schedule

        found, bank_deg, duration_s, extra = optimal_schedule(req, design)
        req = replace(req, profile="optimal", bank_max_deg=bank_deg, duration_s=duration_s)
        check_node_count(req)
        schedule = found.schedule
    else:
        schedule = req.schedule()
    tas_min = schedule.tas_mps.min()
    if req.wind_speed_mps >= 0.9 * tas_min:
        raise PlanInfeasibleError(
            f"wind_speed_mps {req.wind_speed_mps:g} is too strong to hold position at "
            f"{req.cas_min_kt:g} KCAS: it must be below {0.9 * tas_min:.1f} m/s",
            param="wind_speed_mps")
    if design is None:          # the design only scores schedules that turn enough
        _check_turns(req, schedule)
    return schedule, req, extra


def _unconverged(status, iterations, n_nodes, max_iter, during=""):
    """The error for an IPOPT failure that proves nothing about the request: what failed and
    what to change."""
    if status == "Maximum_Iterations_Exceeded":
        return PitotcalError(
            f"the path optimiser stopped at its iteration limit, max_iter {max_iter}, on "
            f"{n_nodes} nodes{during}: a solver limit, the request may well be feasible; "
            f"raise the limit (e.g. to {2 * max_iter}) or plan a shorter maneuver",
            param="max_iter")
    return PitotcalError(
        f"the path optimiser failed with {status} after {iterations} iterations on {n_nodes} "
        f"nodes{during}: a solver failure, the request may well be feasible; try a slightly "
        f"different dt_s", param="dt_s")


def check_converged(plan, max_iter=MAX_ITER):
    """`plan` if IPOPT converged on it; else the error naming what failed and what to change.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
        As returned by `plan_maneuver` (which warns and returns ``success=False`` when its last
        solve does not converge).
    max_iter : int
        The iteration limit it was planned with.
    """
    if not plan.success:
        raise _unconverged(plan.message, plan.iterations, plan.n, max_iter)
    return plan


@lru_cache(maxsize=8)
def _problem(n_intervals, n_groups, max_iter=MAX_ITER):
    # build once per grid structure: re-planning (studies, CLI retries) only re-solves
    return ManeuverProblem(n_intervals, n_groups, ipopt_options={"max_iter": max_iter})


def _solve(req, schedule, ipopt_options):
    """The path: the OCP solved, with the radius-minimising solve as the fallback and judge."""
    problem = _problem(schedule.n_intervals, len(schedule.groups), req.max_iter) \
        if ipopt_options is None else ManeuverProblem(
            schedule.n_intervals, len(schedule.groups),
            ipopt_options={"max_iter": req.max_iter, **ipopt_options})
    args = (schedule, req.radius_m, wind_vector_mps(req.wind_speed_mps, req.wind_from_deg),
            req.bank_max_rad, np.radians(req.roll_rate_max_dps))
    kwargs = {"turn": req.turn, "margin_m": req.margin_m,
              "heading_margin_rad": req.heading_margin_rad}
    # A path whose heading turns 180 deg with turn radius >= r spans at least 2 r across (the
    # along-track drift of the wind does not change the cross extent), so each coverage group
    # needs R >= r at the slowest speed of the group: a necessary condition.
    tas_turn = max(min(schedule.tas_mps[a:b + 1].min() for a, b in runs)
                   for runs in schedule.groups)
    r_turn = float(turn_radius_m(tas_turn, req.bank_max_rad))
    if req.radius_m < r_turn + req.margin_m:
        cas_kt = float(mps_to_kt(cas_from_tas_mps(tas_turn, schedule.altitude_m)))
        message = (f"radius_m {req.radius_m:g} m is below the {np.ceil(r_turn + req.margin_m):.0f}"
                   f" m turn radius at {cas_kt:.0f} KCAS and {req.bank_max_deg:g}° bank")
        smallest = problem.solve(*args, minimize_radius=True, **kwargs)
        if smallest.success:
            need = np.ceil(smallest.radius_m + req.margin_m)
            message += (f"; the smallest radius that fits this {req.profile} maneuver in "
                        f"{req.wind_speed_mps:g} m/s wind is {need:.0f} m")
        raise PlanInfeasibleError(message, param="radius_m")
    sol = problem.solve(*args, **kwargs)
    log.info("plan: %s after %d iterations, %.3f s", sol.message, sol.iterations,
             sol.solve_time_s)
    if sol.success:
        return sol
    smallest = problem.solve(*args, minimize_radius=True, **kwargs)
    log.info("smallest radius: %s, %.1f m", smallest.message, smallest.radius_m)
    if not smallest.success:
        if smallest.message not in _INFEASIBLE:
            raise _unconverged(sol.message, sol.iterations, schedule.time_s.size,
                               (ipopt_options or {}).get("max_iter", req.max_iter),
                               " (and when minimising the radius)")
        raise PlanInfeasibleError(
            f"no path turns 360° in each {_where(schedule)} within {req.bank_max_deg:g}° bank "
            f"and {req.roll_rate_max_dps:g}°/s roll rate: try a longer duration_s than "
            f"{req.duration_s:g} s", param="duration_s")
    need = smallest.radius_m + req.margin_m
    if need > req.radius_m:
        raise PlanInfeasibleError(
            f"radius_m {req.radius_m:g} m is below the smallest radius that fits this "
            f"{req.profile} maneuver in {req.wind_speed_mps:g} m/s wind at "
            f"{req.bank_max_deg:g}° bank: {np.ceil(need):.0f} m", param="radius_m")
    # the smallest-radius path fits inside the requested radius: start from it
    sol = problem.solve(*args, guess=smallest, **kwargs)
    if not sol.success:
        warnings.warn(f"maneuver planner did not converge: {sol.message}", stacklevel=3)
    return sol


def _build_plan(req, schedule, sol, extra):
    settings = {
        "profile": req.profile, "cas_min_kt": req.cas_min_kt, "cas_max_kt": req.cas_max_kt,
        "radius_m": req.radius_m, "altitude_m": req.altitude_m, "duration_s": req.duration_s,
        "bank_max_deg": req.bank_max_deg, "wind_speed_mps": req.wind_speed_mps,
        "wind_from_deg": req.wind_from_deg, "roll_rate_max_dps": req.roll_rate_max_dps,
        "accel_max_mps2": req.accel_max_mps2, "turn": req.turn, "margin_m": req.margin_m,
    }
    if req.profile == "step-pause":
        settings["levels"] = req.levels
    if req.profile == "continuous":
        settings["return_leg"] = req.return_leg
    if schedule.levels_qc_pa:
        settings["levels_qc_pa"] = [round(q, 3) for q in schedule.levels_qc_pa]
    settings["coverage_runs"] = [[list(run) for run in runs] for runs in schedule.groups]
    settings.update(extra)
    return Plan(time_s=schedule.time_s, north_m=sol.north_m, east_m=sol.east_m,
                alt_m=np.full(schedule.time_s.size, req.altitude_m),
                heading_deg=np.degrees(sol.heading_rad), bank_deg=np.degrees(sol.bank_rad),
                tas_mps=schedule.tas_mps, cas_mps=schedule.cas_mps, qc_pa=schedule.qc_pa,
                settings=settings, success=sol.success, message=sol.message,
                iterations=sol.iterations)


def plan_maneuver(request=None, *positional, **overrides):
    """Plan a calibration maneuver: fixed q(t) schedule, optimised lateral path.

    Parameters
    ----------
    request : PlanRequest, optional
        What to plan (maneuvers.plan.request.PlanRequest, every field checked when it is made;
        defaults: the paper's T-2 case). For compatibility the first arguments may also be
        given in their old positional order: ``plan_maneuver("two-speed", 70, 90)`` (profile,
        cas_min_kt, cas_max_kt, radius_m, altitude_m, duration_s, bank_max_deg,
        wind_speed_mps, wind_from_deg).
    **overrides
        Fields of `PlanRequest` by name (``cas_min_kt=60``, ``design="optimal"``, ...), put
        into `request`: with both, the overrides win. An unknown name is a TypeError.

    Returns
    -------
    pitotcal.core.plan.Plan
        Nodes of the plan (time_s, north_m, east_m, alt_m, heading_deg unwrapped, bank_deg,
        tas_mps, cas_mps, qc_pa) with the request in ``settings`` and IPOPT's outcome in
        ``success``, ``message``, ``iterations`` (``success=False`` with a warning when the
        last solve does not converge: see `check_converged`).

    Raises
    ------
    PlanInfeasibleError
        A request that cannot be met; the message names the constraint and a value that works.
    PitotcalError
        A malformed argument, or IPOPT failing in a way that proves nothing about the request
        (e.g. its iteration limit): the message says what failed and what to change.

    Example
    -------
    >>> plan = plan_maneuver()           # the T-2 case: 70-100 KCAS, 926 m, 240 s
    >>> plan.success, plan.n
    (True, 241)
    >>> plan = plan_maneuver(PlanRequest(profile="two-speed", radius_m=600.0), turn="left")
    """
    asked = plan_request(request, positional, overrides)
    req = working_request(asked)
    options = asked.design_options
    schedule, req, extra = _feasible_schedule(req, options)
    sol = _solve(req, schedule, asked.ipopt_options)
    if options is not None:
        from .design_request import record_prediction
        extra = record_prediction(extra, schedule, sol, req, options)
        design = options
        for _ in range(_TARGET_ROUNDS):
            # the duration was chosen on the speed design's assumed headings; the path the
            # wind and the turn give may predict a little worse: design again with that margin
            if (design := _target_margin(extra, design)) is None:
                break
            schedule, req, extra = _feasible_schedule(working_request(asked), design)
            sol = _solve(req, schedule, asked.ipopt_options)
            extra = record_prediction({**extra, "target_2sigma_kt": options.target_2sigma_kt},
                                      schedule, sol, req, options)
        _warn_target_missed(extra, req.duration_s)
    return _build_plan(req, schedule, sol, extra)


# Re-designs allowed for `target_2sigma_kt` when the path misses it, and the margin added to
# the shortfall each time (the path's prediction moves by about a percent between designs).
_TARGET_ROUNDS = 3
_TARGET_MARGIN = 0.01


def _target_margin(settings, design):
    """`design` (DesignOptions) with its target tightened by the path's shortfall and
    `_TARGET_MARGIN`, or None when the path planned meets `target_2sigma_kt` (or none was
    asked)."""
    target, got = settings.get("target_2sigma_kt"), settings.get("predicted_dv_2sigma_kt")
    if target is None or got is None or got <= target:
        return None
    return replace(design, target_2sigma_kt=design.target_2sigma_kt * target / got
                   * (1.0 - _TARGET_MARGIN))


def _warn_target_missed(settings, duration_s):
    """Say when the path planned still predicts a worse 2σ than `target_2sigma_kt` asked for,
    with the duration that 2σ ~ 1/√T says meets it."""
    target, got = settings.get("target_2sigma_kt"), settings.get("predicted_dv_2sigma_kt")
    if target is None or got is None or got <= target:
        return
    longer = int(np.ceil(duration_s * (got / target) ** 2)) + 1
    warnings.warn(f"target_2sigma_kt {target:g} kt is not met: the path planned predicts "
                  f"{got:.3g} kt in {duration_s:g} s; a plan of duration_s {longer} s without "
                  "the target should meet it", stacklevel=3)
