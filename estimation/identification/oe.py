"""The output-error problem (paper section II, eqs. 1-4) in CasADi, solved with IPOPT.

One `OutputErrorProblem` per pressure-error structure. Its symbolic problem comes from small
named builders, `residual_function` → `objective_function` → the IPOPT solver: whole-vector MX
with one MX parameter per data channel, so the graph has a few dozen nodes whatever N is
(STYLE.md, CasADi). CasADi symbols have a fixed size, so the solver itself is built once per
(N, has-vertical-speed) and cached on the problem object: re-solving flights of the same
length (Monte Carlo, repeated windows) reuses it. After the solve, the coefficients are refined
with instrumental variables (`estimation.identification.iv`) and the covariance is corrected for colored
residuals (`estimation.uncertainty.covariance`).
"""

import logging
import time
from dataclasses import dataclass

import numpy as np

from pitotcal.core import checks
from pitotcal.core.measurement import AIR_CHANNELS, IncompressibleAir, as_air, tas_squared
from pitotcal.core.models import get_model
from pitotcal.core.processes import solver_interrupts

from ..uncertainty.covariance import (
    ColoredCovariance,
    colored_covariance,
    known_gps_error,
    plain_covariance,
)
from .iv import IV_NOT_CONVERGED, IV_WINDOW_S, iv_refine, smooth_in_time
from .residual import (
    flight_channels,
    ratio_columns,
    residual,
    residual_function,
    sensitivities,
)
from .result import IdentificationResult
from .unknowns import WIND_NAMES, theta_scales, to_reported

__all__ = ["DEFAULT_IPOPT_OPTIONS", "OutputErrorProblem", "objective_function",
           "objective_inputs", "start_values"]

log = logging.getLogger(__name__)

# tol: the objective is a mean scaled to O(1) at the start, so 1e-6 leaves a parameter error
# ~1e-6 in scaled units, far below any sigma. Tighter stalls on rounding in the gradient at
# N = 1e6 (docs/measured.md; measured here: tol 1e-8 took 4 extra line-search-bound iterations,
# +0.9 s, for a change in k1 of 1e-12).
DEFAULT_IPOPT_OPTIONS = {
    "print_level": 0,
    "sb": "yes",
    "tol": 1e-6,
    "acceptable_tol": 1e-5,
    "acceptable_iter": 5,
    "max_iter": 200,
}

# Solvers kept per problem object (one per flight length); a Monte Carlo study reuses one.
_CACHE_SIZE = 4

# The objective's scalar parameters: c_eiv = n sigma_v^2, pen_a = 4 sigma_v^2,
# pen_b = 2 n sigma_v^4 (the GPS-noise spread) and the weight w that makes J ~ O(1).
NOISE_TERMS = ("c_eiv", "pen_a", "pen_b", "weight")


def _data_names(has_vd, air_data="incompressible"):
    return ("qci", "vn", "ve", *AIR_CHANNELS[air_data]) + (("vd2",) if has_vd else ())


def objective_function(model, n, has_vd, air_data="incompressible"):
    """The corrected-score objective J (`OutputErrorProblem` Notes) as a named ``ca.Function``.

    Returns
    -------
    casadi.Function
        ``objective(x, qci, vn, ve, rho[, vd2], c_eiv, pen_a, pen_b, weight) -> J``, x the
        scaled unknowns theta / `theta_scales` (vd2 only when `has_vd`; ``pt, oat`` in place
        of ``rho`` when `air_data` is "compressible"). `residual_function` is inlined, so the
        graph stays whole-vector MX.
    """
    import casadi as ca

    residual_fn = residual_function(model, n, has_vd, air_data)
    x = ca.MX.sym("x", len(model.params) + 2)
    data = {name: ca.MX.sym(name, n) for name in _data_names(has_vd, air_data)}
    noise = {name: ca.MX.sym(name) for name in NOISE_TERMS}
    # element by element: a whole-vector x * DM(scales) made IPOPT's derivative functions
    # take 23 MB more at N = 1e6 (measured)
    theta = ca.vertcat(*(x[i] * scale for i, scale in enumerate(theta_scales(model))))
    air = [data[name] for name in AIR_CHANNELS[air_data]]
    r, a, tas_sq = residual_fn.call([theta, data["qci"], data["vn"], data["ve"], *air,
                                     data.get("vd2", 0.0), noise["c_eiv"]], True, False)
    spread = ca.dot(a * a, noise["pen_a"] * tas_sq - noise["pen_b"])
    objective = noise["weight"] * (ca.dot(r, r) - spread) / n
    # common subexpressions merged: the prediction and its slope share the pitot relation,
    # whose two branches (isentropic, Rayleigh) are both evaluated (125 -> 84 nodes)
    return ca.Function("objective", [x, *data.values(), *noise.values()], [ca.cse(objective)],
                       ["x", *data, *noise], ["J"])


