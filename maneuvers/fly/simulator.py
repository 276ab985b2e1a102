"""Flight simulator: flies a `Plan` through the shared point-mass dynamics, in wind, with sensors.

`simulate` runs five steps, each a function here or in a sibling module:

1. options: every field checked before any work (maneuvers.fly.options.SimulationOptions),
   then resolved against the plan; ``engine="jsbsim"`` hands the plan to JSBSim here;
2. references: the plan on the dynamics grid, which steps at DYNAMICS_RATE_HZ or faster
   whatever the logging rate (`References`, `references`);
3. wind field: the mean wind, a slow linear drift and Dryden turbulence (maneuvers.turbulence)
   on the same grid (`WindField`, `wind_field`);
4. flying: lateral guidance and the PI auto-throttle of maneuvers.plan.autothrottle step the aircraft
   through pitotcal.core.dynamics with Heun's method (maneuvers.fly.guidance.integrate_closed_loop);
5. sensors: the records pass through the sensor models of maneuvers.fly.sensors, and the true
   values become a frozen `Truth` (maneuvers.fly.truth).

Everything random comes from `numpy.random.default_rng(seed)` streams, so the same seed gives
the same flight.
"""

import math
from dataclasses import dataclass

import numpy as np
from .guidance import GUIDANCE_GAINS, integrate_closed_loop, planned_tas_mps
from ..plan.autothrottle import tune_autothrottle
from .sensors import (
    air_records,
    gps_velocity_sensor,
    impact_pressure_sensor,
    static_port_pa,
)
from .options import MAX_SAMPLES, SimOptions, SimulationOptions, check_plan, simulation_options
from .truth import (
    Tracking,
    Truth,
    tracking_warnings,
    truth_path_for,
    write_truth_json,
)
from ..turbulence import dryden_gusts, dryden_scales

from pitotcal.core.checks import integer
from pitotcal.core.dynamics import Limits
from pitotcal.core.flight import Flight
from pitotcal.core.measurement import StaticAir, isa_air
from pitotcal.core.models import get_model
from pitotcal.core.speeds import cas_from_tas_mps
from pitotcal.core.units import (
    G0_MPS2,
    isa_density_kgm3,
    mps_to_kt,
    wind_polar,
    wind_vector_mps,
)

__all__ = [
    "DYNAMICS_RATE_HZ",
    "GUIDANCE_GAINS",
    "MAX_SAMPLES",
    "References",
    "SimOptions",
    "SimulationOptions",
    "WindField",
    "references",
    "simulate",
    "simulate_jsbsim",
    "tracking_warnings",
    "truth_path_for",
    "wind_field",
    "write_truth_json",
]

# The dynamics and autopilot never step slower than this (whole sub-steps per sample): at 7 Hz,
# stepping the dynamics at the logging rate put kinks in the velocity that biased k2 by
# ~-3 sigma (found in review); the flight must not change with the data rate.
DYNAMICS_RATE_HZ = 50.0

@dataclass(frozen=True)
class References:
    """The plan on the dynamics grid: what the autopilot tracks, step by step.

    Attributes
    ----------
    time_s : ndarray (n_dyn,)
        Dynamics grid, `steps_per_sample` steps of `dt_s` per logged sample.
    sample_time_s : ndarray (n,)
        Logged sample times.
    north_m, east_m, alt_m, heading_deg, bank_deg, tas_mps : ndarray (n_dyn,)
        The plan's columns on the grid; TAS that of its KCAS (`guidance.planned_tas_mps`).
    vn_mps, ve_mps, tas_rate_mps2, climb_mps : ndarray (n_dyn,)
        Ground velocity, TAS rate and climb rate of the plan, differentiated on its own nodes
        (smoother than the derivative of the interpolant), then interpolated.
    turn_rate_rps : ndarray (n_dyn,)
        Feed-forward turn rate g tan(bank) / V of the plan, rad/s.
    tas_max_mps : float
        The plan's highest true airspeed (sizes the thrust limit).
    """

    time_s: np.ndarray
    dt_s: float
    steps_per_sample: int
    sample_time_s: np.ndarray
    north_m: np.ndarray
    east_m: np.ndarray
    alt_m: np.ndarray
    heading_deg: np.ndarray
    bank_deg: np.ndarray
    tas_mps: np.ndarray
    vn_mps: np.ndarray
    ve_mps: np.ndarray
    tas_rate_mps2: np.ndarray
    climb_mps: np.ndarray
    turn_rate_rps: np.ndarray
    tas_max_mps: float


