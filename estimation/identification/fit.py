"""The output-error fit behind `identify`: checks, gates, outlier trimming, model choice.

`estimate` is the fit alone (the uncertainty budget's re-solves use it); `identify`
(`estimation.identification.identify`) adds the bounds' record to it.
"""

import dataclasses
import functools
import logging

import numpy as np

from pitotcal.core import checks
from pitotcal.core.errors import FlightDataError, ObservabilityError, PitotcalError
from pitotcal.core.flight import MIN_TRACK_SPREAD_DEG, track_spread_deg
from pitotcal.core.measurement import AIR_DATA_MODES, DEFAULT_AIR_DATA
from pitotcal.core.models import MODELS, get_model
from pitotcal.core.scenario import GPS_NOISE_MAX_MPS

from ..robustness import consistency, gates
from . import static_source
from .oe import OutputErrorProblem
from .unknowns import WIND_INTERNAL
from .wind_drift import check_wind_options, fit_wind

__all__ = ["MAX_CORRELATION", "MIN_QCI_SPAN", "MIN_SAMPLES", "MIN_TRACK_SPREAD_DEG", "estimate",
           "fit", "track_spread_deg"]

log = logging.getLogger(__name__)

MIN_SAMPLES = 50
# k1 and the second coefficient separate only over a spread of q_ci: (q98 - q2) / median.
MIN_QCI_SPAN = 0.05
# Above this |correlation| (plain information matrix) two parameters are not separable.
MAX_CORRELATION = 0.9995

# Problems are cached per (structure, IPOPT options): building costs more than solving.
_PROBLEMS = {}
_TRIM_ROUNDS = 3


def fit(flight, model="inverse", *, air=DEFAULT_AIR_DATA, gps_noise_std_mps=None,
        ipopt_options=None, gps_error_sigma_mps=None, gps_error_tau_s=None, wind="auto",
        wind_knot_s=None):
    """The fit with its bounds (colored-residual covariance, consistency checks): `identify`
    without the result record's products (noise model, static-error fit, budget)."""
    return _identify(flight, model, air, gps_noise_std_mps, ipopt_options,
                     (gps_error_sigma_mps, gps_error_tau_s), (wind, wind_knot_s), bounds=True)


def estimate(flight, model="inverse", *, air=DEFAULT_AIR_DATA, gps_noise_std_mps=None,
             ipopt_options=None, gps_error_sigma_mps=None, gps_error_tau_s=None, wind="auto",
             wind_knot_s=None):
    """`identify`'s estimate alone, for re-solves that use only it (`estimation.identification.budget`).

    The same checks, gates, outlier trimming and fit, so the same parameters; without the
    colored-residual covariance and the consistency checks: `covariance` is the plain one and
    `consistency` is empty, so its bounds are not the result's.
    """
    return _identify(flight, model, air, gps_noise_std_mps, ipopt_options,
                     (gps_error_sigma_mps, gps_error_tau_s), (wind, wind_knot_s), bounds=False)


def _identify(flight, model, air, gps_noise_std_mps, ipopt_options, gps_error, wind, *,
              bounds):
    """`identify` (`bounds` True) or `estimate` (False); `wind` is (mode, knot spacing s)."""
    checks.choice("model", model, (*MODELS, "auto"))
    wind, knot_s = check_wind_options(*wind)
    if gps_noise_std_mps is not None:
        gps_noise_std_mps = checks.number("gps_noise_std_mps", gps_noise_std_mps, 0.0,
                                          GPS_NOISE_MAX_MPS)
    ipopt_options = checks.option_dict("ipopt_options", ipopt_options)
    checks.choice("air", air, AIR_DATA_MODES)
    gps_error = _gps_error(*gps_error, flight)
    air_data, air_note = _air_data(flight, air)
    _check_flight(flight, air_data)
    flight, gate_note = gates.gate_flight(flight)
    _check_flight(flight, air_data)
    _check_track(flight)
    fitter = functools.partial(
        _identify_any, model=model, gps_noise_std_mps=gps_noise_std_mps,
        ipopt_options=ipopt_options, air_data=air_data, gps_error=gps_error, colored=bounds)
    result, trim_note = fit_wind(
        flight, functools.partial(_fit_trimmed, fit=fitter, air_data=air_data, check=bounds),
        wind=wind, knot_s=knot_s, gps_noise_std_mps=gps_noise_std_mps, air_data=air_data,
        gps_error=gps_error)
    # the reader's warnings first, so the record (to_dict, the JSON) carries every warning
    warn = tuple(dict.fromkeys(tuple(flight.warnings) + gate_note + trim_note
                               + tuple(result.warnings) + air_note))
    return dataclasses.replace(result, warnings=warn)


