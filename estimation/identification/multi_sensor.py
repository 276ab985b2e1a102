"""Two or more airspeed sensors in one flight: one shared wind, one calibration per sensor.

Each sensor's q_ci is its own measured output of the one measurement model: the sensors see the
same air mass through the same GPS ground velocity, so the wind is one unknown of all of them,
and each sensor has its own pressure-error coefficients. `identify_sensors` solves that joint
output-error problem and returns one `IdentificationResult` per sensor (the shared wind in each).

Notes
-----
Unknowns theta = [k_1..., k_2..., ..., wind_n, wind_e]. The objective is the sum of the
single-sensor objectives (`oe.objective_function`, the corrected score), each on its own samples
with its own noise weight, the wind entries of x shared:

    J = sum_s n_s / (n̄ sigma_s²) J_s(k_s, W),   J_s = mean_i [r_s,i² − spread_s,i],

i.e. weighted least squares with each sensor's residual variance sigma_s² (from its own fit).
Every sensor is first fitted alone by `fit.fit` (its checks, gates and outlier trimming: the
joint problem uses the samples that fit kept, and starts from its estimate).

Bounds: the sandwich of the whole problem, M⁻¹ Ω M⁻¹ with M = sum_s S_sᵀ S_s / sigma_s². The
sensors' weighted residuals and sensitivities are put on the first sensor's time steps (each
sample onto its nearest step) and rotated into orthonormal channels per step: their sum (the
turbulence and GPS error all sensors see alike) and contrasts (mostly each sensor's own white
noise). The score sum_s S_sᵀ r_s is unchanged by the rotation, and Ω is the sum over channels
of the single-sensor colored-residual middle (`uncertainty.covariance.colored_covariance`,
multiscale, with the information set to I), each channel's sensitivities first reduced to
their independent directions (in every channel the k1 columns of all sensors are one column:
dr/dk1 follows from the shared wind and GPS alone).
"""

import dataclasses
import time

import numpy as np

from pitotcal.core import checks
from pitotcal.core.errors import PitotcalError
from pitotcal.core.measurement import DEFAULT_AIR_DATA
from pitotcal.core.models import get_model
from pitotcal.core.processes import solver_interrupts

from ..uncertainty.covariance import colored_covariance, plain_covariance
from ..uncertainty.residual_noise import _inv_sym
from .fit import _air_data, fit
from .identify import budget_inputs, complete
from .oe import DEFAULT_IPOPT_OPTIONS, objective_function, objective_inputs
from .residual import flight_channels, residual, sensitivities
from .unknowns import WIND_NAMES, theta_scales, to_reported
from .wind_drift import constant_wind

__all__ = ["identify_sensors", "joint_note", "sensors_record", "sensors_summary"]


def identify_sensors(flights, model="inverse", *, air=DEFAULT_AIR_DATA, gps_noise_std_mps=None,
                     budget=None, ipopt_options=None):
    """Identify each airspeed sensor's pressure error and the one wind they share.

    Parameters
    ----------
    flights : sequence of Flight, length >= 2
        One flight per sensor, each on its own sensor's time base (`pitotcal.io.sensors`),
        the same GPS velocity; the first is the primary sensor.
    model : {"inverse", "constant", "linear", "auto"}
        Pressure-error structure of every sensor ("auto": each sensor's own choice).
    air, gps_noise_std_mps, budget, ipopt_options
        As `identify`.

    Returns
    -------
    list of IdentificationResult
        One per sensor, in the order of `flights`: its coefficients, the shared wind, the joint
        covariance's block of (k_s, wind) and its residuals; a warning names the joint fit.

    Raises
    ------
    PitotcalError
        Fewer than two flights; the errors of `identify` for any sensor's flight.
    """
    flights = list(flights)
    if len(flights) < 2:
        raise PitotcalError(f"`flights`: {len(flights)} given; the joint fit needs one flight "
                            "per sensor, at least two", param="flights")
    inputs = budget_inputs(budget)
    options = {**DEFAULT_IPOPT_OPTIONS, **checks.option_dict("ipopt_options", ipopt_options)}
    singles = [fit(f, model=model, air=air, gps_noise_std_mps=gps_noise_std_mps)
               for f in flights]
    kept = [f.select(np.isin(f.time_s, r.time_s)) for f, r in zip(flights, singles)]
    modes = [_air_data(f, air)[0] for f in kept]
    parts = [_Part(get_model(r.model), f, flight_channels(f, gps_noise_std_mps, mode), mode, r)
             for f, r, mode in zip(kept, singles, modes)]
    t0 = time.perf_counter()
    theta, stats = _solve(parts, options)
    cov, colored = _sandwich(parts, theta)
    elapsed = time.perf_counter() - t0
    return [complete(_sensor_result(p, i, parts, theta, cov, stats, colored, elapsed), f, air=air,
                     budget=inputs) for i, (p, f) in enumerate(zip(parts, kept))]


