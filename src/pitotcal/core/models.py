"""Pressure-error model structures, Δp/q_c = f(q_ci; k) (docs/interfaces.md §2, paper eq. 4).

Each structure is a `PressureErrorModel` in `MODELS`. To add one, write its ratio with plain
arithmetic (it is evaluated on numpy arrays and on CasADi MX vectors alike) and register it.
"""

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import airdata
from .units import kt_to_mps, mps_to_kt

__all__ = [
    "MAX_PRESSURE_ERROR",
    "MIN_KNOT_SAMPLES",
    "MODELS",
    "PressureErrorModel",
    "delta_v_kt",
    "delta_v_kt_where_defined",
    "denser_knots",
    "get_model",
    "mach_knots",
    "mach_spline_basis",
    "qc_from_qci_pa",
    "qci_from_qc_pa",
    "worst_pressure_error",
]

# The largest pressure error |Δp/q_c| of a working pitot-static system: beyond half the impact
# pressure lost the sensor reads next to none (a working system's is a few percent).
MAX_PRESSURE_ERROR = 0.5


@dataclass(frozen=True)
class PressureErrorModel:
    """One structure of the normalized pressure error Δp/q_c as a function of q_ci.

    Attributes
    ----------
    name : str
        Name used on the command line and in the JSON (`constant`, `linear`, `inverse`).
    params : tuple of str
        Coefficient names in order, e.g. ("k1", "k2").
    units : tuple of str
        Unit of each coefficient ("" for dimensionless).
    scales : tuple of float
        Typical magnitude of each coefficient; the optimizer works on k / scale.
    ratio : callable
        ratio(k, qci_pa) -> Δp/q_c; `k` is a sequence of coefficients.
    formula : str
        The formula, for reports.
    """

    name: str
    params: tuple
    units: tuple
    scales: tuple
    ratio: Callable
    formula: str

    def __call__(self, k, qci_pa):
        return self.ratio(k, qci_pa)


MODELS = {
    m.name: m for m in (
        PressureErrorModel("constant", ("k1",), ("",), (0.01,),
                           lambda k, q: k[0] + 0.0 * q, "dp/qc = k1"),
        PressureErrorModel("linear", ("k1", "k2"), ("", "1/Pa"), (0.01, 1e-5),
                           lambda k, q: k[0] + k[1] * q, "dp/qc = k1 + k2*qci"),
        PressureErrorModel("inverse", ("k1", "k2"), ("", "Pa"), (0.01, 10.0),
                           lambda k, q: k[0] + k[1] / q, "dp/qc = k1 + k2/qci"),
    )
}


def get_model(name):
    """The registered structure called `name`; ValueError naming the choices otherwise."""
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"model {name!r} is not one of {', '.join(MODELS)}") from None


def qc_from_qci_pa(model, k, qci_pa):
    """True impact pressure from the measured one: q_c = q_ci / (1 - f(q_ci)) (from eq. 1)."""
    qci = np.asarray(qci_pa, dtype=float)
    return qci / (1.0 - model(k, qci))


def qci_from_qc_pa(model, k, qc_pa, iterations=50):
    """Measured impact pressure a sensor with this error model reads at true q_c.

    Solves q_ci = q_c (1 - f(q_ci)) by fixed-point iteration; it contracts because
    |q_ci f'(q_ci)| << 1 for any physical pressure error.
    """
    qc = np.asarray(qc_pa, dtype=float)
    qci = qc * (1.0 - model(k, qc))
    for _ in range(iterations):
        new = qc * (1.0 - model(k, qci))
        if np.max(np.abs(new - qci), initial=0.0) < 1e-12 * max(1.0, np.max(np.abs(qc), initial=0.0)):
            return new
        qci = new
    return qci


def delta_v_kt(model, k, vi_kt, air_data="incompressible"):
    """Airspeed correction ΔV = V_c - V_i, kt, at indicated airspeed `vi_kt`.

    q_ci is the impact pressure of V_i, q_c = q_ci / (1 - f(q_ci)), V_c the airspeed of q_c,
    both through the same law: sqrt(2 q / rho0) with `air_data` "incompressible"
    (docs/interfaces.md §2), or the standard calibrated-airspeed law
    (`pitotcal.core.airdata.cas_from_qc_mps`) with "compressible", where V_i is the
    instrument-corrected indicated airspeed V_ic and ΔV the position-error correction ΔV_pc.
    """
    vi_mps = kt_to_mps(np.asarray(vi_kt, dtype=float))
    qc_of, airspeed_of = airdata.airspeed_law(air_data)
    qc = qc_from_qci_pa(model, k, qc_of(vi_mps))
    return mps_to_kt(airspeed_of(qc) - vi_mps)


def delta_v_kt_where_defined(model, k, vi_kt, air_data="incompressible"):
    """`delta_v_kt` at the speeds where it exists, NaN elsewhere.

    A calibration far from the fitted one (a diagnostic's shifted coefficients) can have
    1 - f(q_ci) <= 0 or a true q_c beyond the Mach range of the pitot relations at some indicated speeds: there
    is no V_c, and the diagnostic asking must say so rather than stop the identification.
    """
    vi_mps = kt_to_mps(np.asarray(vi_kt, dtype=float))
    qc_of, airspeed_of = airdata.airspeed_law(air_data)
    qci = qc_of(vi_mps)
    with np.errstate(divide="ignore", invalid="ignore"):
        qc = qc_from_qci_pa(model, k, qci)
    ok = np.isfinite(qc) & (qc >= 0.0)
    if air_data == "compressible":
        ok &= qc <= airdata.QC_MAX_PA
    out = np.full(np.shape(qc), np.nan)
    out[ok] = mps_to_kt(airspeed_of(qc[ok]) - vi_mps[ok])
    return out