@dataclass(frozen=True)
class WindField:
    """The air mass on the dynamics grid.

    Attributes
    ----------
    wind_n_mps, wind_e_mps : ndarray (n_dyn,)
        Process wind (mean + drift), the way it blows TO; what the autopilot knows.
    gust_u_mps, gust_v_mps : ndarray (n_dyn,)
        Dryden gusts along the path and to the right wing.
    gust_u_rate_mps2 : ndarray (n_dyn,)
        d(u_g)/dt, felt at once as an airspeed change.
    drift_mps2 : (float, float)
        Linear drift of the process wind (north, east).
    gust_w_mps : ndarray (n_dyn,)
        Dryden's vertical gust, positive down (zeros unless `vertical_gusts`).
    """

    wind_n_mps: np.ndarray
    wind_e_mps: np.ndarray
    gust_u_mps: np.ndarray
    gust_v_mps: np.ndarray
    gust_u_rate_mps2: np.ndarray
    drift_mps2: tuple
    gust_w_mps: np.ndarray | None = None


def references(plan, rate_hz):
    """The plan on the dynamics grid for a logging rate `rate_hz` (see `References`)."""
    dt = 1.0 / rate_hz
    t0, t1 = float(plan.time_s[0]), float(plan.time_s[-1])
    n = math.floor((t1 - t0) * rate_hz + 1e-9) + 1
    sub = max(1, math.ceil(DYNAMICS_RATE_HZ / rate_hz - 1e-9))
    dt_dyn = dt / sub
    t_dyn = t0 + np.arange((n - 1) * sub + 1) * dt_dyn

    def on_grid(values):
        return np.interp(t_dyn, plan.time_s, values)

    def rate_on_grid(values):
        return on_grid(np.gradient(values, plan.time_s))

    tas_plan = planned_tas_mps(plan)
    tas, bank = on_grid(tas_plan), on_grid(plan.bank_deg)
    return References(
        time_s=t_dyn, dt_s=dt_dyn, steps_per_sample=sub, sample_time_s=t0 + np.arange(n) * dt,
        north_m=on_grid(plan.north_m), east_m=on_grid(plan.east_m), alt_m=on_grid(plan.alt_m),
        heading_deg=on_grid(plan.heading_deg), bank_deg=bank, tas_mps=tas,
        vn_mps=rate_on_grid(plan.north_m), ve_mps=rate_on_grid(plan.east_m),
        tas_rate_mps2=rate_on_grid(tas_plan), climb_mps=rate_on_grid(plan.alt_m),
        turn_rate_rps=G0_MPS2 * np.tan(np.radians(bank)) / tas,
        tas_max_mps=float(tas_plan.max()))


def wind_field(plan, refs, opts, rng):
    """Mean wind + linear drift about the plan's middle + Dryden gusts (path axes).

    wind(t) = mean + drift (t - t_mid), so the process mean over the record is the mean; the
    gusts come from `rng` (maneuvers.turbulence, MIL-F-8785C at the plan's mean altitude).
    """
    t, dt = refs.time_s, refs.dt_s
    n_dyn = t.size
    wn0, we0 = map(float, wind_vector_mps(opts.wind_speed_mps, opts.wind_from_deg))
    t_mid = 0.5 * (float(plan.time_s[0]) + float(plan.time_s[-1]))
    drift_n, drift_e = opts.wind_drift_mps2
    if opts.turbulence_mps > 0:
        # Dryden wants the height above ground; a test area below sea level (ISA altitude
        # < 0, which the planner accepts) is taken as flown just above the ground.
        scales = dryden_scales(max(float(np.mean(refs.alt_m)), 0.0), opts.turbulence_mps,
                               opts.turbulence_length_m)
        gust = dryden_gusts(n_dyn, dt, scales, float(np.mean(refs.tas_mps)), rng)
        ug, vg = gust[:, 0], gust[:, 1]
        wg = gust[:, 2] if opts.vertical_gusts else np.zeros(n_dyn)
    else:
        ug = vg = wg = np.zeros(n_dyn)
    return WindField(wind_n_mps=wn0 + drift_n * (t - t_mid),
                     wind_e_mps=we0 + drift_e * (t - t_mid), gust_u_mps=ug, gust_v_mps=vg,
                     gust_u_rate_mps2=np.gradient(ug, dt) if n_dyn > 1 else np.zeros(n_dyn),
                     drift_mps2=opts.wind_drift_mps2, gust_w_mps=wg)


