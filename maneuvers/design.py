"""Information-optimal speed schedules (`plan --design optimal`).

The planner's OCP chooses the bank; this module chooses the speed schedule it flies, by the
predicted 2σ of ΔV (pitotcal.core.information) over a low-dimensional parametrisation:

- levels: cas_min, cas_max and a check level in between (q half-way) held for at least
  `check_fraction` of the dwell time, so the model structure can still be checked on three
  speeds (a two-point design cannot tell k1 + k2/q from any other two-parameter curve);
- the order the dwells are flown, from a short list (two to four dwells; the ends may come back);
- the share of the dwell time at the low end against the high end.

Each candidate is scored on a constant-bank circle (the OCP's own starting path) with the
sandwich covariance of least squares under the Dryden-correlated turbulence residuals; the
criterion is the worst (or the mean) 2σ of ΔV over the speed range, taking at each speed the
larger of the bound `identify` reports (one stationary noise level) and the estimate's actual
scatter (noise growing with V), so the design cannot buy a smaller reported bound with worse
coverage. A candidate whose end-level dwells cannot turn 360° at full bank is skipped.
"""

from dataclasses import dataclass

import numpy as np
from pitotcal.maneuvers.profiles import dwell_schedule

from pitotcal.core.errors import PlanInfeasibleError
from pitotcal.core.information import (
    ResidualNoise,
    delta_v_band_kt,
    least_squares_covariance,
    qci_sensitivities,
    residual_covariance,
)
from pitotcal.core.models import get_model
from pitotcal.core.scenario import true_k
from pitotcal.core.units import G0_MPS2, kt_to_mps, qc_from_cas_pa

__all__ = [
    "CRITERIA",
    "DEFAULT_CHECK_FRACTION",
    "DEFAULT_STALL_MARGIN",
    "MAX_TARGET_DURATION_S",
    "ORDERS",
    "STALL_DEFAULT_RATIO",
    "Design",
    "DesignOptions",
    "checked_options",
    "circle_heading_rad",
    "default_noise",
    "design_schedule",
    "optimal_schedule",
    "predict_band_kt",
    "predict_plan_band_kt",
    "record_prediction",
    "stall_bank_deg",
]

CRITERIA = ("worst", "average")
# Dwell share of the check level (the third speed): enough for a structure check, little
# information given away.
DEFAULT_CHECK_FRACTION = 0.1
# The slowest speed must stay this factor above the stall speed at the turn's load factor,
# V_s sqrt(n), n = 1 / cos(bank); the stall speed defaults to cas_min / STALL_DEFAULT_RATIO.
DEFAULT_STALL_MARGIN = 1.2
STALL_DEFAULT_RATIO = 1.3
# Dwell orders: 0 the low end, 1 the check level, 2 the high end.
# Without a check level (check_fraction 0) the orders without a 1 are the candidates.
ORDERS = ((0, 1, 2), (2, 1, 0), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1),
          (0, 1, 2, 0), (2, 1, 0, 2), (0, 2, 1, 0), (0, 1, 2, 0, 2),
          (0, 2), (2, 0), (0, 2, 0), (2, 0, 2), (0, 2, 0, 2))
_LOW_SHARES = np.round(np.arange(0.25, 0.76, 0.05), 2)
_GRID_POINTS = 7


@dataclass(frozen=True)
class Design:
    """The chosen schedule and what it predicts.

    Attributes
    ----------
    schedule : maneuvers.profiles.Schedule
    order : tuple of int
        Dwell order (0 low end, 1 check level, 2 high end).
    low_share : float
        Share of the end-level dwell time spent at the low end.
    predicted_2sigma_kt : float
        The criterion's value on the constant-bank circle, kt.
    candidates : int
        How many schedules were scored.
    """

    schedule: object
    order: tuple
    low_share: float
    predicted_2sigma_kt: float
    candidates: int


def stall_bank_deg(cas_min_kt, stall_kt, margin=DEFAULT_STALL_MARGIN):
    """The largest bank at which cas_min keeps `margin` above the stall speed at the turn's
    load factor: cos(bank) = (margin V_s / V_min)^2 (V_s sqrt(n), n = 1/cos(bank)); NaN when
    cas_min is below margin V_s even level."""
    ratio = (margin * stall_kt / cas_min_kt) ** 2
    return float(np.degrees(np.arccos(ratio))) if ratio <= 1.0 else float("nan")


def circle_heading_rad(schedule, bank_rad, sign=1.0):
    """Air-relative heading of a constant-bank turn along the schedule: psi' = g tan(bank)/V."""
    rate = G0_MPS2 * np.tan(bank_rad) / schedule.tas_mps
    t = schedule.time_s
    return sign * np.r_[0.0, np.cumsum(np.diff(t) * 0.5 * (rate[1:] + rate[:-1]))]