def _identify_any(flight, *, model, gps_noise_std_mps, ipopt_options, air_data, gps_error,
                  colored=True):
    if model == "auto":        # the criterion needs the colored covariance: always computed
        return _identify_auto(flight, gps_noise_std_mps, ipopt_options, air_data, gps_error)
    return _identify_one(flight, model, gps_noise_std_mps, ipopt_options, air_data, gps_error,
                         colored)


def _gps_error(sigma_mps, tau_s, flight=None):
    """(sigma_mps, tau_s) of a stated Gauss-Markov GPS velocity error, or None; both or
    neither given; tau no shorter than the `flight`'s sample interval (a faster error is
    white noise, which the fit measures itself)."""
    if sigma_mps is None and tau_s is None:
        return None
    if sigma_mps is None or tau_s is None:
        missing = "gps_error_tau_s" if tau_s is None else "gps_error_sigma_mps"
        raise PitotcalError(f"{missing}: state the GPS velocity error's sigma and correlation "
                            "time together", param=missing)
    sigma = checks.number("gps_error_sigma_mps", sigma_mps, 0.0, 10.0)
    tau = checks.positive("gps_error_tau_s", tau_s)
    dt = float(np.median(np.diff(flight.time_s))) if flight is not None and flight.n > 1 else 0.0
    if tau < dt:
        raise PitotcalError(f"gps_error_tau_s {tau:g} s is shorter than the sample interval "
                            f"({dt:g} s): an error that fast is white noise, which the fit "
                            f"measures itself; state a correlation time of at least {dt:g} s",
                            param="gps_error_tau_s")
    return sigma, tau


def _fit_trimmed(flight, fit, air_data, check=True):
    """(result, warnings): the fit, refitted without the samples `gates.outliers` finds.

    Up to `_TRIM_ROUNDS` rounds; each refit's residuals are judged again on the kept samples.
    More than `gates.MAX_TRIM_FRACTION` trimmed is refused: the noise is not the Gaussian
    the bounds assume, and no trimming threshold makes them honest. `check` False skips the
    consistency checks (`estimate`).
    """
    keep = np.ones(flight.n, dtype=bool)
    result = fit(flight)
    for _ in range(_TRIM_ROUNDS):
        out = gates.outliers(result.residuals_pa)
        if not out.any():
            break
        keep[np.flatnonzero(keep)[out]] = False
        if (~keep).mean() > gates.MAX_TRIM_FRACTION:
            raise ObservabilityError(
                f"{flight.source}: {int((~keep).sum())} samples ({100 * (~keep).mean():.1f}%) "
                f"have residuals beyond {gates.trim_threshold(flight.n):.1f} sigma (more than "
                f"{100 * gates.MAX_TRIM_FRACTION:.0f}%): the data cannot support a calibration; "
                "look for a leak, a blockage or a bad channel")
        result = fit(flight.select(keep))
    kept = flight.select(keep) if not keep.all() else flight
    if check:                   # the record's static-error fit, once, before anything uses it
        result = _with_static_fit(result)
    step_note, found = _consistency(kept, result, air_data) if result.success and check \
        else ((), {})
    cut = consistency.collapse_onset_s(found, kept.time_s) if found else None
    if cut is not None:
        try:
            result, step_note, found = _without_collapse(kept, fit, air_data, cut, found)
        except PitotcalError as exc:    # what is left cannot be fitted: the whole, named
            step_note = (f"{flight.source}: q_ci collapses at the end of the record (from "
                         f"about t = {cut:.0f} s){_scan_text(found)}: a "
                         "blocked pitot or icing? The calibration below is fitted on the "
                         "whole record because the samples before it cannot be fitted alone "
                         f"({exc}); do not use it",) + tuple(step_note)
    result = dataclasses.replace(result, consistency=found)
    if keep.all():
        return result, step_note
    return result, (
        (f"{flight.source}: {int((~keep).sum())} samples trimmed as outliers (residual beyond "
        f"{gates.trim_threshold(flight.n):.1f} sigma of the fitted noise, a false-trim rate of "
        f"{gates.FALSE_TRIM_RATE:g} per flight under Gaussian noise) and the fit repeated "
        f"without them: {gates.spans_text(flight.time_s, ~keep)}"),) + step_note


