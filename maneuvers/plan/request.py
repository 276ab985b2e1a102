"""The planner's request: `PlanRequest`, every field of it checked (PitotcalError naming it)
when it is made, before any work; the planner's working copy of it; the node-count limit of
the path OCP."""

import logging
from dataclasses import dataclass, fields

import numpy as np
from .ocp import TURNS
from .profiles import make_schedule

from pitotcal.core.checks import (
    choice,
    exact,
    integer,
    number,
    option_dict,
    positive,
    round_to_limit,
    with_overrides,
)
from pitotcal.core.dynamics import Limits
from pitotcal.core.errors import PitotcalError, PlanInfeasibleError
from pitotcal.core.plan import ALTITUDE_RANGE_M, PROFILES
from pitotcal.core.scenario import T2_PLAN
from pitotcal.core.airdata import A0_MPS
from pitotcal.core.units import KT_TO_MPS, kt_to_mps

__all__ = ["DESIGNS", "MAX_DURATION_S", "MAX_ITER", "MAX_NODES", "PlanRequest", "check_node_count",
           "min_dt_s", "plan_request", "working_request"]

log = logging.getLogger(__name__)

CAS_MAX_KT = A0_MPS / KT_TO_MPS      # 661.5 kt: the CAS of Mach 1
# A calibration circle is flown in a few minutes: 20 km is a 50-min orbit at 100 kt
MAX_RADIUS_M = 20000.0

# IPOPT's time grows a little faster than the node count (measured: 240 nodes 0.2 s, 1,200 6 s,
# 2,400 19 s, 24,000 more than 5 min); beyond this a plan is refused with the dt_s that works.
MAX_NODES = 3000
# The longest maneuver planned, s (4 h).
MAX_DURATION_S = 14400.0
# IPOPT's iteration limit: the T-2 plans take 30-80 iterations, a 4000 s plan ~440.
MAX_ITER = 300
DESIGNS = ("paper", "optimal")

@dataclass(frozen=True)
class _Request:
    """A checked request: SI where the planner works in SI, the user's units in `settings`."""

    profile: str
    cas_min_kt: float
    cas_max_kt: float
    radius_m: float
    altitude_m: float
    duration_s: float
    bank_max_deg: float
    wind_speed_mps: float
    wind_from_deg: float
    roll_rate_max_dps: float
    accel_max_mps2: float
    levels: int
    return_leg: bool
    turn: str
    dt_s: float
    margin_m: float
    heading_margin_rad: float
    max_iter: int

    @property
    def bank_max_rad(self):
        return np.radians(self.bank_max_deg)

    @property
    def coverage_rad(self):
        """The heading change each coverage group must turn through."""
        return 2 * np.pi + self.heading_margin_rad

    def schedule(self, duration_s=None):
        return make_schedule(self.profile, kt_to_mps(self.cas_min_kt),
                             kt_to_mps(self.cas_max_kt), self.duration_s
                             if duration_s is None else duration_s,
                             altitude_m=self.altitude_m, accel_max_mps2=self.accel_max_mps2,
                             dt_s=self.dt_s, levels=self.levels, return_leg=self.return_leg)


