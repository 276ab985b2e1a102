"""Airspeed schedules of the calibration maneuvers: the q(t) law the planner holds exactly.

Three profiles (paper section IV, Fig. 9):

- ``continuous`` - impact pressure linear in time from q(cas_min) to q(cas_max), so q is
  uniformly distributed over the maneuver and airspeed is non-linear in time; optionally back
  down again (``return_leg=True``: a triangle in q, which cancels pneumatic-lag effects).
- ``step-pause`` - ``levels`` levels equally spaced in q, each held for the same dwell,
  joined by ramps at the acceleration limit.
- ``two-speed`` - the S-2 flight: a dwell at cas_min, one ramp, a dwell at cas_max.

"KCAS" is calibrated airspeed by the standard law (`pitotcal.core.speeds`): q is the isentropic
impact pressure of the true airspeed at the plan altitude's ISA p_s and T, CAS its
airspeed-indicator reading, so a pilot's card and the plan's q_c agree at any altitude.

The time grid is uniform inside each dwell and each ramp, with nodes exactly at every ramp
start and end: docs/measured.md found q errors of ~30 Pa when a ramp corner falls between nodes.
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core.errors import PitotcalError, PlanInfeasibleError
from pitotcal.core.plan import PROFILES
from pitotcal.core.airdata import cas_from_qc_mps, qc_from_cas_pa
from pitotcal.core.speeds import qc_from_tas_isa_pa, qc_slope_per_tas, tas_from_qc_mps
from pitotcal.core.units import isa_density_kgm3

__all__ = ["PROFILES", "Schedule", "coverage_groups", "dwell_schedule", "make_schedule"]


@dataclass(frozen=True)
class Schedule:
    """An airspeed schedule on the planner's time grid (N intervals, N + 1 nodes).

    Attributes
    ----------
    profile : str
    time_s, cas_mps, tas_mps, qc_pa : ndarray (N + 1,)
        Node times and the target airspeeds / impact pressure at each node: CAS by the
        standard law, TAS and the isentropic q_c at the plan altitude (`core.speeds`).
    accel_mps2 : ndarray (N,)
        True-airspeed acceleration on each interval; TAS is linear inside an interval, so the
        point-mass model reproduces the node speeds exactly.
    groups : tuple of tuple of (int, int)
        Heading-coverage groups: each group is a tuple of node ranges (first, last); the
        heading must turn through 360 deg (summed over the ranges) inside each group.
    levels_qc_pa : tuple of float
        Dwell levels (step-pause, two-speed); empty for continuous.
    rho_kgm3 : float
        ISA density at the plan altitude.
    altitude_m : float
        The plan altitude, where TAS and q_c convert.
    """

    profile: str
    time_s: np.ndarray
    cas_mps: np.ndarray
    tas_mps: np.ndarray
    qc_pa: np.ndarray
    accel_mps2: np.ndarray
    groups: tuple
    levels_qc_pa: tuple
    rho_kgm3: float
    altitude_m: float

    @property
    def n_intervals(self):
        return int(self.time_s.size - 1)


def _runs(mask):
    """Contiguous runs of True in `mask`, as (first, last) node index pairs."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return ()
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.r_[idx[0], idx[breaks + 1]]
    ends = np.r_[idx[breaks], idx[-1]]
    return tuple((int(a), int(b)) for a, b in zip(starts, ends))


def coverage_groups(qc_pa, n_groups=3):
    """Node runs of each third (or `n_groups`-th) of the q range.

    Parameters
    ----------
    qc_pa : array_like (M,)
        Target impact pressure at each sample.
    n_groups : int

    Returns
    -------
    tuple of tuple of (int, int)
        For each part of the q range, the contiguous (first, last) index runs that lie in it;
        a sample on a boundary belongs to the upper part (the top value to the last part).
    """
    q = np.asarray(qc_pa, dtype=float)
    lo, hi = q.min(), q.max()
    # the tiny offset puts a level that sits exactly on a boundary in the part above it
    part = np.clip(np.floor(n_groups * (q - lo) / (hi - lo) + 1e-9), 0, n_groups - 1)
    return tuple(_runs(part == j) for j in range(n_groups))


def _segment_grid(durations, dt_s):
    """Node times of consecutive segments, uniform inside each, nodes at every corner."""
    times, counts = [0.0], []
    for seg in durations:
        n = max(1, round(seg / dt_s))
        times.extend(times[-1] + seg * np.arange(1, n + 1) / n)
        counts.append(n)
    return np.asarray(times), counts