def _record(t, states, opts, seed, rng_qc, rng_gps, w_up_mps=None):
    """The sensors' records of the states at the sample times: (Flight, qc_pa, true velocity).
    `w_up_mps`: the air mass's vertical velocity; V_t then includes the air-relative climb."""
    _, _, alt, psi, tas, _, wn, we = states.T
    dt, n = 1.0 / opts.rate_hz, t.size
    v_air = tas                   # horizontal true airspeed, + the air-relative climb if given
    if w_up_mps is not None:
        climb_air = (np.gradient(alt, dt) if n > 1 else np.zeros(n)) - w_up_mps
        v_air = np.sqrt(tas ** 2 + climb_air ** 2)
    rho = isa_density_kgm3(alt)
    # the true air at the ISA state flown (`core.measurement`): what the probe and port see
    true_air = isa_air(alt, opts.air_data)
    qc = true_air.qc_pa(v_air ** 2)
    static = {}
    if isinstance(true_air, StaticAir):
        static = {"ps_pa": static_port_pa(true_air.ps, qc, opts.model, opts.k),
                  "oat_k": true_air.oat}
    air = {}
    if opts.air_sensors is not None:      # temperature, humidity, probe arm
        qc, rho, air = air_records(t, states, opts.air_data, opts.air_sensors, opts.model,
                                   opts.k)
    climb = np.gradient(alt, dt) if n > 1 else np.zeros(n)
    vel = np.column_stack([tas * np.cos(psi) + wn, tas * np.sin(psi) + we, -climb])
    qci = impact_pressure_sensor(qc, dt, rng_qc, model=opts.model, k=opts.k,
                                 pneumatic_lag_s=opts.pneumatic_lag_s,
                                 scale_error=opts.qc_scale_error, bias_pa=opts.qc_bias_pa,
                                 noise_pa=opts.qc_noise_pa,
                                 quantization_pa=opts.qc_quantization_pa)
    gps = gps_velocity_sensor(t, vel, rng_gps, rate_hz=opts.gps_rate_hz,
                              noise_mps=opts.gps_noise_mps, latency_s=opts.gps_latency_s,
                              gm_sigma_mps=opts.gps_gm_sigma_mps, gm_tau_s=opts.gps_gm_tau_s)
    if opts.air_sensors is not None:
        gps = gps + np.asarray(opts.air_sensors.gps_bias_mps)
    meta = {"generator": "pitotcal simulate", "seed": seed, "model": opts.model,
            **dict(zip(get_model(opts.model).params, opts.k)),
            "wind_speed_mps": opts.wind_speed_mps, "wind_from_deg": opts.wind_from_deg}
    if opts.air_data != "incompressible":   # an incompressible flight's CSV keeps its bytes
        meta["air_data"] = opts.air_data
    flight = Flight(time_s=t, qci_pa=qci, gps_vn_mps=gps[:, 0], gps_ve_mps=gps[:, 1],
                    rho_kgm3=rho, gps_vd_mps=gps[:, 2], alt_m=alt,
                    source=f"simulate(seed={seed})", meta=meta, **(air or static))
    return flight, qc, vel


def default_limits(plan):
    """The guidance's bank and roll-rate limits: `Limits` with the plan's bank_max_deg."""
    return Limits(bank_max_deg=float((plan.settings or {}).get("bank_max_deg",
                                                               Limits.bank_max_deg)))


