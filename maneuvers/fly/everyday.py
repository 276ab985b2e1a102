"""Everyday flights: seeded simulated logs of an ordinary flight rather than a calibration
maneuver, for the benchmarks and the tests of whole-flight estimation.

`everyday_plan` builds a 15-minute survey/loiter flight: a closed ground pattern of one
orbit and one racetrack (two straight legs joined by half circles of the orbit's radius),
flown again and again, with the airspeed changed every `level_s` seconds to one of evenly
spread levels over the envelope, in a seeded order, each change flown at the acceleration
limit. `everyday_flight` flies it through `simulate` in a wind that may drift linearly
(`DRIFTING_WIND`: 9 m/s from 270° to 12 m/s from 310° over the flight, 3 m/s and 40°), and
`default_plan_flight` flies the default calibration plan (`plan_maneuver()`) in its constant
wind, both with the simulator's default turbulence (0.5 m/s) and GPS noise.

Example
-------
>>> from pitotcal.maneuvers.fly.everyday import everyday_flight
>>> flight, truth = everyday_flight(seed=3, drifting=True)           # doctest: +SKIP
>>> round(flight.time_s[-1]), truth.history is not None              # doctest: +SKIP
(900, True)
"""

import math
from types import MappingProxyType

import numpy as np

from pitotcal.core.checks import integer, number
from pitotcal.core.dynamics import ground_speed_on_track_mps
from pitotcal.core.errors import PitotcalError
from pitotcal.core.plan import Plan
from pitotcal.core.speeds import cas_from_tas_mps, qc_from_tas_isa_pa, tas_from_cas_mps
from pitotcal.core.units import G0_MPS2, kt_to_mps, wind_polar, wind_vector_mps

__all__ = ["CONSTANT_WIND", "DRIFTING_WIND", "EVERYDAY_FLIGHT", "default_plan_flight",
           "everyday_flight", "everyday_plan", "wind_at"]

# The flight: 70-100 KCAS (the T-2 envelope, which the simulator's aircraft flies) at 244 m;
# an 850 m radius keeps the downwind bank of a circle at 100 KCAS in a 12 m/s wind at 26°,
# under the 30° limit; ten 90 s speed levels; a 10 Hz log (an ArduPilot ARSP rate).
EVERYDAY_FLIGHT = MappingProxyType({
    "duration_s": 900.0, "cas_min_kt": 70.0, "cas_max_kt": 100.0, "altitude_m": 244.0,
    "radius_m": 850.0, "leg_m": 2000.0, "level_s": 90.0, "bank_max_deg": 30.0,
    "accel_max_mps2": 1.0, "rate_hz": 10.0,
})
# The wind at the start and at the end of the flight, (speed m/s, FROM deg true); between
# them the wind vector moves linearly in time (the simulator's `wind_drift_mps2`).
DRIFTING_WIND = MappingProxyType({"start": (9.0, 270.0), "end": (12.0, 310.0)})
CONSTANT_WIND = MappingProxyType({"start": (9.0, 270.0), "end": (9.0, 270.0)})

_NODE_S = 1.0          # plan node spacing (as `pitotcal plan`'s default)
_SUBSTEPS = 5          # integration steps of the path per node


def wind_at(time_s, wind=DRIFTING_WIND, duration_s=EVERYDAY_FLIGHT["duration_s"]):
    """The process wind (north, east; blowing TO, m/s) at `time_s` of a flight of
    `duration_s` whose wind goes linearly from ``wind["start"]`` to ``wind["end"]``."""
    w0 = np.array(wind_vector_mps(*wind["start"]), dtype=float)
    w1 = np.array(wind_vector_mps(*wind["end"]), dtype=float)
    f = np.clip(np.asarray(time_s, dtype=float) / duration_s, 0.0, 1.0)
    return w0[0] + f * (w1[0] - w0[0]), w0[1] + f * (w1[1] - w0[1])


def _pattern(radius_m, leg_m):
    """The closed ground pattern as (length m, curvature 1/m) pieces: one right orbit, then a
    right racetrack that comes back to the orbit's start on its heading."""
    return ((2 * math.pi * radius_m, 1.0 / radius_m), (leg_m, 0.0),
            (math.pi * radius_m, 1.0 / radius_m), (leg_m, 0.0),
            (math.pi * radius_m, 1.0 / radius_m))


def _right(chi):
    """Unit vector (north, east) to the right of track `chi` (rad): toward a right turn's
    centre."""
    return np.array([-np.sin(chi), np.cos(chi)])


