"""The planner's request: every argument of `plan_maneuver` checked (PitotcalError naming
it) before any work, and the node-count limit of the path OCP."""

import logging
from dataclasses import dataclass

import numpy as np
from .ocp import TURNS
from .profiles import make_schedule

from pitotcal.core.checks import choice, exact, integer, number, positive, round_to_limit
from pitotcal.core.dynamics import Limits
from pitotcal.core.errors import PitotcalError, PlanInfeasibleError
from pitotcal.core.plan import PROFILES
from pitotcal.core.units import kt_to_mps

__all__ = ["MAX_DURATION_S", "MAX_NODES", "check_node_count", "min_dt_s", "request"]

log = logging.getLogger(__name__)

# IPOPT's time grows a little faster than the node count (measured: 240 nodes 0.2 s, 1,200 6 s,
# 2,400 19 s, 24,000 more than 5 min); beyond this a plan is refused with the dt_s that works.
MAX_NODES = 3000
# The longest maneuver planned, s (4 h).
MAX_DURATION_S = 14400.0

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


def request(profile, cas_min_kt, cas_max_kt, radius_m, altitude_m, duration_s, bank_max_deg,
             wind_speed_mps, wind_from_deg, roll_rate_max_dps, accel_max_mps2, levels,
             return_leg, turn, dt_s, margin_m, heading_margin_deg, max_iter):
    """Every argument checked (PitotcalError naming it), before any work."""
    limits = Limits()
    cas_min_kt, cas_max_kt = positive("cas_min_kt", cas_min_kt), positive("cas_max_kt", cas_max_kt)
    if cas_min_kt >= cas_max_kt:
        raise PlanInfeasibleError(f"cas_min_kt {cas_min_kt:g} must be below the top of the "
                                  f"airspeed range, {cas_max_kt:g} KCAS", param="cas_min_kt")
    radius_m = positive("radius_m", radius_m)
    duration_s = positive("duration_s", duration_s)
    if duration_s > MAX_DURATION_S:
        raise PitotcalError(f"duration_s {exact(duration_s)} must be <= {MAX_DURATION_S:g} s: "
                            "a calibration maneuver is minutes long, and the simulator records "
                            "at most 2.8 h at 50 Hz", param="duration_s")
    return _Request(
        profile=choice("profile", profile, PROFILES), cas_min_kt=cas_min_kt,
        cas_max_kt=cas_max_kt, radius_m=radius_m,
        altitude_m=number("altitude_m", altitude_m, -400.0, 11000.0), duration_s=duration_s,
        bank_max_deg=number("bank_max_deg", bank_max_deg, 0.0, 75.0, lo_open=True),
        wind_speed_mps=number("wind_speed_mps", wind_speed_mps, 0.0),
        wind_from_deg=number("wind_from_deg", wind_from_deg, 0.0, 360.0, hi_open=True),
        roll_rate_max_dps=positive("roll_rate_max_dps", limits.roll_rate_max_dps
                                   if roll_rate_max_dps is None else roll_rate_max_dps),
        accel_max_mps2=positive("accel_max_mps2", limits.accel_max_mps2
                                if accel_max_mps2 is None else accel_max_mps2),
        levels=integer("levels", levels, 2), return_leg=bool(return_leg),
        turn=choice("turn", turn, TURNS),
        dt_s=number("dt_s", dt_s, 0.0, duration_s / 2, lo_open=True),
        margin_m=number("margin_m", margin_m, 0.0, radius_m),
        heading_margin_rad=np.radians(number("heading_margin_deg", heading_margin_deg, 0.0)),
        max_iter=integer("max_iter", max_iter, 1))


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
