"""Two or more airspeed sensors in one flight: one shared wind model, one calibration per sensor.

Each sensor's q_ci is its own measured output of the one measurement model: the sensors see the
same air mass through the same GPS ground velocity, so the wind is one unknown of all of them,
and each sensor has its own pressure-error coefficients. `identify_sensors` solves that joint
output-error problem and returns one `IdentificationResult` per sensor (the shared wind in each).

Notes
-----
The wind is the first sensor's wind model, W(t) = W_mean + B(t) d (`wind_drift`): its fit alone
(`fit.fit`, with `wind` and `wind_knot_s`) chooses a constant wind, one wind per calibration
window or a drift, and that basis B is every sensor's, evaluated at its own sample times.
Unknowns x = (theta, d), theta = [k_1..., k_2..., ..., wind_n, wind_e]
(`multi_sensor_wind`). Every other sensor is first fitted alone with the first sensor's drift
taken out of its GPS velocity (its checks, gates and outlier trimming: the joint problem uses
the samples that fit kept, and starts from its estimate). Then:

1. (theta, d) by Gauss-Newton on all sensors' residuals, each weighted by 1 / sigma_s, from the
   first sensor's d (`multi_sensor_wind.joint_gauss_newton`; skipped for a constant wind): a
   full Gauss-Newton, not one step, because it costs a few sensitivity evaluations and d is
   then the joint problem's, not the first sensor's alone;
2. theta given d by IPOPT on the sum of the single-sensor objectives (`oe.objective_function`,
   the corrected score), each on its own samples with its own noise weight, the wind shared:

       J = sum_s n_s / (n̄ sigma_s²) J_s(k_s, W),   J_s = mean_i [r_s,i² − spread_s,i],

   i.e. weighted least squares with each sensor's residual variance sigma_s² (its own fit);
3. the instrumental-variable step (`multi_sensor_wind.joint_iv`, as `iv.iv_refine` for one
   sensor): each sensor's coefficient rows on its instruments Z_s, the mean-wind and drift
   rows the weighted sum of the sensors' corrected scores, solved in (theta, d) together.

Bounds: the sandwich of the whole problem, A⁻¹ Ω A⁻ᵀ with A = sum_s Z_sᵀ S_s / sigma_s² (the
sensitivities S_s and instruments Z_s in the columns of x, d included; Z_s = S_s when the
instrumental-variable step did not converge). The sensors' weighted residuals,
sensitivities and instruments are put on the first sensor's time steps (each sample onto its
nearest step) and rotated into orthonormal channels per step: their sum (the turbulence and
GPS error all sensors see alike) and contrasts (mostly each sensor's own white noise). The
estimating equations sum_s Z_sᵀ r_s are unchanged by the rotation, and Ω is the sum over
channels of the single-sensor colored-residual middle built from the channel's instruments
(`uncertainty.covariance.colored_covariance` with `instruments`, multiscale, the information
set to I), its noise model fitted at the channel's sensitivities reduced to their independent
directions (in every channel the k1 columns of all sensors are one column: dr/dk1 follows
from the shared wind and GPS alone). Each sensor's `covariance` is the block of (k_s, W_mean)
of that whole covariance, so it includes the wind's freedom; its `wind_track` is the shared
wind with the 2σ from the block of (W_mean, d).
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
from .fit import _air_data, fit
from .identify import budget_inputs, complete
from .iv import IV_NOT_CONVERGED
from .multi_sensor_wind import (
    joint_gauss_newton,
    joint_iv,
    sensor_terms,
    shared_drift,
    smoothed_qci,
    x_scales,
)
from .oe import DEFAULT_IPOPT_OPTIONS, objective_function, objective_inputs
from .residual import flight_channels
from .unknowns import WIND_NAMES, to_reported
from .wind_drift import check_wind_options, constant_wind, shifted, wind_track, without_drift

__all__ = ["identify_sensors", "joint_note", "sensors_record", "sensors_summary"]


def identify_sensors(flights, model="inverse", *, air=DEFAULT_AIR_DATA, gps_noise_std_mps=None,
                     budget=None, ipopt_options=None, wind="auto", wind_knot_s=None):
    """Identify each airspeed sensor's pressure error and the wind model they share.

    Parameters
    ----------
    flights : sequence of Flight, length >= 2
        One flight per sensor, each on its own sensor's time base (`pitotcal.io.sensors`),
        the same GPS velocity and calibration windows (`Flight.segment`); the first is the
        primary sensor.
    model : {"inverse", "constant", "linear", "auto"}
        Pressure-error structure of every sensor ("auto": each sensor's own choice).
    air, gps_noise_std_mps, budget, ipopt_options
        As `identify`.
    wind : {"auto", "constant", "drifting"}
        The wind model, chosen on the first sensor's flight as `identify` chooses it (a drift,
        one wind per calibration window, or one constant wind) and then fitted with every
        sensor's residuals.
    wind_knot_s : float, optional
        Knot spacing of a drift, s (as `identify`).

    Returns
    -------
    list of IdentificationResult
        One per sensor, in the order of `flights`: its coefficients, the shared wind (mean,
        `drift`, `wind_model`, `wind_track`), the joint covariance's block of (k_s, wind) and
        its residuals; a warning names the joint fit.

    Raises
    ------
    PitotcalError
        Fewer than two flights; the errors of `identify` for any sensor's flight.
    """
    flights = list(flights)
    if len(flights) < 2:
        raise PitotcalError(f"`flights`: {len(flights)} given; the joint fit needs one flight "
                            "per sensor, at least two", param="flights")
    wind, wind_knot_s = check_wind_options(wind, wind_knot_s)
    inputs = budget_inputs(budget)
    options = {**DEFAULT_IPOPT_OPTIONS, **checks.option_dict("ipopt_options", ipopt_options)}
    first = fit(flights[0], model=model, air=air, gps_noise_std_mps=gps_noise_std_mps,
                wind=wind, wind_knot_s=wind_knot_s)
    basis, d = shared_drift(first)
    # the other sensors alone with the first sensor's wind model taken out of their GPS:
    # their start values, noise scale and kept samples
    singles = [first] + [fit(_first_wind_removed(f, basis, d), model=model, air=air,
                             gps_noise_std_mps=gps_noise_std_mps, wind="constant")
                         for f in flights[1:]]
    kept = [f.select(np.isin(f.time_s, r.time_s)) for f, r in zip(flights, singles)]
    parts = [_sensor_part(f, r, air, gps_noise_std_mps, basis) for f, r in zip(kept, singles)]
    t0 = time.perf_counter()
    x, stats, iv_ok = _estimate(parts, d, options)
    cov, colored = _sandwich(parts, x, iv_ok)
    elapsed = time.perf_counter() - t0
    shared = _SharedWind(basis, first.wind_model, iv_ok)
    return [complete(_sensor_result(i, parts, x, cov, stats, colored, elapsed, shared), f,
                     air=air, budget=inputs) for i, f in enumerate(kept)]


@dataclasses.dataclass(frozen=True)
class _Part:
    """One sensor of the joint problem."""

    model: object
    flight: object
    ch: object               # its channels, the drift not taken out (x carries it)
    air_data: str
    single: object           # its own fit (start values, noise scale, warnings)
    b: np.ndarray            # the drift basis at its samples, (N, m); m = 0: constant wind

    @property
    def sigma2(self):
        return max(float(np.mean(self.single.residuals_pa ** 2)), 1e-12)


@dataclasses.dataclass(frozen=True)
class _SharedWind:
    """What every sensor's result says of the shared wind model."""

    basis: object            # DriftBasis or None
    record: dict             # the first sensor's `wind_model`
    iv: bool                 # the instrumental-variable step converged


