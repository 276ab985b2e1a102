"""`simulate_jsbsim`: a plan flown by JSBSim (`maneuvers.fly.jsbsim_engine`), recorded by pitotcal's
sensor models into the same Flight and Truth as `maneuvers.fly.simulator.simulate`."""

import math
import tempfile

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model

from .jsbsim_engine import (
    DEFAULT_AIRCRAFT,
    DEFAULT_CENTER_DEG,
    GAINS,
    JSBSIM_RATE_HZ,
    fly,
    new_fdm,
    set_turbulence,
    start,
)

__all__ = ["simulate_jsbsim"]


def simulate_jsbsim(plan, *, seed=0, aircraft=DEFAULT_AIRCRAFT, center_deg=None, limits=None,
                    keep_history=False, **options):
    """Fly `plan` with JSBSim and record what the sensors would log (see the module notes).

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
    seed : int
        Seed of the turbulence (JSBSim's own generator), the transducer and the GPS noise.
    aircraft : str
        A JSBSim aircraft (`aircraft_names()`); default the Cessna 172 `c172x`.
    center_deg : (float, float), optional
        Where the test area's centre is on the earth; default the plan's `center_lat_deg`,
        `center_lon_deg` settings, else `DEFAULT_CENTER_DEG`.
    limits : pitotcal.core.dynamics.Limits, optional
        Bank and roll-rate limits of the guidance (default: the plan's bank_max_deg).
    **options
        The sensor, wind and turbulence options of `maneuvers.fly.simulator.simulate` (same names,
        same checks). `air_data` is ignored: JSBSim's own (isentropic) total pressure is used.

    Returns
    -------
    (Flight, Truth)
        As `maneuvers.fly.simulator.simulate`; the truth's `air_data` is "compressible", its
        options add `engine`, `aircraft` and the Milspec settings with the sigma they make.
    """
    from pitotcal.core.checks import integer

    from .options import check_plan, sim_options
    from .simulator import default_limits, references

    check_plan(plan)
    options.pop("air_data", None)
    opts = sim_options(plan, **_sim_option_args(options))
    seed = integer("seed", seed, 0)
    settings = plan.settings or {}
    limits = default_limits(plan) if limits is None else limits
    if center_deg is None:
        center_deg = (settings.get("center_lat_deg", DEFAULT_CENTER_DEG[0]),
                      settings.get("center_lon_deg", DEFAULT_CENTER_DEG[1]))
    refs = references(plan, opts.rate_hz)
    steps = max(1, math.ceil(JSBSIM_RATE_HZ * refs.dt_s - 1e-9))
    # the ground 300 m below the lowest point of the plan (Milspec wants a height above it),
    # as the own simulator takes the altitude as the height above ground
    alt_agl_m = max(float(np.mean(plan.alt_m)), 300.0)
    with tempfile.TemporaryDirectory(prefix="pitotcal-jsbsim-") as scratch:
        fdm = new_fdm(aircraft, refs.dt_s / steps, scratch)
        trim = start(fdm, plan, refs, opts, center_deg, alt_agl_m)
        sigma = set_turbulence(fdm, opts, alt_agl_m, seed)
        record, path_index = fly(fdm, refs, limits, opts, trim, center_deg, steps)
        del fdm                             # closes its output file before the folder goes
    return _outputs(plan, refs, opts, seed, record, path_index,
                    {"engine": "jsbsim", "aircraft": aircraft, "milspec_sigma_mps": sigma,
                     "center_deg": list(center_deg)}, keep_history)


def _sim_option_args(options):
    """`sim_options`'s arguments: the given options, `simulate`'s defaults for the others."""
    import inspect

    from .options import sim_options
    from .simulator import simulate

    defaults = inspect.signature(simulate).parameters
    names = [n for n in inspect.signature(sim_options).parameters if n != "plan"]
    unknown = set(options) - set(names)
    if unknown:
        raise TypeError(f"simulate_jsbsim() got unexpected options {sorted(unknown)}")
    if options.get("turbulence_length_m") is not None:
        raise PitotcalError("turbulence_length_m: JSBSim's Milspec turbulence sets its own "
                            "scale lengths (MIL-F-8785C)", param="turbulence_length_m")
    return {n: options.get(n, defaults[n].default) for n in names if n in defaults}