def _continuous_q(q_range, altitude_m, duration_s, accel_max_mps2, dt_s, return_leg):
    """Node times and q of the continuous profile: q linear in time (up, or up and down)."""
    q_min, q_max = q_range
    legs = 2 if return_leg else 1
    # dq_c/dV_t grows with V_t, so a uniform-q ramp accelerates hardest at the slowest speed:
    # dV_t/dt = (dq/dt) / (dq_c/dV_t)
    slope = float(qc_slope_per_tas(tas_from_qc_mps(q_min, altitude_m), altitude_m))
    need_s = legs * (q_max - q_min) / (slope * accel_max_mps2)
    if duration_s < need_s:
        raise PlanInfeasibleError(
            f"duration_s {duration_s:g} s is too short for the {accel_max_mps2:g} m/s^2 "
            f"acceleration limit: needs at least {np.ceil(need_s):.0f} s", param="duration_s")
    n = max(2 * legs, round(duration_s / dt_s))
    time_s = np.linspace(0.0, duration_s, n + 1)
    frac = time_s / duration_s
    if return_leg:
        frac = 1.0 - np.abs(1.0 - 2.0 * frac)
    return time_s, q_min + (q_max - q_min) * frac


def _stepped_q(q_range, levels, duration_s, altitude_m, accel_max_mps2, dt_s):
    """Node times, q and the levels of a stepped profile: equal dwells at levels equally
    spaced in q, joined by ramps at the acceleration limit (TAS linear in time)."""
    q_min, q_max = q_range
    n_levels = int(levels)
    if n_levels < 2:
        raise PitotcalError(f"levels {levels} must be at least 2", param="levels")
    level_q = q_min + (q_max - q_min) * np.arange(n_levels) / (n_levels - 1)
    return _dwell_q(level_q, np.full(n_levels, 1.0 / n_levels), duration_s, altitude_m,
                    accel_max_mps2, dt_s)


def _dwell_q(level_q, fractions, duration_s, altitude_m, accel_max_mps2, dt_s):
    """Node times, q and the levels of dwells at `level_q` (in flying order, repeats allowed)
    sharing the time the ramps leave in proportion to `fractions`, joined by ramps at the
    acceleration limit (TAS linear in time)."""
    level_q = np.asarray(level_q, dtype=float)
    n_levels = level_q.size
    level_tas = tas_from_qc_mps(level_q, altitude_m)
    ramps = np.abs(np.diff(level_tas)) / accel_max_mps2
    dwells = (duration_s - ramps.sum()) * np.asarray(fractions, dtype=float) / np.sum(fractions)
    # a dwell shorter than one node spacing is no dwell at all
    if dwells.min() < dt_s:
        need_s = ramps.sum() + dt_s * np.sum(fractions) / np.min(fractions)
        raise PlanInfeasibleError(
            f"duration_s {duration_s:g} s is too short for {n_levels} levels at the "
            f"{accel_max_mps2:g} m/s^2 acceleration limit: needs at least "
            f"{np.ceil(need_s):.0f} s", param="duration_s")
    segments = [dwells[0]]
    for ramp, dwell in zip(ramps, dwells[1:]):
        segments += [ramp, dwell]
    time_s, counts = _segment_grid(segments, dt_s)
    qc = np.empty_like(time_s)
    qc[0] = level_q[0]
    node = 1
    for i, count in enumerate(counts):
        seg = i // 2
        if i % 2 == 0:           # dwell
            qc[node:node + count] = level_q[seg]
        else:                    # ramp: TAS linear in time at the acceleration limit
            tas = np.linspace(level_tas[seg], level_tas[seg + 1], count + 1)[1:]
            qc[node:node + count] = qc_from_tas_isa_pa(tas, altitude_m)
        node += count
    return time_s, qc, tuple(float(v) for v in level_q)