def worst_pressure_error(model, k, vi_kt, air_data="incompressible"):
    """max |f(q_ci; k)| over the indicated airspeeds `vi_kt` (q_ci by the law of `air_data`);
    inf where f is not finite."""
    qci = airdata.airspeed_law(air_data)[0](kt_to_mps(np.asarray(vi_kt, dtype=float)))
    with np.errstate(all="ignore"):
        ratio = np.abs(np.asarray(model(k, qci), dtype=float))
    return float(np.max(np.where(np.isfinite(ratio), ratio, np.inf))) if ratio.size else 0.0


# Knot spacing of the Mach-dependent static error: coarse where it varies slowly, dense through
# the transonic rise and fall (a shock crossing the static port moves it by 0.02 within 0.05 of
# M_ic); the last entry covers supersonic flight.
_KNOT_SPACING = ((0.8, 0.1), (0.9, 0.05), (1.1, 0.025), (3.0, 0.1))
# The fewest samples between two knots: each spline coefficient is fitted by data.
MIN_KNOT_SAMPLES = 40


def mach_knots(mach_ic, min_samples=MIN_KNOT_SAMPLES):
    """Knots of the Mach-dependent error chosen by the data, M_ic.

    From the lowest to the highest M_ic of the samples, spaced by `_KNOT_SPACING` (0.1 below
    M_ic 0.8, 0.05 to 0.9, 0.025 to 1.1); a knot is dropped when fewer than `min_samples`
    samples lie between it and the previous one, so each coefficient is fitted by data.

    Parameters
    ----------
    mach_ic : ndarray
        M_ic of the samples.
    min_samples : int
        The fewest samples between two knots.

    Returns
    -------
    ndarray, shape (K,)
        Increasing knots, K >= 2 (the ends of the data).
    """
    m = np.sort(np.asarray(mach_ic, dtype=float))
    lo, hi = float(m[0]), float(m[-1])
    starts = (0.0,) + tuple(top for top, _ in _KNOT_SPACING[:-1])
    grid = np.concatenate([np.arange(start, top - 1e-9, step) for start, (top, step)
                           in zip(starts, _KNOT_SPACING)])
    grid = [lo] + [float(round(g, 6)) for g in grid if lo < g < hi]
    knots = [lo]
    for k in grid[1:] + [hi]:
        if np.count_nonzero((m > knots[-1]) & (m <= k)) >= min_samples:
            knots.append(k)
    if knots[-1] != hi:
        knots[-1] = hi
    return np.array(knots if len(knots) >= 2 else [lo, hi])


def denser_knots(knots, mach_ic, min_samples=MIN_KNOT_SAMPLES):
    """`knots` with the midpoint of each interval added where both halves hold at least
    `min_samples` samples of `mach_ic`: the spline twice as dense wherever the data can fit it,
    to measure what the coarser one cannot represent."""
    m = np.asarray(mach_ic, dtype=float)
    out = [float(knots[0])]
    for lo, hi in zip(knots[:-1], knots[1:]):
        mid = 0.5 * (lo + hi)
        if min(np.count_nonzero((m > lo) & (m <= mid)),
               np.count_nonzero((m > mid) & (m <= hi))) >= min_samples:
            out.append(float(mid))
        out.append(float(hi))
    return np.array(out)


def _positive(u):
    return 0.5 * (u + abs(u))


def _natural_terms(x, knots):
    """The truncated-power basis of the natural cubic spline (Hastie, Tibshirani & Friedman,
    Elements of Statistical Learning, eq. 5.4-5.5): 1, x, d_k − d_(K−1), as a list."""
    last = len(knots) - 1

    def d(k):
        return (_positive(x - knots[k]) ** 3 - _positive(x - knots[last]) ** 3) \
            / (knots[last] - knots[k])
    terms = [1.0 + 0.0 * x, x]
    if last >= 2:
        d_before = d(last - 1)
        terms += [d(k) - d_before for k in range(last - 1)]
    return terms


def mach_spline_basis(mach_ic, knots):
    """Cardinal basis of the natural cubic spline through `knots`: f(M) = B(M) @ values.

    Parameters
    ----------
    mach_ic : ndarray (N,) or CasADi MX
        M_ic where the spline is evaluated; plain arithmetic, so MX works too (then a list of
        MX columns is returned).
    knots : sequence of float
        Increasing knots (`mach_knots`), K of them.

    Returns
    -------
    ndarray (N, K), or list of K MX
        Column j is the natural cubic spline that is 1 at knot j and 0 at the others (linear
        beyond the end knots), so the unknowns are the curve's values at the knots.
    """
    knots = np.asarray(knots, dtype=float)
    at_knots = np.column_stack(_natural_terms(knots, knots))
    to_cardinal = np.linalg.inv(at_knots)
    terms = _natural_terms(mach_ic, knots)
    if isinstance(mach_ic, np.ndarray) or np.isscalar(mach_ic):
        return np.column_stack([np.broadcast_to(t, np.shape(mach_ic)) for t in terms]) \
            @ to_cardinal
    return [sum(float(to_cardinal[i, j]) * terms[i] for i in range(len(terms)))
            for j in range(len(knots))]
