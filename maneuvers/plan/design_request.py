"""What `plan --design optimal` asks for, and the designed schedule of a planner request.

`DesignOptions` holds the design's own options (checked by `checked_options`);
`optimal_schedule` turns a checked planner request into the designed schedule (the stall
margin's bank limit applied, the duration found for a target 2σ, or the shortest duration
that can turn 360° at each end named in the refusal); `record_prediction` adds the prediction
on the path IPOPT found to the plan's settings.
"""

from dataclasses import dataclass

import numpy as np
from .design import (
    CRITERIA,
    DEFAULT_CHECK_FRACTION,
    DEFAULT_STALL_MARGIN,
    GRID_POINTS,
    STALL_DEFAULT_RATIO,
    criterion_value,
    default_noise,
    design_schedule,
    predict_band_kt,
    stall_bank_deg,
)

from pitotcal.core.errors import PlanInfeasibleError
from pitotcal.core.units import kt_to_mps

__all__ = ["MAX_TARGET_DURATION_S", "DesignOptions", "checked_options", "optimal_schedule",
           "record_prediction"]


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
    req : maneuvers.plan.planner._Request
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
    bank_deg = min(req.bank_max_deg, round(stall_bank, 1))
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
    try:
        design = run(duration)
    except PlanInfeasibleError:
        raise _too_short(run, duration, bank_deg) from None
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


def _too_short(run, duration_s, bank_deg):
    """The refusal of a duration in which no candidate turns 360° at each end, naming the
    shortest that works (doubling, then halving the interval to a second)."""
    lo, hi = duration_s, 2.0 * duration_s
    while not _designs(run, hi):
        lo, hi = hi, 2.0 * hi
        if hi > MAX_TARGET_DURATION_S:
            return PlanInfeasibleError(
                f"duration_s {duration_s:g} s: no optimal design turns 360° at each end speed "
                f"at {bank_deg:g}° bank in up to {MAX_TARGET_DURATION_S:.0f} s: try a larger "
                f"bank_max_deg", param="duration_s", mentions=("bank_max_deg",))
    while hi - lo > 1.0:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _designs(run, mid) else (mid, hi)
    return PlanInfeasibleError(
        f"duration_s {duration_s:g} s is too short for an optimal design: each end speed must "
        f"turn 360° at {bank_deg:g}° bank; {np.ceil(hi):.0f} s is long enough",
        param="duration_s", mentions=("bank_max_deg",))


def _designs(run, duration_s):
    try:
        run(duration_s)
    except PlanInfeasibleError:
        return False
    return True


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
            # too short to turn at each end: the shortest that can (10-s steps) meets the
            # target a fortiori
            duration = guess + 10.0
            while not _designs(run, duration):
                duration += 10.0
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
    vi_kt = np.linspace(req.cas_min_kt, req.cas_max_kt, GRID_POINTS)
    bands = predict_band_kt(schedule, sol.heading_rad,
                            wind_vector_mps(req.wind_speed_mps, req.wind_from_deg), noise, vi_kt)
    return {**settings, "predicted_dv_2sigma_kt": round(criterion_value(bands, options.criterion), 3),
            "turbulence_tau_s": round(noise.tau_s, 2)}