@dataclass(frozen=True)
class _Built:
    solver: object          # ca.nlpsol: x = scaled unknowns, p = the inputs named p_names
    hessian: object         # the solver's own exact Hessian of the objective (upper triangle)
    p_names: tuple          # data channels, then NOISE_TERMS, in the order of p
    build_s: float


def _build_solver(model, n, has_vd, ipopt_options, air_data="incompressible"):
    """IPOPT on `objective_function`: x the scaled unknowns, p its other inputs in order."""
    import casadi as ca

    t0 = time.perf_counter()
    objective = objective_function(model, n, has_vd, air_data)
    args = objective.mx_in()
    nlp = {"x": args[0], "p": ca.vertcat(*args[1:]), "f": objective.call(args, True, False)[0]}
    opts = {"ipopt": dict(ipopt_options), "print_time": False}
    solver = ca.nlpsol(f"oe_{model.name}", "ipopt", nlp, opts)
    # IPOPT's exact Hessian is already built: reuse it for the covariance rather than
    # building ca.jacobian(r, x) (0.9 s of sparsity analysis at N = 1e6)
    return _Built(solver, solver.get_function("nlp_hess_l"), tuple(objective.name_in()[1:]),
                  time.perf_counter() - t0)


@dataclass(frozen=True)
class _Fit:
    """The refined estimate and its covariances, in the solver's parameters."""

    theta: np.ndarray
    residuals: np.ndarray
    covariance_plain: np.ndarray
    colored: ColoredCovariance
    warnings: tuple