def _first_wind_removed(flight, basis, d):
    """`flight` with the first sensor's drift taken out and no windows, for its fit alone."""
    if basis is not None:
        flight = without_drift(flight, basis, d)
    return dataclasses.replace(flight, segment=None)


def _sensor_part(flight, single, air, gps_noise_std_mps, basis):
    mode = _air_data(flight, air)[0]
    b = (np.zeros((flight.n, 0)) if basis is None
         else basis.rows(flight.time_s, flight.segment))
    return _Part(get_model(single.model), flight, flight_channels(flight, gps_noise_std_mps, mode),
                 mode, single, b)


def _slices(parts):
    """theta's slice of each sensor's coefficients; the mean wind is theta's last two."""
    out, at = [], 0
    for p in parts:
        out.append(slice(at, at + len(p.model.params)))
        at += len(p.model.params)
    return out, at + 2


def _estimate(parts, d, options):
    """(x, solver stats, IV converged): x = (theta, d) by the joint Gauss-Newton from the
    first sensor's drift (skipped for a constant wind), IPOPT on theta given d, then the
    joint instrumental-variable equations in (theta, d)."""
    slices, n_theta = _slices(parts)
    start = np.concatenate([p.single.internal_params[:-2] for p in parts]
                           + [np.mean([p.single.internal_params[-2:] for p in parts], axis=0)])
    x = np.concatenate([start, d])
    if d.size:
        x = joint_gauss_newton(parts, slices, x, n_theta)
    given = [dataclasses.replace(p, ch=shifted(p.ch, p.b, x[n_theta:])) for p in parts]
    theta, stats = _solve(given, options, x[:n_theta])
    x = np.concatenate([theta, x[n_theta:]])
    if not stats.get("success", False):
        return x, stats, False
    x_iv, ok = joint_iv(parts, slices, x, n_theta, smoothed_qci(parts))
    return x_iv, stats, ok