def predict_band_kt(schedule, heading_rad, wind_ne_mps, noise, vi_kt, *, model="inverse",
                    k=None):
    """2σ of ΔV at `vi_kt` predicted for the trajectory: (reported, actual) arrays, kt.

    reported: one stationary turbulence level (what `identify`'s colored covariance reports);
    actual: turbulence pressure growing with V (the estimate's scatter).
    """
    pe = get_model(model)
    k = true_k(model) if k is None else k
    jac = qci_sensitivities(schedule.tas_mps, heading_rad, schedule.rho_kgm3, pe, k,
                            wind_ne_mps)
    p = len(k)
    out = []
    for stationary in (True, False):
        sigma = residual_covariance(schedule.time_s, schedule.tas_mps, schedule.rho_kgm3,
                                    noise, stationary=stationary)
        cov = least_squares_covariance(jac, sigma)
        out.append(delta_v_band_kt(pe, k, cov[:p, :p], vi_kt))
    return tuple(out)


def _criterion(bands, criterion):
    band = np.maximum(*bands)
    return float(band.max() if criterion == "worst" else band.mean())


def _turns_enough(schedule, bank_max_rad, coverage_rad):
    heading = circle_heading_rad(schedule, bank_max_rad)
    return all(sum(heading[b] - heading[a] for a, b in runs) >= coverage_rad
               for runs in schedule.groups)


def design_schedule(cas_min_kt, cas_max_kt, duration_s, *, altitude_m, accel_max_mps2,
                    dt_s, bank_max_rad, radius_m, wind_ne_mps, noise, coverage_rad,
                    criterion="worst", range_kt=None, check_fraction=DEFAULT_CHECK_FRACTION,
                    orders=ORDERS, model="inverse"):
    """The best schedule of the parametrisation for this request (see the module notes).

    Parameters
    ----------
    cas_min_kt, cas_max_kt, duration_s, altitude_m, accel_max_mps2, dt_s :
        The request.
    bank_max_rad, radius_m : float
        The bank limit (after the stall margin) and the test-area radius: the scoring circle
        banks as the OCP's first guess does.
    wind_ne_mps : (float, float)
        Expected mean wind (TO).
    noise : pitotcal.core.information.ResidualNoise
    coverage_rad : float
        Heading turn each end level must allow at full bank.
    criterion : {"worst", "average"}
    range_kt : (float, float), optional
        Indicated-airspeed range of the criterion (default: cas_min to cas_max).
    check_fraction : float
        Dwell share of the check level.

    Returns
    -------
    Design

    Raises
    ------
    PlanInfeasibleError
        No candidate turns 360° at each end level in this duration.
    """
    q_lo, q_hi = (float(qc_from_cas_pa(kt_to_mps(v))) for v in (cas_min_kt, cas_max_kt))
    levels = (q_lo, 0.5 * (q_lo + q_hi), q_hi)
    lo_kt, hi_kt = range_kt or (cas_min_kt, cas_max_kt)
    vi_kt = np.linspace(lo_kt, hi_kt, _GRID_POINTS)
    best, scored = None, 0
    for order in (o for o in orders if (1 in o) == (check_fraction > 0)):
        n_lo, n_hi = order.count(0), order.count(2)
        for share in _LOW_SHARES:
            ends = 1.0 - check_fraction
            frac = [check_fraction if j == 1 else ends * (share / n_lo if j == 0
                                                           else (1 - share) / n_hi)
                    for j in order]
            try:
                sched = dwell_schedule([levels[j] for j in order], frac, duration_s,
                                       altitude_m=altitude_m, accel_max_mps2=accel_max_mps2,
                                       dt_s=dt_s, covered=(q_lo, q_hi))
            except PlanInfeasibleError:
                continue
            if not _turns_enough(sched, bank_max_rad, coverage_rad):
                continue
            heading = circle_heading_rad(sched, _circle_bank(sched, radius_m, bank_max_rad,
                                                             coverage_rad))
            value = _criterion(predict_band_kt(sched, heading, wind_ne_mps, noise, vi_kt,
                                               model=model), criterion)
            scored += 1
            if best is None or value < best[0]:
                best = (value, sched, order, float(share))
    if best is None:
        raise PlanInfeasibleError(
            f"duration_s {duration_s:g} s is too short for an optimal design: each end speed "
            f"must turn 360° at {np.degrees(bank_max_rad):.0f}° bank; try a longer duration",
            param="duration_s")
    value, sched, order, share = best
    return Design(schedule=sched, order=order, low_share=share, predicted_2sigma_kt=value,
                  candidates=scored)