class OutputErrorProblem:
    """Output-error identification of one pressure-error structure and a constant wind.

    Parameters
    ----------
    model : str
        Name of a structure in `pitotcal.core.models.MODELS` (`constant`, `linear`, `inverse`).
    ipopt_options : dict, optional
        IPOPT options (without the ``ipopt.`` prefix), merged over `DEFAULT_IPOPT_OPTIONS`.

    Notes
    -----
    Unknowns (`estimation.identification.unknowns`): the coefficients k divided by `model.scales`, and the
    wind velocity vector (wind_n, wind_e) in m/s (the way the air mass moves; no singularity in
    calm air). With V_t^2 = (V_gn - wind_n)^2 + (V_ge - wind_e)^2 [+ V_gd^2] (docs/interfaces.md §2)
    the output residual (`estimation.identification.residual`) is

        r = q_ci - (1 - f(q_ci; k)) * rho/2 * (V_t^2 - n sigma_v^2),

    the measured minus the predicted impact pressure, written with f evaluated at the
    measured q_ci (the regressor of the paper's eq. 4). Since q_ci = (1 - f) q_c exactly
    (eq. 1), this is the documented equivalent of "q_ci minus predicted q_ci".
    n sigma_v^2 (n = 2, or 3 with V_gd) removes the mean that GPS velocity noise sigma_v adds
    to V_t^2. The noise also makes the spread of the prediction depend on the unknowns, so
    the minimiser of sum(r^2) is still biased (by about 2 rho sigma_v^2 / q_c in f); the
    objective subtracts that expected spread (the corrected score of errors-in-variables
    regression, Nakamura 1990):

        J = w / N * sum_i [ r_i^2 - a_i^2 (4 sigma_v^2 V_t,i^2 - 2 n sigma_v^4) ],
        a_i = (1 - f(q_ci,i; k)) rho_i / 2,

    whose expectation over the GPS noise is the noise-free sum of squares plus a constant.
    That is the incompressible problem (paper eq. 2). The compressible one replaces
    rho/2 (V_t^2 - n sigma_v^2) by the isentropic q_c(V_t^2 - n sigma_v^2) of the measured total
    pressure (or a reference static pressure) and a_i by the local slope
    (1 - f) dq_c/dV_t^2 (`estimation.identification.residual`); the curvature of q_c(V_t^2) leaves a bias
    of about M^2/2 of the noise correction itself, negligible.
    w scales J to O(1) at the start. IPOPT uses the exact Hessian.

    Example
    -------
    >>> problem = OutputErrorProblem("inverse")            # doctest: +SKIP
    >>> result = problem.solve(flight)                     # doctest: +SKIP
    """

    def __init__(self, model="inverse", *, ipopt_options=None):
        self.model = get_model(model)   # ValueError naming the choices
        self.ipopt_options = {**DEFAULT_IPOPT_OPTIONS,
                              **checks.option_dict("ipopt_options", ipopt_options)}
        self._built = {}

    def _build(self, n, has_vd, air_data="incompressible"):
        """The solver for flights of `n` samples, built once and cached."""
        key = (n, has_vd, air_data)
        if key not in self._built:
            if len(self._built) >= _CACHE_SIZE:
                self._built.pop(next(iter(self._built)))
            self._built[key] = _build_solver(self.model, n, has_vd, self.ipopt_options,
                                             air_data)
            log.debug("built %s problem for N=%d in %.3f s", self.model.name, n,
                      self._built[key].build_s)
        return self._built[key]

    def solve(self, flight, *, gps_noise_std_mps=None, start=None, air_data="incompressible",
              gps_error=None, colored=True):
        """Identify the coefficients and the wind from `flight`.

        Parameters
        ----------
        flight : pitotcal.core.flight.Flight
        gps_noise_std_mps : float, optional
            GPS velocity noise per component, m/s; estimated from the data when None
            (`pitotcal.core.gps_velocity.estimate_gps_noise_std`).
        start : ndarray, optional
            Start values (k..., wind_n_mps, wind_e_mps); the linear least-squares start
            (`start_values`) when None.
        air_data : {"incompressible", "compressible", "reference"}
            How q_c follows from V_t (`estimation.identification.residual`): "compressible" from the
            flight's `ps_pa` + q_ci and `oat_k`, "reference" from its `ps_ref_pa` and
            `oat_k` (`estimation.identify` checks and chooses; both report "compressible").
        gps_error : (float, float), optional
            (sigma_mps, tau_s) of a stated Gauss-Markov GPS velocity error: a known term of
            the colored-residual covariance (`covariance.colored_covariance`).
        colored : bool
            False: no colored-residual covariance (`covariance` is the plain one), for
            re-solves that use only the estimate (`estimation.identification.budget`).

        Returns
        -------
        IdentificationResult
            Every field filled; no observability checks here (`estimation.identify` does them).
        """
        built = self._build(flight.n, flight.gps_vd_mps is not None, air_data)
        timing = {"build": built.build_s}
        t0 = time.perf_counter()
        ch = flight_channels(flight, gps_noise_std_mps, air_data)
        theta0 = (np.asarray(start, dtype=float) if start is not None
                  else start_values(self.model, ch.qci, ch.vn, ch.ve, ch.air, ch.vd2, ch.c_eiv))
        x_opt, p_val, weight, stats = _minimise(self.model, built, ch, theta0)
        timing["solve"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        fit = _refine(self.model, built, x_opt, p_val, weight, ch, flight.time_s, gps_error,
                      colored)
        timing["covariance"] = time.perf_counter() - t0
        return _result(self.model, flight, ch, fit, stats, timing, air_data)


def _minimise(model, built, ch, theta0):
    """Run IPOPT from theta0; returns (x_opt, p_val, weight, stats)."""
    import casadi as ca

    r0 = residual(model, theta0, *ch.args)
    # robust scale of the start residuals: makes J ~ O(1) whatever the noise level
    s0 = 1.4826 * np.median(np.abs(r0 - np.median(r0)))
    s0 = max(s0, 1e-6 * float(np.mean(ch.qci)), 1e-9)
    weight = 1.0 / s0 ** 2
    p_val = ca.DM(np.concatenate(objective_inputs(ch, weight, built.p_names)))
    with solver_interrupts():
        sol = built.solver(x0=theta0 / theta_scales(model), p=p_val)
    return np.asarray(sol["x"]).ravel(), p_val, weight, built.solver.stats()


def objective_inputs(ch, weight, names):
    """The values of `objective_function`'s inputs `names` (after x), each a 1-d array: the
    data channels of `ch` (`flight_channels`), its GPS-noise terms and the weight."""
    values = {"qci": ch.qci, "vn": ch.vn, "ve": ch.ve, "rho": ch.rho, "vd2": ch.vd2,
              "pt": ch.pt, "oat": ch.oat, "ps_ref": ch.ps_ref,
              "c_eiv": ch.c_eiv, "pen_a": 4.0 * ch.var_v,
              "pen_b": 2.0 * ch.n_comp * ch.var_v ** 2, "weight": weight}
    return [np.atleast_1d(values[name]) for name in names]


def _refine(model, built, x_opt, p_val, weight, ch, time_s, gps_error=None, colored=True):
    """Instrumental-variable refinement and both covariances at the output-error optimum."""
    warn = []
    scales = theta_scales(model)
    theta = x_opt * scales
    jac = sensitivities(model, theta, *ch.args)
    info = _information(built.hessian, x_opt, p_val, scales, ch.qci.size, weight, jac)
    q_smooth = smooth_in_time(ch.qci, time_s, IV_WINDOW_S)
    theta_iv, instruments, jac_iv = iv_refine(model, theta, ch, q_smooth)
    if instruments is None:
        warn.append(f"{IV_NOT_CONVERGED}; output-error estimate kept")
    else:
        theta, jac = theta_iv, jac_iv
    residuals = residual(model, theta, *ch.args)
    cov_plain = plain_covariance(jac, residuals, information=info)
    known = known_gps_error(gps_error, time_s)
    cov = ColoredCovariance(cov_plain, 0, "none (not computed)", 0.0) if not colored else \
        colored_covariance(jac, residuals, velocity=jac[:, -2:], known_velocity=known,
                           information=info if instruments is None else instruments.T @ jac,
                           instruments=instruments)    # not colored: the estimate alone
    warn += [w for w in (cov.warning, _gap_warning(time_s)) if w]
    return _Fit(theta, residuals, cov_plain, cov, tuple(warn))


def _result(model, flight, ch, fit, stats, timing, air_data="incompressible"):
    """The `IdentificationResult` of a solve and its refinement."""
    params, cov = to_reported(fit.theta, fit.colored.covariance)
    _, cov_plain = to_reported(fit.theta, fit.covariance_plain)
    success = bool(stats.get("success", False))
    message = str(stats.get("return_status", "unknown"))
    warn = fit.warnings
    if not success:
        warn += (f"solver did not converge ({message}); the numbers are not a calibration",)
    return IdentificationResult(
        model=model.name,
        param_names=tuple(model.params) + WIND_NAMES,
        params=params,
        covariance=cov,
        covariance_plain=cov_plain,
        internal_params=fit.theta,
        internal_covariance=fit.colored.covariance,
        internal_covariance_plain=fit.covariance_plain,
        success=success,
        message=message,
        iterations=int(stats.get("iter_count", 0)),
        n_samples=flight.n,
        noise_std_pa=float(np.sqrt(np.mean(fit.residuals ** 2))),
        gps_noise_std_mps=ch.sigma_v,
        time_s=flight.time_s,
        qci_pa=flight.qci_pa,
        rho_kgm3=flight.rho_kgm3,
        residuals_pa=fit.residuals,
        warnings=warn,
        air_data="incompressible" if air_data == "incompressible" else "compressible",
        ps_pa=flight.ps_pa if air_data != "incompressible" else None,
        ps_ref_pa=flight.ps_ref_pa if air_data == "reference" else None,
        timing_s=timing,
    )


def _information(hessian, x_opt, p_val, scales, n, weight, jac):
    """Information matrix M (= S^T S at a least-squares optimum) from CasADi's exact Hessian.

    The objective is weight/N * sum(r^2 - spread) in the scaled unknowns x = theta / scales,
    so M = N / (2 weight) * D^-1 H D^-1, D = diag(scales). Falls back to the Gauss-Newton
    S^T S when the Hessian is not positive definite (a solver that did not converge).
    """
    upper = np.asarray(hessian(x_opt, p_val, 1.0, np.zeros(0)))
    h = upper + upper.T - np.diag(np.diag(upper))
    info = n / (2.0 * weight) * h / np.outer(scales, scales)
    if not np.all(np.isfinite(info)) or np.linalg.eigvalsh(info).min() <= 0:
        return jac.T @ jac
    return info


def start_values(model, qci_pa, vn_mps, ve_mps, air, vd2=None, c_eiv=0.0):
    """Start values (k..., wind_n_mps, wind_e_mps) by linear least squares, any wind.

    Parameters
    ----------
    air : ndarray or (ndarray, ndarray)
        Density rho, kg/m^3 (incompressible), or total pressure and static temperature
        (p_T Pa, T_s K) (compressible; `estimation.identification.residual`).

    Notes
    -----
    With c = 1 - k1 and a constant ratio, 2 q_ci / rho = c (|V_g|^2 - c_eiv) - 2 c V_g . W
    + c |W|^2 is linear in (c, c wind_n, c wind_e, c |W|^2): one least-squares solve gives the
    wind from any direction and speed (the problem is not convex in the wind direction, so a
    start from the data matters). Compressible, the left side is the V_t^2 whose q_c is q_ci
    (about (1 - k1) V_t^2 too). The remaining coefficients then come from a Gauss-Newton
    fit of the per-sample ratio 1 - q_ci / q_c(W) to the model.
    """
    air = as_air(air)
    y = air.tas_sq(qci_pa)                                 # about (1 - f) V_t^2
    v2g = tas_squared(vn_mps, ve_mps, 0.0, 0.0, vd2) - c_eiv  # |V_g|^2 - c_eiv
    design = np.column_stack([v2g, -2.0 * vn_mps, -2.0 * ve_mps, np.ones_like(y)])
    colscale = np.sqrt(np.mean(design ** 2, axis=0))
    beta = np.linalg.lstsq(design / colscale, y, rcond=None)[0] / colscale
    c = beta[0] if abs(beta[0]) > 1e-6 else 1.0
    wn, we = beta[1] / c, beta[2] / c
    k = np.zeros(len(model.params))
    k[0] = 1.0 - c
    # Gauss-Newton on the ratio (exact in one step for models linear in k)
    tas_sq = tas_squared(vn_mps, ve_mps, wn, we, vd2) - c_eiv
    qc = air.qc_pa(tas_sq if isinstance(air, IncompressibleAir) else np.maximum(tas_sq, 0.0))
    ok = qc > 0
    ratio = 1.0 - qci_pa[ok] / qc[ok]
    q = qci_pa[ok]
    for _ in range(2):
        step = np.linalg.lstsq(np.column_stack(ratio_columns(model, k, q)), ratio - model(k, q),
                               rcond=None)[0]
        k = k + step
    return np.concatenate([k, [wn, we]])


def _gap_warning(time_s):
    """Warn when gaps are not rare: the colored-residual correction counts lags in samples."""
    dt = np.diff(time_s)
    if dt.size == 0:
        return None
    gaps = dt > 1.5 * np.median(dt)
    if gaps.mean() > 0.01:
        return (f"{gaps.sum()} time gaps ({100 * gaps.mean():.1f}% of steps): the colored-residual "
                "bounds count lags in samples and may be off")
    return None
