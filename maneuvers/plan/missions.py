"""Export a plan as an autopilot mission: loiter circles at the test-area centre with airspeed
changes, as stock ArduPilot and PX4 fly them.

The mission is what a loitering autopilot flies: a ground-referenced circle of the plan's
radius in the plan's wind, at the plan's airspeeds. Before writing, two checks:

- the downwind bank, tan(bank) = V_g,max^2 / (g R) with V_g,max = V_t,max + wind, within
  the plan's bank limit;
- the heading coverage: a full circle turns through every heading, but each coverage group
  of the plan (each third of the q range, or each dwell of a two-level plan) lasts a fixed
  time, and the circle must turn the air-relative heading through 360° within it.

Each refusal names the radius (or duration) that works.
"""

import math
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np

from pitotcal.core.airdata import cas_from_qc_mps
from pitotcal.core.checks import choice, number
from pitotcal.core.dynamics import ground_speed_on_track_mps
from pitotcal.core.errors import PlanInfeasibleError
from pitotcal.core.geo import check_lat_lon
from pitotcal.core.plan import Plan
from pitotcal.core.scenario import CAS_TOLERANCE_KT
from pitotcal.core.speeds import cas_from_tas_mps, qc_from_tas_isa_pa, tas_from_cas_mps
from pitotcal.core.units import G0_MPS2, mps_to_kt, wind_vector_mps
from pitotcal.io.mission_files import (
    FRAME_GLOBAL,
    FRAME_GLOBAL_RELATIVE_ALT,
    FRAME_MISSION,
    MAV_CMD,
    MissionItem,
    write_qgc_plan,
    write_qgc_wpl,
)

from .export_checks import check_exportable_turn, check_ground_clearance

__all__ = ["ALTITUDE_REFS", "AUTOPILOTS", "MIN_STEP_S", "Mission", "build_mission",
           "check_loiter", "export_mission", "loiter_plan", "mission_path", "speed_levels",
           "write_mission"]

AUTOPILOTS = ("ardupilot", "px4")
ALTITUDE_REFS = ("msl", "agl")
_SUFFIX = {"ardupilot": ".waypoints", "px4": ".plan"}
# Shortest staircase step: an autopilot's airspeed loop settles in a few seconds.
MIN_STEP_S = 10.0


@dataclass(frozen=True)
class Mission:
    """A plan as mission items.

    Attributes
    ----------
    home : MissionItem
        The planned home position (the centre; the autopilot replaces it when it arms).
    items : tuple of MissionItem
        DO_CHANGE_SPEED, NAV_LOITER_TIME pairs, one per speed level.
    cas_mps, loiter_s : tuple
        Each level's calibrated airspeed (m/s) and loiter time (whole seconds).
    radius_m : float
        Loiter radius, signed: positive clockwise (right turns), negative counter-clockwise.
    staircase_error_kt : float or None
        Continuous plans: the largest difference between the staircase and the ramp, KCAS.
    downwind_bank_deg, heading_turn_deg : float
        The loiter's downwind bank and the least air-heading turn of any coverage group.
    """

    home: MissionItem
    items: tuple
    cas_mps: tuple
    loiter_s: tuple
    radius_m: float
    altitude_ref: str
    staircase_error_kt: object
    downwind_bank_deg: float
    heading_turn_deg: float

    def summary(self):
        """One line: levels, speeds, loiter radius and direction, altitude frame, checks."""
        kt = ", ".join(f"{mps_to_kt(v):.1f}" for v in self.cas_mps)
        way = "clockwise" if self.radius_m > 0 else "counter-clockwise"
        stair = ("" if self.staircase_error_kt is None else
                 f" (staircase within {self.staircase_error_kt:.1f} kt of the ramp)")
        return (f"mission: {len(self.cas_mps)} speed levels {kt} KCAS{stair}, loiter "
                f"{abs(self.radius_m):g} m {way} at {self.items[1].alt_m:g} m "
                f"{self.altitude_ref.upper()}, downwind bank {self.downwind_bank_deg:.0f}°, "
                f"least heading turn {self.heading_turn_deg:.0f}° per coverage group")


