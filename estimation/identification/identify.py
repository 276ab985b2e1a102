"""`identify`: the public entry point of the output-error calibration.

The fit itself is `estimation.identification.fit`; `complete` adds, once, everything the result
record carries (its JSON: `estimation.identification.record`).
"""

import dataclasses
import functools

import numpy as np

from pitotcal.core import checks
from pitotcal.core.errors import PitotcalError
from pitotcal.core.measurement import DEFAULT_AIR_DATA, INCOMPRESSIBLE_MACH_MAX, flight_mach
from pitotcal.core.moist_air import at_mach
from pitotcal.core.scenario import HIDES_THRESHOLD_KT
from pitotcal.core.units import wind_vector_mps
from pitotcal.io.result_record import check_noise_model

from ..robustness.consistency import hides_threshold, with_hides_threshold
from ..uncertainty.block_noise import block_residual_stats
from . import static_source
from .budget import BudgetInputs, lever_arm_corrected, uncertainty_budget
from .fit import (
    MAX_CORRELATION,
    MIN_QCI_SPAN,
    MIN_SAMPLES,
    MIN_TRACK_SPREAD_DEG,
    estimate,
    fit,
    track_spread_deg,
)
from .view import correction_table
from .wind_drift import without_drift

__all__ = ["MAX_CORRELATION", "MIN_QCI_SPAN", "MIN_SAMPLES", "MIN_TRACK_SPREAD_DEG",
           "TEMPERATURE_TOL_K", "budget_inputs", "complete", "estimate", "identify", "track_spread_deg"]


def identify(flight, model="inverse", *, air=DEFAULT_AIR_DATA, gps_noise_std_mps=None,
             ipopt_options=None, gps_error_sigma_mps=None, gps_error_tau_s=None, budget=None,
             probe_arm_m=0.0, wind="auto", wind_knot_s=None,
             hides_threshold_kt=HIDES_THRESHOLD_KT):
    """Identify the pressure-error model and the wind from one calibration flight.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
        Time, measured impact pressure q_ci, GPS ground velocity, density (SI).
    model : {"inverse", "constant", "linear", "auto"}
        Pressure-error structure (docs/interfaces.md §2); "auto": the lowest BIC of `MODELS`.
    air : {"compressible", "incompressible"}
        How the impact pressure follows from the true airspeed (`pitotcal.core.measurement`):
        isentropic from the flight's static pressure `ps_pa` (the static port's reading) and
        temperature `oat_k`, with all the pressure error in the static source (the default,
        `DEFAULT_AIR_DATA`, which `simulate` flies), or the paper's eq. 2, q_c = ½ρV_t²
        ("incompressible"). A flight without `ps_pa` and `oat_k` is fitted incompressible
        with a warning. With an independent reference static pressure `ps_ref_pa` as well,
        q_c is predicted from it instead, and the static and total pressure errors are
        separated (`estimation.identification.static_source`).
    gps_noise_std_mps : float, optional
        GPS velocity noise per component, m/s, for the errors-in-variables correction;
        estimated from the data when None.
    ipopt_options : dict, optional
        IPOPT options (without the ``ipopt.`` prefix), e.g. ``{"max_iter": 50}``.
    gps_error_sigma_mps, gps_error_tau_s : float, optional
        The GPS receiver's Gauss-Markov velocity error (m/s, s; both or neither).
    budget : BudgetInputs or True, optional
        Compute the GUM uncertainty budget of the airspeed correction
        (`estimation.identification.budget`) with these Type B inputs (True: the defaults);
        by the fit's sensitivities (`budget`: no solve unless a term is not linear, then up
        to 16 re-solves). None (the default): no budget.
    probe_arm_m : float
        Lateral position of the pitot probe, m (right wing +), corrected in the data
        (`_fit_corrected`); the record's `reading` keeps it. Default 0.
    wind, wind_knot_s : {"auto", "constant", "drifting"}, float or None
        The wind model and a drift's knot spacing, s (`wind_drift.fit_wind`; None: 300 s).
    hides_threshold_kt : float
        ΔV shift, kt, of a missed leak above which the maneuver is said to hide one (`hides`).

    Returns
    -------
    IdentificationResult
        params/std (k..., wind_speed_mps, wind_from_deg), covariance (colored-residual
        corrected) and covariance_plain, residuals, success/message/iterations, warnings
        (the flight's own, from its reader, first), candidates/criterion with "auto", timing_s;
        and the result record's products, each computed once here: `monitor_noise` (the
        residuals' noise model `pitotcal monitor` designs from), `static_fit` (the measured
        static-error fit, with a reference static pressure), `budget`, `gps_error` (the
        statement), `reading`, `source`, `n_dropped`, `wind_model` and `wind_track`.
        `to_dict()` is the record `pitotcal identify --json` writes.

    Raises
    ------
    PitotcalError
        Unknown model, bad option.
    FlightDataError
        Too few samples, non-finite values.
    ObservabilityError
        The data cannot separate the wind from the calibration: track spread below
        MIN_TRACK_SPREAD_DEG, q_ci span too narrow for a two-coefficient model, or a
        near-singular information matrix (|correlation| > MAX_CORRELATION).

    Notes
    -----
    Non-convergence is a result, not an exception: `success` False, IPOPT's status in `message`.
    "auto" uses the BIC with an effective sample size (`_identify_auto`).

    Example
    -------
    >>> from tests.synthetic import synthetic_flight        # doctest: +SKIP
    >>> identify(synthetic_flight(seed=1)[0]).value("k2")    # doctest: +SKIP
    -15.0...
    """
    inputs, kt = budget_inputs(budget), hides_threshold(hides_threshold_kt)
    arm_m = checks.number("probe_arm_m", probe_arm_m, -50.0, 50.0)
    options = {"air": air, "gps_noise_std_mps": gps_noise_std_mps, "ipopt_options": ipopt_options,
               "gps_error_sigma_mps": gps_error_sigma_mps, "gps_error_tau_s": gps_error_tau_s,
               "wind": wind, "wind_knot_s": wind_knot_s}
    flight, result = _fit_corrected(flight, model, arm_m, options)
    refit = functools.partial(fit, model=model, **options)
    result, flight = _at_calibrated_mach(result, flight, refit)
    return with_hides_threshold(complete(result, flight, air=air, budget=inputs, gps_error=(
        gps_error_sigma_mps, gps_error_tau_s)), kt)