def _circle_bank(schedule, radius_m, bank_max_rad, coverage_rad):
    """The bank of the OCP's starting circle: the fastest circle at 80 % of the radius, or
    steeper if the end levels need it to turn 360°, at most 95 % of the limit."""
    tan_fit = schedule.tas_mps.max() ** 2 / (G0_MPS2 * 0.8 * radius_m)
    unit = circle_heading_rad(schedule, np.arctan(1.0))      # heading per unit tan(bank)
    need = min(sum(unit[b] - unit[a] for a, b in runs) for runs in schedule.groups)
    tan_cover = 1.2 * coverage_rad / max(need, 1e-9)
    return min(np.arctan(max(tan_fit, tan_cover)), 0.95 * bank_max_rad)


def default_noise(turbulence_mps, altitude_m, tas_mps):
    """The residual noise of a flight in `turbulence_mps` of Dryden turbulence at the plan
    altitude (simulator defaults for the sensors): tau = L_u / mean TAS."""
    from pitotcal.maneuvers.turbulence import dryden_scales

    scales = dryden_scales(max(altitude_m, 0.0), max(turbulence_mps, 1e-9))
    return ResidualNoise(turbulence_mps=turbulence_mps,
                         tau_s=scales.length_u_m / float(np.mean(tas_mps)))


@dataclass(frozen=True)
class DesignOptions:
    """What `plan --design optimal` asks for besides the plan's own request.

    Attributes
    ----------
    turbulence_mps : float
        RMS Dryden gust the flight is designed for, m/s.
    criterion : {"worst", "average"}
        Minimise the worst or the mean 2σ of ΔV over the speed range.
    target_2sigma_kt : float or None
        Instead of the requested duration: the shortest flight whose criterion meets this.
    stall_kt : float or None
        Stall speed, KCAS (default cas_min / 1.3).
    stall_margin : float
        cas_min must stay this factor above the stall speed at the turn's load factor.
    check_fraction : float
        Dwell share of the check level.
    """

    turbulence_mps: float = 0.5
    criterion: str = "worst"
    target_2sigma_kt: float | None = None
    stall_kt: float | None = None
    stall_margin: float = DEFAULT_STALL_MARGIN
    check_fraction: float = DEFAULT_CHECK_FRACTION


def checked_options(options):
    """`options` (a DesignOptions or a dict of its fields) with every field checked."""
    from pitotcal.core.checks import choice, number, positive

    if options is None:
        options = DesignOptions()
    elif isinstance(options, dict):
        unknown = set(options) - set(DesignOptions.__dataclass_fields__)
        if unknown:
            from pitotcal.core.errors import PitotcalError
            raise PitotcalError(f"design option {min(unknown)!r} is not one of "
                                f"{', '.join(DesignOptions.__dataclass_fields__)}",
                                param="design_options")
        options = DesignOptions(**options)
    target = options.target_2sigma_kt
    return DesignOptions(
        turbulence_mps=positive("turbulence_mps", options.turbulence_mps),
        criterion=choice("criterion", options.criterion, CRITERIA),
        target_2sigma_kt=None if target is None else positive("target_2sigma_kt", target),
        stall_kt=None if options.stall_kt is None else positive("stall_kt", options.stall_kt),
        stall_margin=number("stall_margin", options.stall_margin, 1.0),
        check_fraction=number("check_fraction", options.check_fraction, 0.0, 0.5,
                              hi_open=True))


# The longest flight `--target-2sigma-kt` may ask for, s.
MAX_TARGET_DURATION_S = 3600.0


