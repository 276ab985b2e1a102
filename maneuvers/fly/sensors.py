"""Sensor models of the simulator: the pitot-static chain and the GPS velocity, on whole arrays.

Impact pressure, in the order the air and the signal meet them: the pressure-error model at the
probe (pitotcal.core.models, paper eq. 1 and 4), the first-order pneumatic lag of the tubing, the
transducer's scale error, bias and white noise, then the converter's quantization.
GPS velocity: the receiver measures the velocity `latency` seconds old, adds white noise, and
reports it at its own rate; the logger holds the last report until the next (sample-and-hold).
"""

import numpy as np

from pitotcal.core.checks import number, positive
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model, qci_from_qc_pa
from pitotcal.core.scenario import true_k

__all__ = [
    "air_records",
    "first_order_lag",
    "gauss_markov",
    "gps_velocity_sensor",
    "hold_index",
    "impact_pressure_sensor",
    "static_port_pa",
]


def first_order_lag(x, dt_s, tau_s):
    """First-order lag tau y' + y = x, discretised exactly for a zero-order-held input.

    Starts in equilibrium with the first sample (the probe was settled before the record).

    Parameters
    ----------
    x : ndarray (N,)
    dt_s : float
        Sample step, s.
    tau_s : float
        Time constant, s (0: no lag, `x` is returned).
    """
    x = np.asarray(x, dtype=float)
    if tau_s <= 0 or x.size == 0:
        return x.copy()
    from scipy.signal import lfilter                    # ~1 s to import: only with a lag

    a = np.exp(-dt_s / tau_s)
    y, _ = lfilter([1.0 - a], [1.0, -a], x, zi=[a * x[0]])
    return y


def impact_pressure_sensor(qc_pa, dt_s, rng, *, model="inverse", k=None,
                           pneumatic_lag_s=0.0, scale_error=0.0, bias_pa=0.0, noise_pa=0.0,
                           quantization_pa=0.0):
    """What a differential-pressure transducer on the pitot-static system records.

    Parameters
    ----------
    qc_pa : ndarray (N,)
        True impact pressure q_c, Pa, sampled every `dt_s` seconds.
    dt_s : float
        Sample step, s.
    rng : numpy.random.Generator
        Source of the transducer noise.
    model : str
        Pressure-error structure (pitotcal.core.models.MODELS).
    k : sequence of float, optional
        Its coefficients (the first as many as the model has are used); default
        `pitotcal.core.scenario.true_k(model)`.
    pneumatic_lag_s : float
        Time constant of the tubing lag, s.
    scale_error : float
        Relative gain error of the transducer (0.01: reads 1 % high).
    bias_pa, noise_pa, quantization_pa : float
        Zero offset, white-noise standard deviation and converter step, Pa.

    Returns
    -------
    ndarray (N,)
        Recorded q_ci, Pa.

    Notes
    -----
    q_ci solves q_ci = q_c (1 - f(q_ci; k)) (paper eq. 1 with eq. 4), then
    recorded = Q[(1 + scale_error) lag(q_ci) + bias + noise], Q rounding to the step.
    """
    m = get_model(model)
    k = true_k(model) if k is None else k
    if len(k) < len(m.params):
        raise PitotcalError(f"k needs {len(m.params)} coefficients for model {model!r}, "
                            f"got {len(k)}", param="k")
    for name, value in (("pneumatic_lag_s", pneumatic_lag_s), ("noise_pa", noise_pa),
                        ("quantization_pa", quantization_pa)):
        number(name, value, 0.0)
    qci = qci_from_qc_pa(m, tuple(k[:len(m.params)]), qc_pa)
    qci = first_order_lag(qci, dt_s, pneumatic_lag_s)
    qci = (1.0 + scale_error) * qci + bias_pa + rng.standard_normal(qci.size) * noise_pa
    if quantization_pa > 0:
        qci = np.round(qci / quantization_pa) * quantization_pa
    return qci


def hold_index(time_s, rate_hz):
    """For each sample, the index of the sample that carries the device's latest update.

    An update tick of a `rate_hz` device is recorded at the first sample at or after the tick
    (never later than the sample itself, so the hold is causal); when the rates are not
    multiples the update times jitter by up to one sample step. With `rate_hz` None or 0, or
    not below the sample rate, every sample is its own update.
    """
    t = np.asarray(time_s, dtype=float)
    if not rate_hz:
        return np.arange(t.size)
    period = 1.0 / rate_hz
    tick = np.floor((t - t[0]) / period + 1e-9) * period + t[0]
    return np.searchsorted(t, tick - 1e-9)


def gps_velocity_sensor(time_s, vel_mps, rng, *, rate_hz=5.0, noise_mps=0.05, latency_s=0.0,
                        gm_sigma_mps=0.0, gm_tau_s=30.0):
    """GPS velocity as logged: delayed, noisy, updated at `rate_hz` and held in between.

    Parameters
    ----------
    time_s : ndarray (N,)
        Sample times, s (uniform step).
    vel_mps : ndarray (N, C)
        True ground velocity components (north, east, down), m/s.
    rng : numpy.random.Generator
        Source of the noise: one independent draw per component and GPS update.
    rate_hz : float or None
        GPS update rate, Hz (None or 0: every sample).
    noise_mps : float
        White-noise standard deviation per component and update, m/s.
    latency_s : float
        Age of the reported velocity, s (>= 0); before the record starts the first value is used.
    gm_sigma_mps, gm_tau_s : float
        Time-correlated error on top of the white noise: a first-order Gauss-Markov process
        per component, steady-state standard deviation (m/s; 0: none) and correlation time (s)
        (`gauss_markov`).

    Returns
    -------
    ndarray (N, C)
    """
    t = np.asarray(time_s, dtype=float)
    vel = np.asarray(vel_mps, dtype=float).reshape(t.size, -1)
    if rate_hz is not None:
        number("gps_rate_hz", rate_hz, 0.0)
    number("gps_noise_mps", noise_mps, 0.0)
    number("gps_latency_s", latency_s, 0.0)
    if latency_s > 0:
        # np.interp holds the first value for times before the record: the receiver's first fix.
        vel = np.column_stack([np.interp(t - latency_s, t, vel[:, j]) for j in range(vel.shape[1])])
    held = hold_index(t, rate_hz)
    # One noise draw per sample, read through the hold: each update carries its own draw and
    # the result does not depend on how many updates there are before a given sample.
    noise = rng.standard_normal(vel.shape) * noise_mps
    if gm_sigma_mps > 0:      # drawn after the white noise: flights without it stay as they were
        noise = noise + gauss_markov(t, vel.shape[1], rng, gm_sigma_mps, gm_tau_s)
    return vel[held] + noise[held]