# The total-to-static temperature conversion is iterated until T_s moves less than this, K
TEMPERATURE_TOL_K = 0.005
_MAX_TEMPERATURE_PASSES = 4


def _at_calibrated_mach(result, flight, refit):
    """(result, flight) with the static temperature made from the total one (`tat_k`) at the
    calibration's true Mach instead of the indicated one, fitted again until it settles.

    The reader converts T_t with the indicated Mach (q_ci / p_s,ind), the only one it has:
    off by the position error's ΔM (0.25 K at Mach 0.47 with a 2 % static error). A flight
    whose `oat_k` was not made from `tat_k` is returned as it is.
    """
    first = flight
    for _ in range(_MAX_TEMPERATURE_PASSES):
        again = at_mach(first, static_source.calibrated_mach(result, first))
        if again is None:
            break
        step = float(np.max(np.abs(again.oat_k - flight.oat_k)))
        flight, result = again, refit(again)
        if step < TEMPERATURE_TOL_K:
            break
    return result, flight


def _fit_corrected(flight, model, arm_m, options):
    """(flight, fit): with a probe lever arm, the flight corrected for it and fitted again.

    In a turn at yaw rate r the probe at y = arm_m sees V_t − r y, so q_ci is divided by
    (1 − r y / V_t)² (`budget.lever_arm_corrected`); r and V_t need the wind, which a first
    fit gives.
    """
    result = fit(flight, model, **options)
    if not arm_m:
        return flight, result
    flight = lever_arm_corrected(flight, result, arm_m)
    return flight, fit(flight, model, **options)