def dwell_schedule(level_q, fractions, duration_s, *, altitude_m, accel_max_mps2=1.0,
                   dt_s=1.0, covered=None, profile="optimal"):
    """A schedule of dwells at given impact pressures, in flying order (the designed ones).

    Parameters
    ----------
    level_q : sequence of float
        Dwell levels, Pa, in the order flown; a level may come back (a later dwell).
    fractions : sequence of float
        Share of the dwell time (what the ramps at `accel_max_mps2` leave) of each dwell.
    duration_s : float
    altitude_m, accel_max_mps2, dt_s :
        As `make_schedule`.
    covered : sequence of float, optional
        The levels whose dwells (together) must turn the heading through 360 deg: one coverage
        group each. Default: the lowest and the highest level.
    profile : str
        Name kept in the schedule.

    Returns
    -------
    Schedule
        ``levels_qc_pa`` is the flying order of the dwells.
    """
    time_s, qc, level_q = _dwell_q(level_q, fractions, duration_s, altitude_m,
                                   accel_max_mps2, dt_s)
    covered = (min(level_q), max(level_q)) if covered is None else covered
    groups = tuple(_runs(np.isclose(qc, q, rtol=1e-9, atol=1e-6)) for q in covered)
    return _schedule(profile, time_s, qc, groups, level_q, altitude_m)


def _schedule(profile, time_s, qc, groups, level_q, altitude_m):
    """The `Schedule` of node times and q: CAS by the standard law, TAS at the altitude."""
    tas = tas_from_qc_mps(qc, altitude_m)
    return Schedule(profile=profile, time_s=time_s, cas_mps=cas_from_qc_mps(qc), tas_mps=tas,
                    qc_pa=qc, accel_mps2=np.diff(tas) / np.diff(time_s), groups=groups,
                    levels_qc_pa=level_q, rho_kgm3=float(isa_density_kgm3(altitude_m)),
                    altitude_m=float(altitude_m))


def make_schedule(profile, cas_min_mps, cas_max_mps, duration_s, *, altitude_m,
                  accel_max_mps2=1.0, dt_s=1.0, levels=4, return_leg=False):
    """Build the q(t) schedule of a profile on the planner's time grid.

    Parameters
    ----------
    profile : {"continuous", "step-pause", "two-speed"}
    cas_min_mps, cas_max_mps : float
        Calibrated airspeed range, m/s.
    duration_s : float
        Total maneuver time, s.
    altitude_m : float
        Plan altitude; the ISA p_s and T there convert CAS to TAS (`core.speeds`).
    accel_max_mps2 : float
        Acceleration limit; step-pause ramps fly at exactly this value.
    dt_s : float
        Nominal node spacing, s.
    levels : int
        Number of q levels of the step-pause profile (two-speed always has 2).
    return_leg : bool
        Continuous profile only: go back down to cas_min in the second half.

    Returns
    -------
    Schedule

    Raises
    ------
    PlanInfeasibleError
        When the duration cannot fit the ramps at the acceleration limit; the message gives
        the shortest duration that does.

    Notes
    -----
    Continuous: q(t) = q_min + (q_max - q_min) t / T, CAS = a0 sqrt(5 [(q/p0 + 1)^(2/7) - 1])
    (`core.airdata.cas_from_qc_mps`). Step-pause: level
    i has q_i = q_min + i (q_max - q_min) / (levels - 1); each ramp takes
    (V_{i+1} - V_i) / accel_max (TAS) and the dwells share the rest of the duration equally.

    Example
    -------
    >>> s = make_schedule("continuous", 36.0, 51.4, 240.0, altitude_m=244.0)
    >>> s.n_intervals
    240
    """
    if profile not in PROFILES:
        raise PitotcalError(f"profile {profile!r} is not one of {', '.join(PROFILES)}",
                            param="profile")
    q_range = (float(qc_from_cas_pa(cas_min_mps)), float(qc_from_cas_pa(cas_max_mps)))
    if profile == "continuous":
        time_s, qc = _continuous_q(q_range, altitude_m, duration_s, accel_max_mps2, dt_s,
                                   return_leg)
        level_q = ()
    else:
        time_s, qc, level_q = _stepped_q(q_range, 2 if profile == "two-speed" else levels,
                                         duration_s, altitude_m, accel_max_mps2, dt_s)
    if len(level_q) == 2:
        # S-2 style (two-speed, or step-pause with 2 levels): the middle third of the q range
        # is only the ramp, whose length no duration changes; cover each dwell instead
        groups = tuple((run,) for run in _runs(np.isclose(qc, level_q[0]))[:1]
                       + _runs(np.isclose(qc, level_q[-1]))[-1:])
    else:
        groups = coverage_groups(qc)
    return _schedule(profile, time_s, qc, groups, level_q, altitude_m)