def _without_collapse(flight, fit, air_data, cut_s, found):
    """(result, warnings, consistency): the fit refitted on the samples before `cut_s`, the
    collapsed tail of q_ci (`consistency.collapse_onset_s`) removed and named; the
    consistency checks repeated on what is kept."""
    head = flight.select(flight.time_s < cut_s)
    result = _with_static_fit(fit(head))
    note = (f"{flight.source}: q_ci collapses at the end of the record: by the end "
            f"({flight.time_s[-1]:.0f} s) it reads {100 * found['end_ratio']:.0f}% of the "
            f"impact pressure the GPS and the wind give (median over the record: 100%)"
            f"{_scan_text(found)}: a blocked pitot or icing? The samples from "
            f"t = {cut_s:.0f} s on ({int(flight.n - head.n)}) are removed and the calibration "
            f"is fitted on t = {head.time_s[0]:.0f}-{head.time_s[-1]:.0f} s")
    step_note, again = _consistency(head, result, air_data) if result.success else ((), {})
    return result, (note,) + tuple(step_note), {**again, "collapse": {
        "onset_s": found["onset_s"], "kind": found["kind"], "step": found["step"],
        "z": found["z"], "flagged": found["flagged"], "end_ratio": found["end_ratio"],
        "removed_from_s": float(cut_s), "n_removed": int(flight.n - head.n)}}


def _scan_text(found):
    """The step test's part of the collapse warning: its onset and z when it flagged."""
    if not found["flagged"]:
        return ""
    return (f"; the consistency scan puts a {found['kind']} from about "
            f"t = {found['onset_s']:.0f} s, z = {found['z']:+.1f}")


def _consistency(flight, result, air_data):
    """`consistency.check`, or (its warning, {}) when the data refuse a test: a diagnostic
    beside the fit never takes the calibration down."""
    try:
        return consistency.check(flight, result, air_data)
    except PitotcalError as exc:
        return (f"{flight.source}: the consistency checks (step, jump, hidden change) were "
                f"not computed: {exc}",), {}


def _with_static_fit(result):
    """`result` with its measured static-error fit (`static_source.static_error_fit`) when it
    has a reference static pressure: fitted here once, for the record and every view of it."""
    if result.air_data != "compressible" or result.ps_pa is None or result.ps_ref_pa is None:
        return result
    return dataclasses.replace(result, static_fit=static_source.static_error_fit(result))


def _identify_auto(flight, gps_noise_std_mps, ipopt_options, air_data, gps_error=None):
    """Every structure in MODELS, the one with the lowest BIC kept.

    BIC = N_eff ln(RSS / N) + p ln(N_eff), N_eff = N median_j(P_jj / C_jj) clipped to [1, N],
    P the plain and C the colored-residual covariance of the lowest-RSS candidate, in the
    solver's parameters: N divided by the variance inflation the reported bounds carry, so
    the criterion and the bounds use one noise model. At 50 Hz the residuals are correlated
    over hundreds of samples; the plain N would reward any extra coefficient that fits
    turbulence. (A Bartlett long-run variance of the residuals, the earlier N_eff, made the
    same choices on the test flights but counted about twice as many samples in turbulence,
    because its taper underestimates the long-run variance.)
    """
    results, candidates = {}, []
    for name in MODELS:
        try:
            results[name] = _identify_one(flight, name, gps_noise_std_mps, ipopt_options,
                                          air_data, gps_error)
        except ObservabilityError as exc:
            candidates.append({"model": name, "bic": None, "error": str(exc)})
    if not results:
        raise ObservabilityError(f"no model structure is identifiable: {candidates[0]['error']}")
    best_rss = min(results.values(), key=lambda r: float(r.residuals_pa @ r.residuals_pa))
    n_eff = _effective_n(best_rss)
    candidates += [_candidate(res, n_eff) for res in results.values()]
    ok = [c for c in candidates if c["bic"] is not None and c["converged"]] or \
         [c for c in candidates if c["bic"] is not None]
    chosen = min(ok, key=lambda c: c["bic"])["model"]
    order = {name: i for i, name in enumerate(MODELS)}
    candidates.sort(key=lambda c: order[c["model"]])
    return dataclasses.replace(results[chosen], candidates=tuple(candidates),
                               criterion="BIC with effective N (N / variance inflation of the "
                                         "colored-residual covariance)")


def _candidate(result, n_eff):
    """One row of `candidates`: BIC = N_eff ln(RSS / N) + p ln(N_eff) and the estimate."""
    rss = float(result.residuals_pa @ result.residuals_pa)
    p = result.internal_params.size
    bic = n_eff * np.log(rss / result.n_samples) + p * np.log(n_eff)
    return {"model": result.model, "bic": float(bic), "n_eff": float(n_eff),
            "n_params": int(p), "noise_std_pa": result.noise_std_pa,
            "converged": result.success,
            "params": dict(zip(result.param_names, map(float, result.params)))}


def _identify_one(flight, model, gps_noise_std_mps, ipopt_options, air_data, gps_error=None,
                  colored=True):
    m = get_model(model)
    if len(m.params) > 1:
        _check_qci_span(flight, m)
    key = (model, tuple(sorted(ipopt_options.items())))
    if key not in _PROBLEMS:
        _PROBLEMS[key] = OutputErrorProblem(model, ipopt_options=ipopt_options)
    result = _PROBLEMS[key].solve(flight, gps_noise_std_mps=gps_noise_std_mps,
                                  air_data=air_data, gps_error=gps_error, colored=colored)
    if result.success:
        _check_information(result)
    return result