def _whole_seconds(bounds_s):
    """Durations between boundaries rounded to whole seconds (ArduPilot stores loiter time as
    an integer), rounding the cumulative times so the total stays the plan's."""
    edges = np.round(np.asarray(bounds_s, dtype=float))
    return tuple(int(d) for d in np.diff(edges))


def _stepped_levels(plan):
    """The plan's own levels; level i lasts from the end of dwell i-1 (the autopilot ramps
    during the loiter that follows a speed change) to the end of dwell i."""
    levels = plan.settings["levels_qc_pa"]
    ends, start = [], 0
    for q, following in pairwise(levels):
        # in flying order (a designed plan may come back to a level): the end of this dwell
        # is the last node at q before the first node at the next level
        at = np.isclose(plan.qc_pa, q, rtol=1e-6, atol=1e-3)
        nxt = start + np.flatnonzero(np.isclose(plan.qc_pa[start:], following, rtol=1e-6,
                                                atol=1e-3))[0]
        last = np.flatnonzero(at[:nxt])[-1]
        ends.append(plan.time_s[last])
        start = nxt
    bounds = [plan.time_s[0], *ends, plan.time_s[-1]]
    return tuple(float(cas_from_qc_mps(q)) for q in levels), _whole_seconds(bounds), None


def _staircase(plan, n):
    """n equal-time steps; each holds the CAS of the plan's q at the step's middle (for q
    linear in time, the step's mean q), and its worst difference from the ramp, KCAS."""
    t = plan.time_s
    bounds = np.linspace(t[0], t[-1], n + 1)
    q_mid = np.interp(0.5 * (bounds[1:] + bounds[:-1]), t, plan.qc_pa)
    cas = cas_from_qc_mps(q_mid)
    cas_edges = cas_from_qc_mps(np.interp(bounds, t, plan.qc_pa))
    error = np.maximum(np.abs(cas_edges[:-1] - cas), np.abs(cas_edges[1:] - cas))
    return cas, bounds, float(mps_to_kt(error.max()))


