"""Information-optimal speed schedules (`plan --design optimal`).

The planner's OCP chooses the bank; this module chooses the speed schedule it flies, by the
predicted 2σ of ΔV (pitotcal.core.information) over a low-dimensional parametrisation:

- levels: cas_min, cas_max and a check level in between (q half-way) held for at least
  `check_fraction` of the dwell time, so the model structure can still be checked on three
  speeds (a two-point design cannot tell k1 + k2/q from any other two-parameter curve);
- the order the dwells are flown, from a short list (two to five dwells; the ends may come
  back; `alternating_orders` gives longer ones to pass as `orders`);
- the share of the dwell time at the low end against the high end.

Each candidate is scored on a constant-bank circle (the OCP's own starting path) with the
sandwich covariance of least squares under the residual noise `identify` models
(`pitotcal.core.information.gust_covariance`: the Dryden gust along the path and the GPS
velocity noise through the wind sensitivities, the transducer's white noise), widened for the
degrees of freedom of a noise model fitted to one record as `identify` widens its bounds; the
criterion is the worst (or the mean) 2σ of ΔV over the speed range, taking at each speed the
larger of that reported bound and the estimate's actual scatter (the unwidened sandwich), so
the design cannot buy a smaller reported bound with worse coverage. A candidate whose
end-level dwells cannot turn 360° at full bank is skipped.
"""

from dataclasses import dataclass

import numpy as np
from .profiles import dwell_schedule

from pitotcal.core.airdata import qc_from_cas_pa
from pitotcal.core.errors import PlanInfeasibleError
from pitotcal.core.information import (
    ResidualNoise,
    delta_v_band_kt,
    qci_sensitivities,
    reported_covariance,
)
from pitotcal.core.models import get_model
from pitotcal.core.scenario import true_k
from pitotcal.core.units import G0_MPS2, kt_to_mps

__all__ = [
    "CRITERIA",
    "DEFAULT_CHECK_FRACTION",
    "DEFAULT_STALL_MARGIN",
    "GRID_POINTS",
    "MAX_DWELLS",
    "ORDERS",
    "STALL_DEFAULT_RATIO",
    "Design",
    "alternating_orders",
    "circle_heading_rad",
    "criterion_value",
    "default_noise",
    "design_schedule",
    "predict_band_kt",
    "predict_plan_band_kt",
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
# Longer orders (the information bound's, not the default candidates): the two ends alternating
# (the check level, if any, second), up to MAX_DWELLS dwells. Under gusts correlated over tau,
# a speed change every few tau lets the difference of neighbouring dwells cancel the slow part
# of the gust; each change costs a ramp. On the scoring circle they gain 1.5% at 1 m/s²; on the
# OCP's path, whose bank follows the ground speed in the wind, the T-2 design with them came out
# 4-11% worse than without (dwells too short to turn evenly). Shares near a half only.
MAX_DWELLS = 12
_ALT_SHARES = (0.45, 0.5, 0.55)


def alternating_orders(max_dwells=MAX_DWELLS):
    """Dwell orders of 6 to `max_dwells` dwells alternating between the ends, starting low
    or high, without and with the check level as the second dwell."""
    out = []
    for n in range(6, max_dwells + 1):
        for first in (0, 2):
            ends = tuple(first if i % 2 == 0 else 2 - first for i in range(n))
            out += [ends, ends[:1] + (1,) + ends[1:]]
    return tuple(out)
GRID_POINTS = 7


@dataclass(frozen=True)
class Design:
    """The chosen schedule and what it predicts.

    Attributes
    ----------
    schedule : maneuvers.plan.profiles.Schedule
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

    reported: what `identify` will report (`core.information.reported_covariance`); actual:
    the estimate's scatter (the same sandwich, unwidened).
    """
    pe = get_model(model)
    k = true_k(model) if k is None else k
    jac = qci_sensitivities(schedule.tas_mps, heading_rad, schedule.rho_kgm3, pe, k,
                            wind_ne_mps)
    p = len(k)
    return tuple(delta_v_band_kt(pe, k, cov[:p, :p], vi_kt)
                 for cov in reported_covariance(jac, schedule.time_s, noise))


def criterion_value(bands, criterion):
    """The worst or mean, over the speeds, of the larger of (reported, actual) 2σ."""
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
    vi_kt = np.linspace(lo_kt, hi_kt, GRID_POINTS)
    best, scored = None, 0
    for order in (o for o in orders if (1 in o) == (check_fraction > 0)):
        n_lo, n_hi = order.count(0), order.count(2)
        for share in (_LOW_SHARES if len(order) <= 5 else _ALT_SHARES):
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
            value = criterion_value(predict_band_kt(sched, heading, wind_ne_mps, noise, vi_kt,
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
    from ..turbulence import dryden_scales

    scales = dryden_scales(max(altitude_m, 0.0), max(turbulence_mps, 1e-9))
    return ResidualNoise(turbulence_mps=turbulence_mps,
                         tau_s=scales.length_u_m / float(np.mean(tas_mps)))


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