def _air_data(flight, air):
    """(the air-data mode used, warnings): compressible needs the flight's ps_pa and oat_k."""
    if air == "compressible" and flight.ps_ref_pa is not None and flight.ps_pa is not None \
            and flight.oat_k is not None:
        return "reference", ()
    if air == "compressible" and (flight.ps_pa is None or flight.oat_k is None):
        return "incompressible", ((
            f"{flight.source}: no static pressure and temperature (ps_pa, oat_k): fitted with "
            "the incompressible q_c = rho V_t^2 / 2 (`air` incompressible), so V_c and dV "
            "are sqrt(2 q / rho0), not the standard calibrated airspeed; give ps_pa and oat_k "
            "for the compressible calibration"),)
    return air, ()


def _check_flight(flight, air_data="incompressible"):
    n = flight.n
    if n < MIN_SAMPLES:
        raise FlightDataError(f"{flight.source}: {n} samples; identification needs at least {MIN_SAMPLES}")
    air = {"compressible": ("ps_pa", "oat_k"),
           "reference": ("ps_pa", "oat_k", "ps_ref_pa")}.get(air_data, ())
    for name in ("qci_pa", "gps_vn_mps", "gps_ve_mps", "rho_kgm3", "gps_vd_mps", *air):
        values = getattr(flight, name)
        if values is None:
            continue
        if values.shape != (n,):
            raise FlightDataError(f"{flight.source}: {name} has shape {values.shape}, expected ({n},)")
        bad = ~np.isfinite(values)
        if bad.any():
            raise FlightDataError(f"{flight.source}: {name}, row {int(np.argmax(bad)) + 1}: not finite")
        if name in air and np.any(values <= 0):
            raise FlightDataError(f"{flight.source}: {name}, row "
                                  f"{int(np.argmax(values <= 0)) + 1}: not positive")


def _check_track(flight):
    spread = track_spread_deg(flight.gps_vn_mps, flight.gps_ve_mps)
    if spread <= MIN_TRACK_SPREAD_DEG:
        raise ObservabilityError(
            f"{flight.source}: the ground track turns through only {spread:.0f} deg (need more "
            f"than {MIN_TRACK_SPREAD_DEG:.0f}): wind and calibration cannot be separated; fly turns")


def _check_qci_span(flight, model):
    q2, q50, q98 = np.percentile(flight.qci_pa, [2, 50, 98])
    span = (q98 - q2) / q50
    if span < MIN_QCI_SPAN:
        raise ObservabilityError(
            f"{flight.source}: q_ci spans only {100 * span:.1f}% of its median (need "
            f">= {100 * MIN_QCI_SPAN:.0f}%) to separate {model.params[0]} from {model.params[1]} "
            f"in the {model.name} model; fly a speed range or use the constant model")


def _check_information(result):
    cov = result.internal_covariance_plain
    s = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(s, s)
    names = tuple(get_model(result.model).params) + WIND_INTERNAL
    np.fill_diagonal(corr, 0.0)
    if not np.all(np.isfinite(corr)):
        raise ObservabilityError("the information matrix is singular: wind and calibration "
                                 "cannot be separated")
    i, j = np.unravel_index(np.argmax(np.abs(corr)), corr.shape)
    if abs(corr[i, j]) > MAX_CORRELATION:
        raise ObservabilityError(
            f"near-singular information matrix: {names[i]} and {names[j]} correlated "
            f"{corr[i, j]:+.5f}; the data cannot separate them")


def _effective_n(result):
    """N / the variance inflation of the colored-residual covariance (see `_identify_auto`).

    Falls back to the residuals' Bartlett long-run variance ratio when the covariance has no
    finite positive diagonal (a solve that did not converge).
    """
    n = result.n_samples
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.diag(result.internal_covariance_plain) / np.diag(result.internal_covariance)
    ratio = ratio[np.isfinite(ratio) & (ratio > 0)]
    if ratio.size:
        return float(np.clip(n * np.median(ratio), 1.0, n))
    return _effective_n_long_run(result)


def _effective_n_long_run(result):
    from ..uncertainty.covariance import lag_weights, residual_acf, truncation_lag

    r = result.residuals_pa
    lag, _ = truncation_lag(r)
    acov = residual_acf(r, lag)
    w = lag_weights(lag)
    long_run = acov[0] + 2.0 * float(np.sum(w[1:] * acov[1:]))
    return float(np.clip(r.size * acov[0] / max(long_run, 1e-300), 1.0, r.size))