def _on_pattern(s_m, pieces, track0_rad):
    """(north m, east m, track rad) at path lengths `s_m` along the repeated pattern from the
    origin on track `track0_rad` (north 0, clockwise); right turns only."""
    starts, pos, chi = [], np.zeros(2), track0_rad
    for length, curv in pieces:
        starts.append((pos.copy(), chi))
        if curv == 0.0:
            pos = pos + length * np.array([math.cos(chi), math.sin(chi)])
        else:
            centre = pos + _right(chi) / curv
            chi = chi + length * curv
            pos = centre - _right(chi) / curv
    edges = np.cumsum([0.0] + [length for length, _ in pieces])
    s = np.mod(np.asarray(s_m, dtype=float), edges[-1])
    k = np.minimum(np.searchsorted(edges, s, side="right") - 1, len(pieces) - 1)
    north, east, track = np.empty_like(s), np.empty_like(s), np.empty_like(s)
    for i, (_, curv) in enumerate(pieces):
        m = k == i
        d = s[m] - edges[i]
        p0, chi0 = starts[i]
        if curv == 0.0:
            north[m], east[m], track[m] = (p0[0] + d * math.cos(chi0),
                                           p0[1] + d * math.sin(chi0), chi0)
        else:
            centre = p0 + _right(chi0) / curv
            chi = chi0 + d * curv
            north[m], east[m] = centre[0] + np.sin(chi) / curv, centre[1] - np.cos(chi) / curv
            track[m] = chi
    return north, east, track