def budget_inputs(budget):
    """`identify`'s `budget` option as checked `BudgetInputs`, or None (no budget)."""
    if budget is None or budget is False:
        return None
    if budget is True:
        return BudgetInputs().checked()
    if not isinstance(budget, BudgetInputs):
        raise PitotcalError(f"budget: expected BudgetInputs, True or None, got "
                            f"{type(budget).__name__}", param="budget")
    return budget.checked()


def complete(result, flight, *, air, budget=None, gps_error=(None, None)):
    """`result` with the record's products (the fit carries its static-error fit already,
    `fit._with_static_fit`), each computed once.

    Parameters
    ----------
    result : IdentificationResult
        The fit (`estimation.identification.fit.fit`).
    flight : pitotcal.core.flight.Flight
        The flight as given to `identify` (its `reading`, `source`, `n_dropped`).
    air : str
        `identify`'s air-data option (the budget's re-solves use it).
    budget : BudgetInputs, optional
        Checked inputs of the uncertainty budget; None: no budget.
    gps_error : (sigma_mps, tau_s)
        The stated GPS velocity error (None, None: none stated).
    """
    noise, noise_note = _monitor_noise(result)
    reading = getattr(flight, "reading", None)
    sigma, tau = gps_error
    result = dataclasses.replace(
        result, monitor_noise=noise,
        gps_error={"stated": sigma is not None, "sigma_mps": sigma, "tau_s": tau},
        reading=None if reading is None else dict(reading), source=str(flight.source),
        n_dropped=int(flight.n_dropped))
    result = _with_warning(_with_warning(result, noise_note), _static_note(result))
    result = _with_warning(result, _incompressible_note(result, flight))
    if budget is None:
        return result
    if result.drift is not None:        # the budget perturbs the flight the fit solved
        flight = without_drift(flight, *result.drift)
    try:
        return dataclasses.replace(
            result, budget=uncertainty_budget(flight, result, budget, air=air))
    except PitotcalError as exc:        # the calibration stands without its budget
        return _with_warning(result, f"{result.source}: the uncertainty budget was not "
                                     f"computed: {exc}")


def _monitor_noise(result):
    """(the residuals' noise model for `pitotcal monitor`, or None; a warning or None): None
    without a warning for a record too short for the monitor's blocks, with one when the
    model is degenerate (a zero or non-finite scale the monitor could not test against)."""
    try:
        noise = block_residual_stats(result)
    except PitotcalError:               # too short a record for the monitor's blocks
        return None, None
    try:
        check_noise_model("noise_model", noise)
    except PitotcalError as exc:
        return None, (f"{result.source}: the monitor's noise model was not computed ({exc}); "
                      "the record carries noise_std_pa only")
    return noise, None


def _static_note(result):
    """The warning naming the static-source products the record cannot hold, or None."""
    if result.air_data != "compressible" or result.ps_pa is None:
        return None
    return static_source.unavailable_warning(result, correction_table(result))


def _incompressible_note(result, flight):
    """The warning of an incompressible fit of a flight flown above Mach 0.3, or None."""
    if result.air_data != "incompressible":
        return None
    wind = wind_vector_mps(result.value("wind_speed_mps"), result.value("wind_from_deg"))
    with np.errstate(over="ignore", invalid="ignore"):     # a gated absurd sample: inf
        mach = float(np.nanpercentile(flight_mach(flight, *wind), 99))
    if not mach > INCOMPRESSIBLE_MACH_MAX:
        return None
    return (f"{result.source}: fitted with the incompressible air data (q_c = ½ρV_t²) up to "
            f"Mach {mach:.2f}: above Mach {INCOMPRESSIBLE_MACH_MAX:g} the impact pressure "
            f"exceeds ½ρV_t² by about M²/4 ({25 * mach ** 2:.1f} % at Mach {mach:.2f}), "
            "which the fit takes into the pressure-error coefficients and ΔV; fit with the "
            "compressible air data (`air` \"compressible\"; it needs ps_pa and oat_k)")


def _with_warning(result, note):
    """`result` with `note` added to its warnings (None: unchanged)."""
    if not note or note in result.warnings:
        return result
    return dataclasses.replace(result, warnings=tuple(result.warnings) + (note,))