def optimal_schedule(req, options):
    """The designed schedule of a checked planner request, and the request it is planned with
    (the stall margin's bank limit; the duration that meets a target), and the settings to
    record.

    Parameters
    ----------
    req : maneuvers.planner._Request
    options : DesignOptions (checked)

    Returns
    -------
    (Design, bank_max_deg, duration_s, settings)
    """
    from pitotcal.core.units import wind_vector_mps

    stall_kt = req.cas_min_kt / STALL_DEFAULT_RATIO if options.stall_kt is None \
        else options.stall_kt
    stall_bank = stall_bank_deg(req.cas_min_kt, stall_kt, options.stall_margin)
    if not stall_bank >= 5.0:
        need = options.stall_margin * stall_kt / np.sqrt(np.cos(np.radians(5.0)))
        raise PlanInfeasibleError(
            f"stall_kt {stall_kt:g} KCAS leaves cas_min_kt {req.cas_min_kt:g} below "
            f"{options.stall_margin:g} x the stall speed at 5° bank: raise cas_min_kt to at "
            f"least {np.ceil(need):.0f} KCAS", param="stall_kt", mentions=("cas_min_kt",))
    bank_deg = min(req.bank_max_deg, stall_bank)
    wind = wind_vector_mps(req.wind_speed_mps, req.wind_from_deg)

    def run(duration_s):
        tas_guess = kt_to_mps(0.5 * (req.cas_min_kt + req.cas_max_kt))
        return design_schedule(
            req.cas_min_kt, req.cas_max_kt, duration_s, altitude_m=req.altitude_m,
            accel_max_mps2=req.accel_max_mps2, dt_s=req.dt_s,
            bank_max_rad=np.radians(bank_deg), radius_m=req.radius_m, wind_ne_mps=wind,
            noise=default_noise(options.turbulence_mps, req.altitude_m, [tas_guess]),
            coverage_rad=req.coverage_rad, criterion=options.criterion,
            check_fraction=options.check_fraction)

    duration = req.duration_s
    design = run(duration)
    if options.target_2sigma_kt is not None:
        duration, design = _meet_target(run, duration, design, options.target_2sigma_kt)
    settings = {"design": "optimal", "criterion": options.criterion,
                "turbulence_mps": options.turbulence_mps, "stall_kt": round(stall_kt, 2),
                "stall_margin": options.stall_margin, "check_fraction": options.check_fraction,
                "dwell_order": "-".join("LCH"[j] for j in design.order),
                "low_share": design.low_share}
    if options.target_2sigma_kt is not None:
        settings["target_2sigma_kt"] = options.target_2sigma_kt
    return design, bank_deg, duration, settings


def _meet_target(run, duration, design, target_kt):
    """The shortest duration (whole seconds) whose design meets the target: 2σ ~ 1/sqrt(T)
    gives the next guess; a last step up in seconds until it holds."""
    for _ in range(4):
        guess = float(np.ceil(duration * (design.predicted_2sigma_kt / target_kt) ** 2))
        if guess > MAX_TARGET_DURATION_S:
            raise PlanInfeasibleError(
                f"target_2sigma_kt {target_kt:g} kt needs about {guess:.0f} s of flight in "
                f"this turbulence, more than {MAX_TARGET_DURATION_S:.0f} s: ask for a larger "
                f"target or fly in calmer air", param="target_2sigma_kt")
        if guess == duration:
            break
        try:
            duration, design = guess, run(guess)
        except PlanInfeasibleError:
            # too short to turn at each end: the shortest that can, meets the target a fortiori
            duration = guess + 10.0
            design = run(duration)
    while design.predicted_2sigma_kt > target_kt:
        duration += max(1.0, round(0.01 * duration))
        design = run(duration)
    return duration, design


def record_prediction(settings, schedule, sol, req, options):
    """`settings` with the prediction on the path the OCP found: the criterion's value and the
    worst reported 2σ of ΔV over the speed range (``predicted_dv_2sigma_kt``)."""
    from pitotcal.core.units import wind_vector_mps

    noise = default_noise(options.turbulence_mps, req.altitude_m, schedule.tas_mps)
    vi_kt = np.linspace(req.cas_min_kt, req.cas_max_kt, _GRID_POINTS)
    bands = predict_band_kt(schedule, sol.heading_rad,
                            wind_vector_mps(req.wind_speed_mps, req.wind_from_deg), noise, vi_kt)
    return {**settings, "predicted_dv_2sigma_kt": round(_criterion(bands, options.criterion), 3),
            "turbulence_tau_s": round(noise.tau_s, 2)}


def predict_plan_band_kt(plan, turbulence_mps, vi_kt, *, model="inverse", k=None):
    """(reported, actual) 2σ of ΔV at `vi_kt` predicted for a planned flight (any profile or
    design) in `turbulence_mps` of Dryden turbulence; see `predict_band_kt`."""
    from types import SimpleNamespace

    from pitotcal.core.units import isa_density_kgm3, wind_vector_mps

    s = plan.settings
    alt = float(np.mean(plan.alt_m))
    track = SimpleNamespace(time_s=plan.time_s, tas_mps=plan.tas_mps,
                            rho_kgm3=float(isa_density_kgm3(alt)))
    wind = wind_vector_mps(s.get("wind_speed_mps", 0.0), s.get("wind_from_deg", 0.0))
    return predict_band_kt(track, np.radians(plan.heading_deg), wind,
                           default_noise(turbulence_mps, alt, plan.tas_mps), vi_kt,
                           model=model, k=k)