def _tas_schedule(t, cfg, rng):
    """True airspeed (m/s) at `t`: the levels in a seeded order, each change at accel_max."""
    n_levels = max(2, int(math.ceil(cfg["duration_s"] / cfg["level_s"])))
    cas_kt = np.linspace(cfg["cas_min_kt"], cfg["cas_max_kt"], n_levels)[rng.permutation(n_levels)]
    target = tas_from_cas_mps(kt_to_mps(cas_kt), cfg["altitude_m"])
    level = target[np.minimum((t // cfg["level_s"]).astype(int), n_levels - 1)]
    tas = np.empty_like(t)
    tas[0] = level[0]
    step = cfg["accel_max_mps2"] * np.diff(t)
    for k in range(t.size - 1):
        tas[k + 1] = tas[k] + np.clip(level[k] - tas[k], -step[k], step[k])
    return tas


def everyday_plan(seed=0, wind=DRIFTING_WIND, **settings):
    """The 15-minute everyday flight as a `Plan` the simulator follows.

    Parameters
    ----------
    seed : int
        Seeds the order of the speed levels and where the pattern points (its first track).
    wind : mapping
        ``{"start": (speed m/s, from deg), "end": (...)}``: the process wind the ground
        speeds (hence the plan's clock) are computed in (`wind_at`).
    **settings
        Overrides of `EVERYDAY_FLIGHT` (duration_s, cas_min_kt, cas_max_kt, altitude_m,
        radius_m, leg_m, level_s, bank_max_deg, accel_max_mps2).

    Returns
    -------
    pitotcal.core.plan.Plan
        Nodes every second; its settings give the mean wind (the middle of the drift) and
        ``profile`` "everyday".
    """
    cfg = _settings(settings)
    rng = np.random.default_rng(integer("seed", seed, 0))
    track0 = float(rng.uniform(0.0, 2 * math.pi))
    duration = cfg["duration_s"]
    t = np.arange(0.0, duration + 0.5 * _NODE_S, _NODE_S)
    tas = _tas_schedule(t, cfg, rng)
    pieces = _pattern(cfg["radius_m"], cfg["leg_m"])
    # path length flown at each node: midpoint rule on substeps, ground speed in the wind
    h = _NODE_S / _SUBSTEPS
    s = np.zeros(t.size)
    for k in range(t.size - 1):
        sk = s[k]
        for j in range(_SUBSTEPS):
            tm = t[k] + (j + 0.5) * h
            v = np.interp(tm, t, tas)
            wn, we = wind_at(tm, wind, duration)
            half = sk + 0.5 * h * ground_speed_on_track_mps(
                _on_pattern([sk], pieces, track0)[2][0], v, wn, we)
            sk = sk + h * ground_speed_on_track_mps(
                _on_pattern([half], pieces, track0)[2][0], v, wn, we)
        s[k + 1] = sk
    north, east, track = _on_pattern(s, pieces, track0)
    wn, we = wind_at(t, wind, duration)
    vg = ground_speed_on_track_mps(track, tas, wn, we)
    heading = np.unwrap(np.arctan2(vg * np.sin(track) - we, vg * np.cos(track) - wn))
    bank = np.arctan(tas * np.gradient(heading, t) / G0_MPS2)
    alt = np.full(t.size, cfg["altitude_m"])
    mid_speed, mid_from = wind_polar(*wind_at(0.5 * duration, wind, duration))
    plan_settings = {k: v for k, v in cfg.items() if k != "rate_hz"}
    plan_settings.update(profile="everyday", seed=int(seed), wind_speed_mps=float(mid_speed),
                         wind_from_deg=float(mid_from), turn="right")
    return Plan(time_s=t, north_m=north, east_m=east, alt_m=alt,
                heading_deg=np.degrees(heading), bank_deg=np.degrees(bank), tas_mps=tas,
                cas_mps=cas_from_tas_mps(tas, alt), qc_pa=qc_from_tas_isa_pa(tas, alt),
                settings=plan_settings, message="everyday survey/loiter flight")


def _settings(overrides):
    unknown = sorted(set(overrides) - set(EVERYDAY_FLIGHT))
    if unknown:
        raise PitotcalError(f"unknown everyday-flight setting {unknown[0]!r}; known: "
                            f"{', '.join(EVERYDAY_FLIGHT)}", param=unknown[0])
    cfg = dict(EVERYDAY_FLIGHT)
    for name, value in overrides.items():
        cfg[name] = number(name, value, 0.0, lo_open=True)
    if cfg["cas_max_kt"] <= cfg["cas_min_kt"]:
        raise PitotcalError(f"cas_max_kt {cfg['cas_max_kt']:g} must exceed cas_min_kt "
                            f"{cfg['cas_min_kt']:g}", param="cas_max_kt")
    return cfg


def everyday_flight(seed=0, drifting=True, *, wind=None, rate_hz=EVERYDAY_FLIGHT["rate_hz"],
                    plan_settings=None, **sim_options):
    """(Flight, Truth) of the everyday flight flown by `simulate`, its history kept.

    Parameters
    ----------
    seed : int
        Seeds the plan (`everyday_plan`) and the simulation (turbulence, sensor noise).
    drifting : bool
        `DRIFTING_WIND` when True, else `CONSTANT_WIND`; `wind` overrides both.
    wind : mapping or None
        ``{"start": (speed m/s, from deg), "end": (...)}``.
    rate_hz : float
        Logging rate (default 10 Hz).
    plan_settings : dict or None
        Overrides of `EVERYDAY_FLIGHT` for the plan.
    **sim_options
        Fields of `SimulationOptions` (turbulence_mps, gps_noise_mps, model, k, ...).

    Notes
    -----
    The simulator's wind is mean + drift (t − t_mid): the mean is the wind at the middle of the
    flight and the drift (end − start) / duration, so the flown wind starts at ``start`` and
    ends at ``end`` (plus the gusts). ``truth.history["wind_n_mps"]`` is the wind flown through;
    `wind_at` the process wind without gusts.
    """
    from .simulator import simulate

    wind = dict(wind or (DRIFTING_WIND if drifting else CONSTANT_WIND))
    plan = everyday_plan(seed, wind, **(plan_settings or {}))
    duration = float(plan.time_s[-1] - plan.time_s[0])
    w0 = np.array(wind_at(0.0, wind, duration))
    w1 = np.array(wind_at(duration, wind, duration))
    drift = tuple(float(x) for x in (w1 - w0) / duration)
    return simulate(plan, seed=seed, rate_hz=rate_hz, wind_drift_mps2=drift,
                    wind_speed_mps=plan.settings["wind_speed_mps"],
                    wind_from_deg=plan.settings["wind_from_deg"], keep_history=True,
                    **sim_options)


def default_plan_flight(seed=0, **sim_options):
    """(Flight, Truth) of the default calibration plan (`plan_maneuver()`: T-2, 240 s, 5 m/s
    from 270°) flown by `simulate` at its defaults (0.5 m/s turbulence, 0.05 m/s GPS noise),
    its history kept."""
    from ..plan.planner import plan_maneuver
    from .simulator import simulate

    return simulate(_default_plan(plan_maneuver), seed=seed, keep_history=True, **sim_options)


_DEFAULT_PLAN = []


def _default_plan(plan_maneuver):
    if not _DEFAULT_PLAN:           # planning takes ~0.3 s: once per process
        _DEFAULT_PLAN.append(plan_maneuver())
    return _DEFAULT_PLAN[0]