@dataclass(frozen=True)
class PlanRequest:
    """What `plan_maneuver(request)` plans: each field checked when the object is made, a
    `PitotcalError` naming the field (the command line shows its flag, ``--cas-min-kt``).

    Defaults are the paper's T-2 case (pitotcal.core.scenario.T2_PLAN) and the limits of
    pitotcal.core.dynamics.Limits.

    Attributes
    ----------
    profile : {"continuous", "step-pause", "two-speed"}
        Airspeed schedule (maneuvers.plan.profiles); with design "optimal" the design's own.
    cas_min_kt, cas_max_kt : float
        Calibrated airspeed range, knots; cas_min_kt < cas_max_kt.
    radius_m : float
        Radius of the test area around its centre; the ground track stays inside it at every
        node in the given wind.
    altitude_m : float
        Constant plan altitude, -400 to 32,000 m (`ALTITUDE_RANGE_M`; the ISA there gives
        TAS from CAS).
    duration_s, bank_max_deg : float
        Maneuver length, s (at most MAX_DURATION_S); bank limit, degrees (0-75).
    wind_speed_mps, wind_from_deg : float
        Expected mean wind: speed, and the direction it blows FROM (deg true, in [0, 360)).
    roll_rate_max_dps, accel_max_mps2 : float
        Roll-rate and acceleration limits (None: `Limits`' 10 deg/s and 1 m/s²).
    levels : int
        Step-pause levels, equally spaced in q (>= 2).
    return_leg : bool
        Continuous profile: sweep back down to cas_min in the second half.
    turn : {"right", "left", "both"}
        Turn direction; "both" alternates from one coverage group to the next.
    dt_s : float
        Node spacing of the plan, s (at most half the duration).
    margin_m, heading_margin_deg : float
        Radius margin against overshoot between nodes (<= radius_m); turn beyond 360 deg
        demanded in each third of the q range.
    max_iter : int
        IPOPT's iteration limit.
    ipopt_options : dict or None
        Options passed to IPOPT on top of `max_iter`.
    design : {"paper", "optimal"}
        "optimal": the speed schedule designed for information (maneuvers.plan.design)
        replaces `profile`'s (the plan's profile is then "optimal").
    design_options : DesignOptions, dict or None
        The optimal design's options (maneuvers.plan.design_request.DesignOptions; a dict of
        some of its fields); design "optimal" only.
    """

    profile: str = T2_PLAN["profile"]
    cas_min_kt: float = T2_PLAN["cas_min_kt"]
    cas_max_kt: float = T2_PLAN["cas_max_kt"]
    radius_m: float = T2_PLAN["radius_m"]
    altitude_m: float = T2_PLAN["altitude_m"]
    duration_s: float = T2_PLAN["duration_s"]
    bank_max_deg: float = T2_PLAN["bank_max_deg"]
    wind_speed_mps: float = T2_PLAN["wind_speed_mps"]
    wind_from_deg: float = T2_PLAN["wind_from_deg"]
    roll_rate_max_dps: float | None = Limits.roll_rate_max_dps
    accel_max_mps2: float | None = Limits.accel_max_mps2
    levels: int = 4
    return_leg: bool = False
    turn: str = "right"
    dt_s: float = 1.0
    margin_m: float = 1.0
    heading_margin_deg: float = 15.0
    max_iter: int = MAX_ITER
    ipopt_options: dict | None = None
    design: str = "paper"
    design_options: object = None

    def __post_init__(self):
        for name, value in _checked_fields(self).items():
            object.__setattr__(self, name, value)


def _checked_fields(r):
    """{field: checked value} of `PlanRequest` `r` (PitotcalError naming the field)."""
    # CAS below a0 (661 kt, Mach 1 at sea level): the fastest a calibration plan is made for
    cas_min_kt, cas_max_kt = (number(name, value, 0.0, CAS_MAX_KT, lo_open=True, hi_open=True)
                              for name, value in (("cas_min_kt", r.cas_min_kt),
                                                  ("cas_max_kt", r.cas_max_kt)))
    if cas_min_kt >= cas_max_kt:
        raise PlanInfeasibleError(f"cas_min_kt {cas_min_kt:g} must be below the top of the "
                                  f"airspeed range, {cas_max_kt:g} KCAS", param="cas_min_kt")
    radius_m = number("radius_m", r.radius_m, 0.0, MAX_RADIUS_M, lo_open=True)
    duration_s = positive("duration_s", r.duration_s)
    if duration_s > MAX_DURATION_S:
        raise PitotcalError(f"duration_s {exact(duration_s)} must be <= {MAX_DURATION_S:g} s: "
                            "a calibration maneuver is minutes long, and the simulator records "
                            "at most 2.8 h at 50 Hz", param="duration_s")
    design = choice("design", r.design, DESIGNS)
    return dict(
        profile=choice("profile", r.profile, PROFILES), cas_min_kt=cas_min_kt,
        cas_max_kt=cas_max_kt, radius_m=radius_m,
        altitude_m=number("altitude_m", r.altitude_m, *ALTITUDE_RANGE_M), duration_s=duration_s,
        bank_max_deg=number("bank_max_deg", r.bank_max_deg, 0.0, 75.0, lo_open=True),
        wind_speed_mps=number("wind_speed_mps", r.wind_speed_mps, 0.0),
        wind_from_deg=number("wind_from_deg", r.wind_from_deg, 0.0, 360.0, hi_open=True),
        roll_rate_max_dps=positive("roll_rate_max_dps", Limits.roll_rate_max_dps
                                   if r.roll_rate_max_dps is None else r.roll_rate_max_dps),
        accel_max_mps2=positive("accel_max_mps2", Limits.accel_max_mps2
                                if r.accel_max_mps2 is None else r.accel_max_mps2),
        levels=integer("levels", r.levels, 2), return_leg=bool(r.return_leg),
        turn=choice("turn", r.turn, TURNS),
        dt_s=number("dt_s", r.dt_s, 0.0, duration_s / 2, lo_open=True),
        margin_m=number("margin_m", r.margin_m, 0.0, radius_m),
        heading_margin_deg=number("heading_margin_deg", r.heading_margin_deg, 0.0),
        max_iter=integer("max_iter", r.max_iter, 1),
        ipopt_options=(None if r.ipopt_options is None
                       else option_dict("ipopt_options", r.ipopt_options)),
        design=design, design_options=_checked_design_options(design, r.design_options))