@dataclasses.dataclass(frozen=True)
class _Part:
    """One sensor of the joint problem."""

    model: object
    flight: object
    ch: object
    air_data: str
    single: object           # its own fit (start values, noise scale, warnings)

    @property
    def sigma2(self):
        return max(float(np.mean(self.single.residuals_pa ** 2)), 1e-12)


def _slices(parts):
    """theta's slice of each sensor's coefficients; the wind is the last two entries."""
    out, at = [], 0
    for p in parts:
        out.append(slice(at, at + len(p.model.params)))
        at += len(p.model.params)
    return out, at + 2


def _theta_s(theta, sl):
    return np.concatenate([theta[sl], theta[-2:]])


def _solve(parts, options):
    """IPOPT on the sum of the sensors' objectives sharing the wind: (theta, solver stats)."""
    import casadi as ca

    slices, n_theta = _slices(parts)
    scales = np.concatenate([theta_scales(p.model)[:-2] for p in parts] + [np.ones(2)])
    x = ca.MX.sym("x", n_theta)
    n_mean = np.mean([p.flight.n for p in parts])
    total, p_syms, p_vals = 0, [], []
    for p, sl in zip(parts, slices):
        n, has_vd = p.flight.n, p.ch.vd2 is not None
        obj = objective_function(p.model, n, has_vd, p.air_data)
        data = [ca.MX.sym(name, n) for name in obj.name_in()[1:-4]]
        noise = [ca.MX.sym(name) for name in obj.name_in()[-4:]]
        total = total + obj(ca.vertcat(x[sl], x[-2:]), *data, *noise)
        p_syms += data + noise
        p_vals += objective_inputs(p.ch, n / (n_mean * p.sigma2), obj.name_in()[1:])
    solver = ca.nlpsol("oe_sensors", "ipopt", {"x": x, "p": ca.vertcat(*p_syms), "f": total},
                       {"ipopt": options, "print_time": False})
    start = np.concatenate([p.single.internal_params[:-2] for p in parts]
                           + [np.mean([p.single.internal_params[-2:] for p in parts], axis=0)])
    with solver_interrupts():
        sol = solver(x0=start / scales, p=ca.DM(np.concatenate(p_vals)))
    return np.asarray(sol["x"]).ravel() * scales, solver.stats()


def _sandwich(parts, theta):
    """(joint colored-residual covariance of theta, the sum channel's `ColoredCovariance`;
    module Notes)."""
    slices, n_theta = _slices(parts)
    base = parts[0].flight.time_s
    dt = max(float(np.median(np.diff(base))), 1e-9)
    n_s = len(parts)
    res = np.zeros((n_s, base.size))
    jac = np.zeros((n_s, base.size, n_theta))
    hess = np.zeros((n_theta, n_theta))
    # weights relative to the mean noise: the rows keep the residuals' own scale, Pa
    sigma_mean = np.sqrt(np.mean([p.sigma2 for p in parts]))
    for j, (p, sl) in enumerate(zip(parts, slices)):
        th = _theta_s(theta, sl)
        rows = np.zeros((p.flight.n, n_theta))
        sens = sensitivities(p.model, th, *p.ch.args)
        rows[:, sl], rows[:, -2:] = sens[:, :-2], sens[:, -2:]
        weight = sigma_mean / np.sqrt(p.sigma2)
        rows, r = rows * weight, residual(p.model, th, *p.ch.args) * weight
        hess += rows.T @ rows
        # each sample onto the first sensor's nearest time step (the score adds there)
        step = np.clip(np.searchsorted(base, p.flight.time_s - dt / 2), 0, base.size - 1)
        np.add.at(res[j], step, r)
        np.add.at(jac[j], step, rows)
    # sum and contrast channels (orthonormal): the score sum_s S_s r_s is unchanged, the
    # sensors' common turbulence lies in the sum channel, their own white noise in all
    q = _helmert(n_s)
    middle, first = np.zeros((n_theta, n_theta)), None
    for c in range(n_s):
        rc, jc = q[c] @ res, np.tensordot(q[c], jac, axes=1)
        basis, back = _orthonormal_columns(jc)
        # with information I the "covariance" returned is the middle of the sandwich itself
        colored = colored_covariance(basis, rc, velocity=jc[:, -2:],
                                     information=np.eye(basis.shape[1]))
        middle += back.T @ colored.covariance @ back
        first = colored if first is None else first
    h_inv = _inv_sym(hess)
    return h_inv @ middle @ h_inv, first