def _solve(parts, options, start):
    """IPOPT on the sum of the sensors' objectives sharing the wind: (theta, solver stats)."""
    import casadi as ca

    slices, n_theta = _slices(parts)
    scales = x_scales(parts, 0)
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
    with solver_interrupts():
        sol = solver(x0=start / scales, p=ca.DM(np.concatenate(p_vals)))
    return np.asarray(sol["x"]).ravel() * scales, solver.stats()


def _sandwich(parts, x, iv):
    """(joint colored-residual covariance of x = (theta, d), the sum channel's
    `ColoredCovariance`; module Notes). `iv`: the coefficient rows' instruments in the meat
    and the bread (else the sensitivities)."""
    slices, n_theta = _slices(parts)
    smooth = smoothed_qci(parts) if iv else [None] * len(parts)
    base = parts[0].flight.time_s
    dt = max(float(np.median(np.diff(base))), 1e-9)
    n_s = len(parts)
    res = np.zeros((n_s, base.size))
    jac, inst = np.zeros((2, n_s, base.size, x.size))
    bread = np.zeros((x.size, x.size))
    # weights relative to the mean noise: the rows keep the residuals' own scale, Pa
    sigma_mean = np.sqrt(np.mean([p.sigma2 for p in parts]))
    for j, (p, sl, q) in enumerate(zip(parts, slices, smooth)):
        r, s, z = (v * (sigma_mean / np.sqrt(p.sigma2))
                   for v in sensor_terms(p, sl, x, n_theta, q)[:3])
        bread += z.T @ s
        # each sample onto the first sensor's nearest time step (the score adds there)
        step = np.clip(np.searchsorted(base, p.flight.time_s - dt / 2), 0, base.size - 1)
        np.add.at(res[j], step, r)
        np.add.at(jac[j], step, s)
        np.add.at(inst[j], step, z)
    # sum and contrast channels (orthonormal): the score sum_s Z_s r_s is unchanged, the
    # sensors' common turbulence lies in the sum channel, their own white noise in all
    q = _helmert(n_s)
    middle, first = np.zeros((x.size, x.size)), None
    for c in range(n_s):
        rc, jc = q[c] @ res, np.tensordot(q[c], jac, axes=1)
        # the noise model is fitted at the channel's independent sensitivity directions; with
        # information I the "covariance" returned is the middle of the sandwich itself
        colored = colored_covariance(_orthonormal_columns(jc), rc,
                                     velocity=jc[:, n_theta - 2:n_theta],
                                     information=np.eye(x.size),
                                     instruments=np.tensordot(q[c], inst, axes=1))
        middle += colored.covariance
        first = colored if first is None else first
    a_inv = _inverse(bread)
    return a_inv @ middle @ a_inv.T, first


