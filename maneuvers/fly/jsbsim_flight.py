"""`fly_jsbsim`: a plan flown by JSBSim (`maneuvers.fly.jsbsim_engine`), recorded by pitotcal's
sensor models into the same Flight as `maneuvers.fly.simulator.simulate`, which makes the Truth
(`simulate(plan, engine="jsbsim")`, or `simulate_jsbsim`)."""

import math
import tempfile
from typing import NamedTuple

import numpy as np

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

__all__ = ["JSBSimFlight", "fly_jsbsim"]


class JSBSimFlight(NamedTuple):
    """What `fly_jsbsim` gives the simulator to make the Truth of: the sensors' Flight, the
    states at the samples (the own engine's columns), the index of the plan's path point each
    was guided to, the guidance's gains, the history (or None) and the truth's options."""

    flight: object
    states: np.ndarray
    path_index: np.ndarray
    speed_loop: dict
    history: dict | None
    options: dict


def fly_jsbsim(plan, opts, seed, refs, limits):
    """The JSBSim engine of `simulate`: `opts` the SimulationOptions resolved for the checked
    `plan` (engine "jsbsim"), `seed` a checked integer, `refs` the plan on the dynamics grid,
    `limits` the guidance's; a `JSBSimFlight`."""
    aircraft = opts.aircraft or DEFAULT_AIRCRAFT
    settings = plan.settings or {}
    center_deg = opts.center_deg
    if center_deg is None:
        center_deg = (settings.get("center_lat_deg", DEFAULT_CENTER_DEG[0]),
                      settings.get("center_lon_deg", DEFAULT_CENTER_DEG[1]))
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
    return _outputs(refs, opts, seed, record, path_index,
                    {"engine": "jsbsim", "aircraft": aircraft, "milspec_sigma_mps": sigma,
                     "center_deg": list(center_deg)})


def _outputs(refs, opts, seed, record, path_index, engine):
    """The sensors' records of JSBSim's flight, as a `JSBSimFlight`."""
    from pitotcal.core.flight import Flight

    from .sensors import gps_velocity_sensor, impact_pressure_sensor, static_port_pa

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
    realised = {"turbulence_rms_mps": _turbulence_rms(record),
                "max_sideslip_deg": float(np.degrees(np.max(np.abs(record["beta_rad"])))),
                "max_alpha_deg": float(np.degrees(np.max(record["alpha_rad"]))),
                "stall_warning_s": float(np.sum(record["stall_warning"] > 0) * dt)}
    return JSBSimFlight(flight, states, path_index, {"gains": dict(GAINS)},
                        dict(record, time_s=t) if opts.keep_history else None,
                        {**opts.to_dict(), **engine, **realised})


# The own simulator's state columns (maneuvers.fly.guidance.fly), from the record.
_STATES = ("north_m", "east_m", "alt_m", "heading_rad", "tas_mps", "bank_rad", "wind_n_mps",
           "wind_e_mps")


def _turbulence_rms(record):
    """RMS of the horizontal turbulence flown through (total wind minus its mean), m/s."""
    dn = record["wind_n_mps"] - np.mean(record["wind_n_mps"])
    de = record["wind_e_mps"] - np.mean(record["wind_e_mps"])
    return float(np.sqrt(0.5 * np.mean(dn ** 2 + de ** 2)))