def static_port_pa(ps_pa, qc_pa, model="inverse", k=None):
    """What the static port reads with all the pressure error in the static source: p_s + Δp_p,
    Δp_p = q_c − q_ci at the probe (the pitot's total pressure exact), before the transducer."""
    m = get_model(model)
    k = true_k(model) if k is None else k
    return ps_pa + qc_pa - qci_from_qc_pa(m, tuple(k[:len(m.params)]), qc_pa)


def air_records(time_s, states, air_data, sensors, model="inverse", k=None):
    """The air-data truth and records of `AirSensors`: (q_c, logged ρ, columns).

    Parameters
    ----------
    time_s : ndarray (N,)
    states : ndarray (N, 8)
        The simulator's states (north, east, alt, heading, tas, bank, wind n, wind e).
    air_data : {"incompressible", "compressible"}
    sensors : maneuvers.fly.options.AirSensors
    model, k :
        The true pressure-error model: with compressible air data the static port reads
        p_s + Δp_p, Δp_p = q_c − q_ci (all the error in the static source, as `simulate`).

    Returns
    -------
    qc_pa : ndarray (N,)
        True impact pressure at the probe: ½ ρ V_p² or isentropic at the virtual temperature,
        V_p = V_t − r y the airspeed the probe sees (r = ψ̇ cos φ, y the arm).
    rho_kgm3 : ndarray (N,)
        The density a logger computes from what it logs, p_s / (R T_logged), dry air.
    columns : dict
        Flight fields: `ps_pa` (as the static port reads it), `oat_k` or `tat_k` (with bias),
        `rh_pct` if humid.
    """
    from pitotcal.core.airdata import mach_from_tas
    from pitotcal.core.measurement import StaticAir, isa_air
    from pitotcal.core.moist_air import virtual_temperature_k
    from pitotcal.core.units import R_AIR_JKGK, isa_pressure_pa, isa_temperature_k

    _, _, alt, psi, tas, bank, _, _ = np.asarray(states, dtype=float).T
    ps, ts = isa_pressure_pa(alt), isa_temperature_k(alt)
    tv = virtual_temperature_k(ts, ps, sensors.rh_pct)
    yaw_rate = (np.gradient(np.unwrap(psi), time_s) if psi.size > 1 else np.zeros_like(psi))
    v_probe = tas - yaw_rate * np.cos(bank) * sensors.probe_arm_m
    true_air = isa_air(alt, air_data, oat_k=tv)         # humid air: at the virtual temperature
    qc = true_air.qc_pa(v_probe ** 2)
    ps_read = static_port_pa(ps, qc, model, k) if isinstance(true_air, StaticAir) else ps
    columns = {"ps_pa": ps_read}
    if sensors.tat_recovery is None:
        logged_t = columns["oat_k"] = ts + sensors.oat_bias_k
    else:
        mach = mach_from_tas(v_probe, ts)
        logged_t = columns["tat_k"] = (ts * (1.0 + sensors.tat_recovery * 0.2 * mach ** 2)
                                       + sensors.oat_bias_k)
    if sensors.rh_pct > 0:
        columns["rh_pct"] = np.full(alt.size, sensors.rh_pct)
    return qc, ps_read / (R_AIR_JKGK * logged_t), columns


def gauss_markov(time_s, n_comp, rng, sigma, tau_s):
    """First-order Gauss-Markov process x' = -x / tau + w, stationary from the start.

    Exact discretisation x_(i+1) = phi x_i + sqrt(1 - phi^2) sigma e_i, phi = exp(-dt / tau),
    on the sample times `time_s`; shape (N, n_comp), steady-state standard deviation `sigma`.
    The GPS velocity error of a receiver's tracking loops and multipath drifts like this
    (tens of seconds), which white noise does not describe.
    """
    from scipy.signal import lfilter

    sigma = number("gps_gm_sigma_mps", sigma, 0.0)
    tau_s = positive("gps_gm_tau_s", tau_s)
    t = np.asarray(time_s, dtype=float)
    dt = np.diff(t, prepend=t[0])
    phi = np.exp(-dt / tau_s)
    e = rng.standard_normal((t.size, n_comp))
    drive = np.sqrt(1.0 - phi ** 2)[:, None] * e
    drive[0] = e[0]                                    # stationary start
    if np.allclose(dt[1:], dt[1:2]):                   # uniform step: one filter pass
        a = float(phi[1]) if t.size > 1 else 0.0
        return sigma * lfilter([1.0], [1.0, -a], drive, axis=0)
    x = np.empty_like(drive)
    x[0] = drive[0]
    for i in range(1, t.size):
        x[i] = phi[i] * x[i - 1] + drive[i]
    return sigma * x