def _inverse(a):
    try:
        return np.linalg.inv(a)
    except np.linalg.LinAlgError:
        return np.linalg.pinv(a)


def _orthonormal_columns(jac, rtol=1e-7):
    """B with jac = B T, B's columns orthogonal with unit RMS, directions along which jac has
    no extent dropped: a channel's sensitivities to k1 of every sensor are the same column
    (dr/dk1 follows from the shared wind and GPS alone), which the noise model's projection
    could not invert."""
    u, sv, _ = np.linalg.svd(jac, full_matrices=False)
    keep = sv > rtol * sv[0]
    return u[:, keep] * np.sqrt(jac.shape[0])


def _helmert(n):
    """An orthonormal n x n matrix whose first row is the mean direction 1/sqrt(n)."""
    q = np.zeros((n, n))
    q[0] = 1.0 / np.sqrt(n)
    for i in range(1, n):
        q[i, :i] = 1.0 / np.sqrt(i * (i + 1))
        q[i, i] = -i / np.sqrt(i * (i + 1))
    return q


def _sensor_result(i, parts, x, cov, stats, colored, elapsed, shared):
    """Sensor `i`'s `IdentificationResult`: its own fit's record with the joint numbers and
    the shared wind model."""
    part = parts[i]
    slices, n_theta = _slices(parts)
    idx = np.r_[np.arange(x.size)[slices[i]], n_theta - 2, n_theta - 1,
                np.arange(n_theta, x.size)]
    n_own = len(part.model.params) + 2
    c_whole = cov[np.ix_(idx, idx)]
    r, s, _, th, _ = sensor_terms(part, slices[i], x, n_theta)
    c = c_whole[:n_own, :n_own]
    plain = plain_covariance(s[:, idx], r)[:n_own, :n_own]
    params, cov_rep = to_reported(th, c)
    _, plain_rep = to_reported(th, plain)
    success = bool(stats.get("success", False))
    message = str(stats.get("return_status", "unknown"))
    warn = tuple(part.single.warnings) + (joint_note(i, len(parts), shared.record),)
    if colored.warning:
        warn += (colored.warning,)
    if success and not shared.iv:
        warn += (f"{IV_NOT_CONVERGED} in the sensors' joint fit; output-error estimate kept",)
    if not success:
        warn += (f"the joint fit of the sensors did not converge ({message}); the numbers "
                 "are not a calibration",)
    d = x[n_theta:]
    joint = dataclasses.replace(
        part.single, params=params, covariance=cov_rep, covariance_plain=plain_rep,
        internal_params=th, internal_covariance=c, internal_covariance_plain=plain,
        residuals_pa=r, noise_std_pa=float(np.sqrt(np.mean(r ** 2))), success=success,
        message=message, iterations=int(stats.get("iter_count", 0)), warnings=warn,
        param_names=tuple(part.model.params) + WIND_NAMES,
        timing_s={**part.single.timing_s, "joint": elapsed},
        drift=None if shared.basis is None else (shared.basis, d))
    record = {**(shared.record or {}), "shared_by_sensors": len(parts)}
    if shared.basis is None:
        joint = constant_wind(joint, record.get("chosen_by", "option"))
        return dataclasses.replace(joint, wind_model=record)
    return dataclasses.replace(joint, wind_model=record,
                               wind_track=wind_track(shared.basis, th, d, c_whole))


def joint_note(i, n_sensors, wind_model=None):
    """The warning line every sensor's result carries: what the joint fit shared."""
    kind = (wind_model or {}).get("kind", "constant")
    shared = "one shared wind" if kind == "constant" else f"one shared wind model ({kind})"
    return (f"airspeed sensor {i + 1} of {n_sensors}: fitted jointly with the other sensors, "
            f"{shared}; bounds from the colored residuals of all sensors together")



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