def _plunge(refs, wind, states, opts):
    """(states, w_up at the samples): with `vertical_gusts`, the altitude offset of the
    aircraft's plunge in the vertical gust (`turbulence.plunge_response`) added to the states'
    altitude; else (states, None)."""
    if not opts.vertical_gusts or not np.any(wind.gust_w_mps):
        return states, None
    from .guidance import GUIDANCE_GAINS
    from ..turbulence import plunge_response

    sub = refs.steps_per_sample
    rho = float(np.mean(isa_density_kgm3(states[:, 2])))
    dh, _ = plunge_response(wind.gust_w_mps, refs.dt_s, float(np.mean(refs.tas_mps)), rho,
                            GUIDANCE_GAINS["k_alt_per_s"])
    out = states.copy()
    out[:, 2] += dh[::sub]
    return out, -wind.gust_w_mps[::sub]


def _tracking(plan, refs, states, path_index):
    """How closely the states at the sample times followed the plan (CAS: `core.speeds`)."""
    north, east, alt, _, tas, bank, _, _ = states.T
    cas_err_kt = mps_to_kt(cas_from_tas_mps(tas, alt)
                           - np.interp(refs.sample_time_s, plan.time_s, plan.cas_mps))
    return Tracking(
        max_cas_error_kt=float(np.max(np.abs(cas_err_kt))),
        rms_cas_error_kt=float(np.sqrt(np.mean(cas_err_kt ** 2))),
        # distance to the nearest point of the plan's path (the guidance reference)
        max_path_error_m=float(np.max(np.hypot(north - refs.north_m[path_index],
                                               east - refs.east_m[path_index]))),
        max_radius_m=float(np.max(np.hypot(north, east))),
        max_bank_deg=float(np.degrees(np.max(np.abs(bank)))),
        max_alt_error_m=float(np.max(np.abs(alt - refs.alt_m[::refs.steps_per_sample]))))


def _history(plan, refs, wind, states, flight, qc, vel):
    north, east, alt, psi, tas, bank, wn, we = states.T
    t, sub = refs.sample_time_s, refs.steps_per_sample
    return {"time_s": t, "north_m": north, "east_m": east, "alt_m": alt, "heading_rad": psi,
            "tas_mps": tas, "cas_mps": cas_from_tas_mps(tas, alt),
            "cas_ref_mps": np.interp(t, plan.time_s, plan.cas_mps), "bank_rad": bank,
            "wind_n_mps": wn, "wind_e_mps": we, "qc_pa": qc, "gps_true_mps": vel,
            "gust_mps": np.column_stack([wind.gust_u_mps, wind.gust_v_mps])[::sub]}


def _truth(plan, opts, seed, states, tracking, speed_loop, history, *, options=None,
           air_data=None):
    """The frozen `Truth`: the true calibration, the wind flown through on average, options.

    `speed_loop` is the auto-throttle's description (a dict); `options` and `air_data` default
    to `opts`'s (the JSBSim engine adds its own and is always compressible)."""
    mean_n, mean_e = float(np.mean(states[:, 6])), float(np.mean(states[:, 7]))
    speed, from_deg = map(float, wind_polar(mean_n, mean_e))
    settings = plan.settings or {}
    return Truth(
        model=opts.model, k=opts.k,
        parameters={**dict(zip(get_model(opts.model).params, opts.k)),
                    "wind_speed_mps": speed, "wind_from_deg": from_deg},
        wind_n_mps=mean_n, wind_e_mps=mean_e,
        wind_mean_process={"speed_mps": opts.wind_speed_mps, "from_deg": opts.wind_from_deg,
                           "drift_mps2": list(opts.wind_drift_mps2)},
        seed=seed, options=opts.to_dict() if options is None else options, tracking=tracking,
        speed_loop=speed_loop, plan=dict(settings), history=history,
        air_data=opts.air_data if air_data is None else air_data)