def _checked_design_options(design, options):
    """The optimal design's checked `DesignOptions` (its defaults for None); with the paper
    design None, and any option given refused, naming it."""
    if design == "optimal":
        from .design_request import checked_options

        return checked_options(options)
    if options is None:
        return None
    name = min(options) if isinstance(options, dict) and options else "design_options"
    raise PitotcalError(f"{name} is for design optimal", param=name, mentions=("design",))


# The legacy positional order of `plan_maneuver`'s first arguments.
_POSITIONAL = ("profile", "cas_min_kt", "cas_max_kt", "radius_m", "altitude_m", "duration_s",
               "bank_max_deg", "wind_speed_mps", "wind_from_deg")


def plan_request(request=None, positional=(), overrides=None, *, caller="plan_maneuver"):
    """The `PlanRequest` of `plan_maneuver`'s arguments: `request` (a PlanRequest, None for the
    defaults, or the profile of the positional form ``plan_maneuver("two-speed", 70, 90)``)
    with `overrides` (a dict of its fields) put in: the overrides win."""
    overrides = dict(overrides or {})
    if isinstance(request, str):
        positional = (request, *positional)
        request = None
    if len(positional) > len(_POSITIONAL):
        raise TypeError(f"{caller}() takes at most {len(_POSITIONAL)} positional arguments "
                        f"({', '.join(_POSITIONAL)}), got {len(positional)}")
    if positional and request is not None:
        raise TypeError(f"{caller}() takes a PlanRequest or the positional form, not both")
    for name, value in zip(_POSITIONAL, positional):
        if name in overrides:
            raise TypeError(f"{caller}() got multiple values for argument {name!r}")
        overrides[name] = value
    return with_overrides(PlanRequest, request, overrides, name="request", caller=caller)


def working_request(request):
    """The planner's working copy (`_Request`) of a checked `PlanRequest`: SI where the
    planner works in SI."""
    return _Request(**{f.name: getattr(request, f.name) for f in fields(_Request)
                       if f.name != "heading_margin_rad"},
                    heading_margin_rad=float(np.radians(request.heading_margin_deg)))


def min_dt_s(duration_s):
    """The smallest dt_s (3 significant digits) the planner takes for `duration_s`."""
    return round_to_limit(duration_s / MAX_NODES, lo=True)


def check_node_count(req):
    n_nodes = req.duration_s / req.dt_s
    if n_nodes > MAX_NODES:
        raise PitotcalError(
            f"dt_s {req.dt_s:g} s over a {req.duration_s:g} s maneuver gives {n_nodes:.0f} "
            f"plan nodes; the planner takes at most {MAX_NODES} (about half a minute): use at "
            f"least {exact(min_dt_s(req.duration_s))} s (the simulator flies between the "
            "nodes)", param="dt_s")
    if n_nodes > 1000:
        log.warning("planning %.0f nodes: this takes %.0f-%.0f s", n_nodes,
                    n_nodes / 250, n_nodes / 120)