def _outputs(plan, refs, opts, seed, record, path_index, engine, keep_history):
    """The sensors' records of JSBSim's flight (Flight) and the Truth."""
    from pitotcal.core.flight import Flight

    from .sensors import gps_velocity_sensor, impact_pressure_sensor, static_port_pa
    from .simulator import _tracking, _truth

    rng_qc, rng_gps = (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(3)[1:])
    t, dt = refs.sample_time_s, 1.0 / opts.rate_hz
    qci = impact_pressure_sensor(record["qc_pa"], dt, rng_qc, model=opts.model, k=opts.k,
                                 pneumatic_lag_s=opts.pneumatic_lag_s,
                                 scale_error=opts.qc_scale_error, bias_pa=opts.qc_bias_pa,
                                 noise_pa=opts.qc_noise_pa, quantization_pa=opts.qc_quantization_pa)
    vel = np.column_stack([record["vn_mps"], record["ve_mps"], record["vd_mps"]])
    gps = gps_velocity_sensor(t, vel, rng_gps, rate_hz=opts.gps_rate_hz,
                              noise_mps=opts.gps_noise_mps, latency_s=opts.gps_latency_s,
                              gm_sigma_mps=opts.gps_gm_sigma_mps, gm_tau_s=opts.gps_gm_tau_s)
    meta = {"generator": "pitotcal simulate --engine jsbsim", "seed": seed,
            "aircraft": engine["aircraft"], "model": opts.model,
            **dict(zip(get_model(opts.model).params, opts.k)),
            "wind_speed_mps": opts.wind_speed_mps, "wind_from_deg": opts.wind_from_deg,
            "air_data": "compressible"}
    flight = Flight(time_s=t, qci_pa=qci, gps_vn_mps=gps[:, 0], gps_ve_mps=gps[:, 1],
                    rho_kgm3=record["rho_kgm3"], gps_vd_mps=gps[:, 2], alt_m=record["alt_m"],
                    ps_pa=static_port_pa(record["ps_pa"], record["qc_pa"], opts.model, opts.k),
                    oat_k=record["oat_k"],
                    source=f"simulate(engine=jsbsim, seed={seed})", meta=meta)
    states = np.column_stack([record[key] for key in _STATES])
    tracking = _tracking(plan, refs, states, path_index)
    realised = {"turbulence_rms_mps": _turbulence_rms(record),
                "max_sideslip_deg": float(np.degrees(np.max(np.abs(record["beta_rad"])))),
                "max_alpha_deg": float(np.degrees(np.max(record["alpha_rad"]))),
                "stall_warning_s": float(np.sum(record["stall_warning"] > 0) * dt)}
    truth = _truth(plan, opts, seed, states, tracking, {"gains": dict(GAINS)},
                   dict(record, time_s=t) if keep_history else None,
                   options={**opts.to_dict(), **engine, **realised}, air_data="compressible")
    return flight, truth


# The own simulator's state columns (maneuvers.fly.guidance.fly), from the record.
_STATES = ("north_m", "east_m", "alt_m", "heading_rad", "tas_mps", "bank_rad", "wind_n_mps",
           "wind_e_mps")


def _turbulence_rms(record):
    """RMS of the horizontal turbulence flown through (total wind minus its mean), m/s."""
    dn = record["wind_n_mps"] - np.mean(record["wind_n_mps"])
    de = record["wind_e_mps"] - np.mean(record["wind_e_mps"])
    return float(np.sqrt(0.5 * np.mean(dn ** 2 + de ** 2)))