def _orthonormal_columns(jac, rtol=1e-7):
    """(B, T) with jac = B T, B's columns orthogonal with unit RMS, directions along which
    jac has no extent dropped: a channel's sensitivities to k1 of every sensor are the same
    column (dr/dk1 follows from the shared wind and GPS alone), which the noise model's
    projection could not invert."""
    u, sv, vt = np.linalg.svd(jac, full_matrices=False)
    keep = sv > rtol * sv[0]
    root_n = np.sqrt(jac.shape[0])
    return u[:, keep] * root_n, (sv[keep, None] * vt[keep]) / root_n


def _helmert(n):
    """An orthonormal n x n matrix whose first row is the mean direction 1/sqrt(n)."""
    q = np.zeros((n, n))
    q[0] = 1.0 / np.sqrt(n)
    for i in range(1, n):
        q[i, :i] = 1.0 / np.sqrt(i * (i + 1))
        q[i, i] = -i / np.sqrt(i * (i + 1))
    return q


def _sensor_result(part, i, parts, theta, cov, stats, colored, elapsed):
    """Sensor `i`'s `IdentificationResult`: its own fit's record with the joint numbers."""
    slices, _ = _slices(parts)
    idx = np.r_[np.arange(theta.size)[slices[i]], theta.size - 2, theta.size - 1]
    th, c = theta[idx], cov[np.ix_(idx, idx)]
    r = residual(part.model, th, *part.ch.args)
    jac = sensitivities(part.model, th, *part.ch.args)
    plain = plain_covariance(jac, r)
    params, cov_rep = to_reported(th, c)
    _, plain_rep = to_reported(th, plain)
    success = bool(stats.get("success", False))
    message = str(stats.get("return_status", "unknown"))
    warn = tuple(part.single.warnings) + (joint_note(i, len(parts)),)
    if colored.warning:
        warn += (colored.warning,)
    if not success:
        warn += (f"the joint fit of the sensors did not converge ({message}); the numbers "
                 "are not a calibration",)
    # the joint fit has one constant wind: the single fit's drift or per-window winds (its
    # wind_model, wind_track, drift) are not this result's, nor the budget's flight
    joint = dataclasses.replace(
        part.single, params=params, covariance=cov_rep, covariance_plain=plain_rep,
        internal_params=th, internal_covariance=c, internal_covariance_plain=plain,
        residuals_pa=r, noise_std_pa=float(np.sqrt(np.mean(r ** 2))), success=success,
        message=message, iterations=int(stats.get("iter_count", 0)), warnings=warn,
        param_names=tuple(part.model.params) + WIND_NAMES,
        timing_s={**part.single.timing_s, "joint": elapsed}, drift=None)
    return constant_wind(joint, "one wind shared by the sensors' joint fit")


def joint_note(i, n_sensors):
    """The warning line every sensor's result carries: what the joint fit shared."""
    return (f"airspeed sensor {i + 1} of {n_sensors}: fitted jointly with the other sensors, "
            "one shared wind; bounds from the colored residuals of all sensors together")



def sensors_record(results, flights, per_sensor=None):
    """``{"sensors": [...]}`` of the result record (docs/interfaces.md §3), {} for one sensor:
    each sensor's record (`IdentificationResult.to_dict`, the usual keys) with its number and
    pressure source, and with `per_sensor` ((recommendation or None, refusal or None) per
    sensor) its ``autopilot_parameter``."""
    if len(results) < 2:
        return {}
    out = []
    for i, (res, flight) in enumerate(zip(results, flights)):
        item = {"sensor": i + 1, "qc_source": flight.meta.get("qc_source"), **res.to_dict()}
        if per_sensor is not None:
            rec, refused = per_sensor[i]
            item["autopilot_parameter"] = rec.to_dict() if rec is not None else {
                "refused": str(refused), "structure_misfit": getattr(refused, "misfit", None)}
        out.append(item)
    return {"sensors": out}


def sensors_summary(results, flights):
    """The summaries of the sensors beyond the first, each under a heading naming it ("" for
    one sensor)."""
    return "".join(f"\nAirspeed sensor {i} ({flight.meta.get('qc_source')}, {flight.n} "
                   f"samples; the wind shared with sensor 1):\n{res.summary()}\n"
                   for i, (res, flight) in enumerate(zip(results[1:], flights[1:]), start=2))