def speed_levels(plan):
    """The mission's airspeed levels and how long each is held.

    Step-pause and two-speed: the plan's levels exactly. Continuous: a staircase of equal-time
    steps, the fewest that keep every step within half the pilot's tolerance (±2.5 of ±5 KCAS)
    of the ramp, with steps no shorter than `MIN_STEP_S` (an even number with the return leg,
    so no step straddles the turn-around).

    Returns
    -------
    cas_mps : tuple of float
    loiter_s : tuple of int
    staircase_error_kt : float or None
    """
    if plan.settings.get("levels_qc_pa"):
        return _stepped_levels(plan)
    duration = plan.time_s[-1] - plan.time_s[0]
    step = 2 if plan.settings.get("return_leg") else 1
    n_max = max(step, int(duration // MIN_STEP_S) // step * step)
    n = step
    while True:
        cas, bounds, error = _staircase(plan, n)
        if error <= CAS_TOLERANCE_KT / 2 or n + step > n_max:
            return tuple(float(v) for v in cas), _whole_seconds(bounds), error
        n += step


def _fly_circle(time_s, tas_mps, radius_m, wind_ne, track0_rad, sign=1.0):
    """Track angle and air heading (rad, unwrapped) flying a ground-fixed circle of `radius_m`
    from track `track0_rad` (a scalar, or one start per column), turning right (`sign` +1) or
    left (-1): d(chi)/dt = sign V_g(chi)/R, midpoint rule on the time grid, V_g closing the
    wind triangle with the true airspeed (one value per time)."""
    tracks = [np.asarray(track0_rad, dtype=float)]
    for k, dt in enumerate(np.diff(time_s)):
        tas, track = 0.5 * (tas_mps[k] + tas_mps[k + 1]), tracks[-1]
        half = track + sign * 0.5 * dt * ground_speed_on_track_mps(track, tas, *wind_ne) / radius_m
        tracks.append(track + sign * dt * ground_speed_on_track_mps(half, tas, *wind_ne) / radius_m)
    track = np.array(tracks)
    tas = np.asarray(tas_mps).reshape((-1,) + (1,) * (track.ndim - 1))
    vg = ground_speed_on_track_mps(track, tas, *wind_ne)
    heading = np.unwrap(np.arctan2(vg * np.sin(track) - wind_ne[1],
                                   vg * np.cos(track) - wind_ne[0]), axis=0)
    return track, heading


def _heading_turns_rad(plan, radius_m, wind_ne, n_phases=8):
    """The least air-heading turn of each coverage group of a loiter circle of `radius_m`,
    over `n_phases` start points on the circle (the turn depends a little on where the
    circle is joined)."""
    start = np.linspace(0.0, 2 * np.pi, n_phases, endpoint=False)
    _, heading = _fly_circle(plan.time_s, plan.tas_mps, radius_m, wind_ne, start)
    runs = plan.settings.get("coverage_runs") or [[[0, plan.n - 1]]]
    return [float(min(sum(heading[b] - heading[a] for a, b in group)))
            for group in runs]


def _coverage_radius_m(plan, radius_m, wind_ne):
    """The largest radius (whole metres) whose circle turns 360° in every coverage group: the
    turn goes as 1/R, so a few rescalings and a last check find it."""
    r = radius_m
    for _ in range(4):
        r *= min(_heading_turns_rad(plan, r, wind_ne)) / (2 * np.pi)
    r = math.floor(r)
    while min(_heading_turns_rad(plan, r, wind_ne)) < 2 * np.pi and r > 1:
        r = math.floor(0.99 * r)
    return r


def check_loiter(plan):
    """The loiter circle's downwind bank (deg) and least air-heading turn per coverage group
    (deg); PlanInfeasibleError naming the radius (or duration) that works when the bank
    exceeds the plan's limit or a group turns less than 360°.

    Notes
    -----
    tan(bank) = V_g,max^2 / (g R), V_g,max = V_t,max + wind: the bank of a steady circle at
    the highest ground speed, downwind at the fastest airspeed.
    """
    s = plan.settings
    check_exportable_turn(s.get("turn", "right"))
    radius, wind = float(s["radius_m"]), float(s["wind_speed_mps"])
    bank_max = float(s["bank_max_deg"])
    vg_max = float(np.max(plan.tas_mps)) + wind
    bank = math.degrees(math.atan(vg_max ** 2 / (G0_MPS2 * radius)))
    need = math.ceil(vg_max ** 2 / (G0_MPS2 * math.tan(math.radians(bank_max))))
    if bank > bank_max:
        raise PlanInfeasibleError(
            f"radius_m {radius:g} m is too small for a loiter: circling it downwind at "
            f"{vg_max:.1f} m/s ground speed ({mps_to_kt(np.max(plan.tas_mps)):.0f} KTAS in "
            f"{wind:g} m/s wind) banks {bank:.0f}°, over bank_max_deg {bank_max:g}°: export "
            f"a plan with radius_m at least {need} m", param="radius_m",
            mentions=("bank_max_deg",))
    wind_ne = tuple(float(w) for w in wind_vector_mps(wind, s["wind_from_deg"]))
    turn = min(_heading_turns_rad(plan, radius, wind_ne))
    if turn < 2 * np.pi:
        # two coverage groups: two-speed's dwells or a designed plan's end levels
        where = "dwell" if len(s.get("coverage_runs") or ()) == 2 else "third of the q range"
        fits = _coverage_radius_m(plan, radius, wind_ne)
        head = (f"a {radius:g} m loiter circle turns only {math.degrees(turn):.0f}° of heading "
                f"in one {where}")
        if fits >= need:
            raise PlanInfeasibleError(f"radius_m {radius:g} m: {head}; export a plan with "
                                      f"radius_m {need}-{fits} m", param="radius_m")
        longer = math.ceil(1.02 * float(s["duration_s"]) * need / fits)
        raise PlanInfeasibleError(
            f"duration_s {s['duration_s']:g} s: {head}, and no radius both turns 360° in each "
            f"{where} and keeps the downwind bank within {bank_max:g}° (at least {need} m): "
            f"export a plan with radius_m {need} m and duration_s {longer} s or more",
            param="duration_s", mentions=("radius_m",))
    return bank, math.degrees(turn)


def build_mission(plan, center_lat_deg, center_lon_deg, *, altitude_ref="msl",
                  ground_elevation_m=None):
    """The plan as mission items at the test-area centre (after `check_loiter`).

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
        A plan with its settings (radius_m, turn, wind, bank_max_deg, altitude_m...).
    center_lat_deg, center_lon_deg : float
        The test-area centre, degrees (WGS-84), latitude in [-90, 90], longitude in [-180, 180).
    altitude_ref : {"msl", "agl"}
        "msl": the loiters at the plan's altitude above mean sea level (MAV_FRAME_GLOBAL) - the
        altitude whose ISA pressure and temperature the plan's true airspeeds use; "agl": the
        same number above home (MAV_FRAME_GLOBAL_RELATIVE_ALT).
    ground_elevation_m : float, optional
        The ground at the centre, m above mean sea level: a loiter less than
        `MIN_CLEARANCE_M` above it is refused; without it an "msl" mission is a warning
        (`check_ground_clearance`). With "agl" the plan's altitude is above mean sea level
        (its ISA air; `pitotcal plan` adds the ground's elevation to --altitude-m) and the
        mission's loiter altitude is that minus the ground's elevation.

    Returns
    -------
    Mission
        Home at the centre, then per speed level a DO_CHANGE_SPEED (param1 0: airspeed,
        param2 CAS m/s, param3 -1: throttle unchanged) and a NAV_LOITER_TIME (param1 seconds,
        param3 the signed radius, at the centre and altitude).
    """
    lat, lon = check_lat_lon(center_lat_deg, center_lon_deg)
    altitude_ref = choice("altitude_ref", altitude_ref, ALTITUDE_REFS)
    if ground_elevation_m is not None:
        ground_elevation_m = number("ground_elevation_m", ground_elevation_m, -500.0, 9000.0)
    bank, turn = check_loiter(plan)
    s = plan.settings
    # the plan flies at its altitude above mean sea level (its ISA air); an "agl" mission
    # counts from home, the ground's elevation below it
    alt = float(s["altitude_m"])
    if altitude_ref == "agl" and ground_elevation_m is not None:
        alt -= ground_elevation_m
    check_ground_clearance(alt if altitude_ref == "agl" else float(s["altitude_m"]),
                           altitude_ref, ground_elevation_m)
    radius = float(s["radius_m"]) * (1.0 if s.get("turn", "right") == "right" else -1.0)
    frame = FRAME_GLOBAL if altitude_ref == "msl" else FRAME_GLOBAL_RELATIVE_ALT
    cas, loiter_s, error = speed_levels(plan)
    items = []
    for v, t in zip(cas, loiter_s):
        items.append(MissionItem(MAV_CMD["DO_CHANGE_SPEED"], FRAME_MISSION, (0.0, v, -1.0, 0.0)))
        items.append(MissionItem(MAV_CMD["NAV_LOITER_TIME"], frame, (float(t), 0.0, radius, 0.0),
                                 lat, lon, alt))
    home = MissionItem(MAV_CMD["NAV_WAYPOINT"], FRAME_GLOBAL, lat_deg=lat, lon_deg=lon)
    return Mission(home=home, items=tuple(items), cas_mps=cas, loiter_s=loiter_s,
                   radius_m=radius, altitude_ref=altitude_ref, staircase_error_kt=error,
                   downwind_bank_deg=bank, heading_turn_deg=turn)


def mission_path(plan_csv, autopilot):
    """Where the mission goes beside PLAN.csv: PLAN.waypoints (ardupilot), PLAN.plan (px4)."""
    autopilot = choice("autopilot", autopilot, AUTOPILOTS)
    return Path(plan_csv).with_suffix(_SUFFIX[autopilot])


def export_mission(plan, path, autopilot, center_lat_deg, center_lon_deg, *,
                   altitude_ref="msl", ground_elevation_m=None):
    """Check the loiter, build the mission and write it; returns the `Mission`.

    `autopilot` "ardupilot" writes QGC WPL 110 text (Mission Planner, MAVProxy), "px4" a
    QGroundControl .plan JSON. Raises PlanInfeasibleError (see `check_loiter`,
    `check_ground_clearance`) or PitotcalError for a bad centre or choice, before writing
    anything.

    Example
    -------
    >>> from pitotcal.maneuvers.plan.planner import plan_maneuver
    >>> plan = plan_maneuver("two-speed", radius_m=600.0)
    >>> m = export_mission(plan, "/tmp/p.waypoints", "ardupilot", 47.4, 8.55,
    ...                    ground_elevation_m=0.0)
    >>> [round(float(mps_to_kt(v))) for v in m.cas_mps], m.loiter_s
    ([70, 100], (112, 128))
    """
    autopilot = choice("autopilot", autopilot, AUTOPILOTS)
    mission = build_mission(plan, center_lat_deg, center_lon_deg, altitude_ref=altitude_ref,
                            ground_elevation_m=ground_elevation_m)
    write_mission(mission, path, autopilot)
    return mission


def write_mission(mission, path, autopilot):
    """Write a built `Mission` in the `autopilot`'s format; returns the path."""
    if choice("autopilot", autopilot, AUTOPILOTS) == "ardupilot":
        return write_qgc_wpl(path, mission.home, mission.items)
    return write_qgc_plan(path, mission.home, mission.items, cruise_speed_mps=mission.cas_mps[0])




def loiter_plan(plan, mission, *, start_deg=0.0):
    """What the autopilot flies for `mission`, as a `Plan` the simulator can follow: the
    ground-referenced circle at the centre, the speed levels with each change flown at the
    plan's acceleration limit.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
        The plan the mission was built from (wind, altitude, limits, time grid).
    mission : Mission
        From `build_mission`.
    start_deg : float
        Bearing from the centre where the circle is joined, degrees true.

    Notes
    -----
    Track angle chi on the circle: d(chi)/dt = +-V_g(chi)/R, V_g the ground speed whose air
    velocity closes the wind triangle; heading psi = the air velocity's direction; bank
    phi = atan(V_t psi_dot / g) (coordinated turn).
    """
    s = plan.settings
    t = plan.time_s
    radius, sign = abs(mission.radius_m), math.copysign(1.0, mission.radius_m)
    wind_ne = tuple(float(w) for w in wind_vector_mps(s["wind_speed_mps"], s["wind_from_deg"]))
    alt_m = float(np.mean(plan.alt_m))
    # the commanded level at each node, then the speed the autopilot reaches at accel_max
    edges = np.cumsum(mission.loiter_s)
    level = tas_from_cas_mps(
        np.asarray(mission.cas_mps)[np.minimum(np.searchsorted(edges, t, side="right"),
                                               len(edges) - 1)], alt_m)
    tas = np.empty_like(t)
    tas[0] = level[0]
    step = float(s.get("accel_max_mps2", 1.0)) * np.diff(t)
    for k in range(t.size - 1):
        tas[k + 1] = tas[k] + np.clip(level[k] - tas[k], -step[k], step[k])
    track, heading = _fly_circle(t, tas, radius, wind_ne,
                                 math.radians(start_deg) + sign * np.pi / 2, sign)
    bearing = track - sign * np.pi / 2
    bank = np.arctan(tas * np.gradient(heading, t) / G0_MPS2)
    cas = cas_from_tas_mps(tas, alt_m)
    return Plan(time_s=t.copy(), north_m=radius * np.cos(bearing),
                east_m=radius * np.sin(bearing), alt_m=plan.alt_m.copy(),
                heading_deg=np.degrees(heading), bank_deg=np.degrees(bank), tas_mps=tas,
                cas_mps=cas, qc_pa=qc_from_tas_isa_pa(tas, alt_m), settings=dict(s),
                message="loiter flown by an autopilot")