def simulate(plan, options=None, *, seed=0, **overrides):
    """Fly `plan` in simulation and record what the sensors would log.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
        The maneuver; its `settings` give the mean wind unless the options say otherwise.
    options : SimulationOptions, optional
        What to fly and record (maneuvers.fly.options.SimulationOptions, every field checked
        when it is made); None: its defaults.
    seed : int
        Seed of all randomness (turbulence, transducer noise, GPS noise: separate streams).
    **overrides
        Fields of `SimulationOptions` by name (``model="linear"``, ``turbulence_mps=0``,
        ``engine="jsbsim"``, ...), put into `options`: with both, the overrides win. An
        unknown name is a TypeError.

    Returns
    -------
    flight : pitotcal.core.flight.Flight
        time_s, qci_pa, gps_vn/ve/vd_mps, rho_kgm3 (ISA at the altitude flown), alt_m; with
        compressible air data also ps_pa (the static port: p_s + q_c − q_ci) and oat_k.
    truth : maneuvers.fly.truth.Truth
        The true calibration and mean wind flown, the options, and the tracking errors.

    Notes
    -----
    ``engine="jsbsim"`` flies the plan with JSBSim (maneuvers.fly.jsbsim_flight) and records it
    with the same sensor models.

    Example
    -------
    >>> from pitotcal.maneuvers import SimulationOptions, plan_maneuver, simulate
    >>> calm = SimulationOptions(turbulence_mps=0.0, rate_hz=10.0)
    >>> flight, truth = simulate(plan_maneuver(), calm, seed=1, model="linear")
    >>> truth.model, flight.n
    ('linear', 2401)
    """
    opts = simulation_options(options, overrides)
    check_plan(plan)
    opts = opts.resolved(plan)
    seed = integer("seed", seed, 0)
    limits = default_limits(plan) if opts.limits is None else opts.limits
    refs = references(plan, opts.rate_hz)
    if opts.engine == "jsbsim":
        return _jsbsim(plan, opts, seed, refs, limits)
    rng_turb, rng_qc, rng_gps = (np.random.default_rng(s)
                                 for s in np.random.SeedSequence(seed).spawn(3))
    wind = wind_field(plan, refs, opts, rng_turb)
    speed_loop = opts.speed_loop
    if speed_loop is None:
        speed_loop = tune_autothrottle(0.5 * float(plan.tas_mps.min() + plan.tas_mps.max()))
    states, path_index = integrate_closed_loop(refs, wind, speed_loop, limits)
    states, w_up = _plunge(refs, wind, states, opts)
    flight, qc, vel = _record(refs.sample_time_s, states, opts, seed, rng_qc, rng_gps, w_up)
    tracking = _tracking(plan, refs, states, path_index)
    history = _history(plan, refs, wind, states, flight, qc, vel) if opts.keep_history else None
    return flight, _truth(plan, opts, seed, states, tracking, _loop_record(speed_loop), history)


def simulate_jsbsim(plan, options=None, *, seed=0, **overrides):
    """`simulate` with ``engine="jsbsim"`` (JSBSim's six-degree-of-freedom model, see
    `SimulationOptions`); the truth's options add `engine`, `aircraft`, `center_deg` and the
    Milspec settings with the sigma they make."""
    return simulate(plan, simulation_options(options, {"engine": "jsbsim", **overrides},
                                             caller="simulate_jsbsim"), seed=seed)


def _jsbsim(plan, opts, seed, refs, limits):
    """(Flight, Truth) of the plan flown by JSBSim (maneuvers.fly.jsbsim_flight)."""
    from .jsbsim_flight import fly_jsbsim

    flown = fly_jsbsim(plan, opts, seed, refs, limits)
    tracking = _tracking(plan, refs, flown.states, flown.path_index)
    return flown.flight, _truth(plan, opts, seed, flown.states, tracking, flown.speed_loop,
                                flown.history, options=flown.options, air_data="compressible")


def _loop_record(speed_loop):
    """The speed loop's description for the truth JSON."""
    return {"kp": speed_loop.kp, "ki": speed_loop.ki, "engine_lag_s": speed_loop.engine_lag_s,
            "lift_to_drag": speed_loop.lift_to_drag, "trim_tas_mps": speed_loop.trim_tas_mps}
