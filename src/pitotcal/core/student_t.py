"""Student's t quantiles without scipy.stats: the robustness checks' bounds on z when the
noise model's variance is itself estimated (`estimation.robustness.consistency.t_bound`)."""

import math

from .errors import PitotcalError
from .information import normal_isf, student_t_widening

__all__ = ["student_t_isf"]

# Degrees of freedom above which the quantile is the normal one's Cornish-Fisher expansion (the
# incomplete beta function's evaluation loses digits as its parameter a = dof / 2 grows).
_EXPANSION_DOF = 1e5


def _beta_cf(a, b, x):
    """The continued fraction of the regularised incomplete beta function I_x(a, b)
    (modified Lentz; Numerical Recipes §6.4)."""
    tiny = 1e-300
    c, d = 1.0, 1.0 - (a + b) * x / (a + 1.0)
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 10_000):
        m2 = 2 * m
        for num in (m * (b - m) * x / ((a + m2 - 1.0) * (a + m2)),
                    -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0))):
            d = 1.0 + num * d
            d = 1.0 / (d if abs(d) > tiny else tiny)
            c = 1.0 + num / c
            c = c if abs(c) > tiny else tiny
            h *= d * c
        if abs(d * c - 1.0) < 1e-16:
            break
    return h


def _half_gamma_ratio(a):
    """ln Γ(a + 1/2) − ln Γ(a): its asymptotic series for large a (the difference of two
    lgamma values loses ~1e-16 a ln a to cancellation), lgamma below."""
    if a < 20.0:
        return math.lgamma(a + 0.5) - math.lgamma(a)
    return (0.5 * math.log(a) - 1.0 / (8.0 * a) + 1.0 / (192.0 * a ** 3) - 1.0 / (640.0 * a ** 5)
            + 17.0 / (14336.0 * a ** 7))


def _t_sf_pdf(t, v):
    """(P(T > t), density at t) of Student's t, t >= 0."""
    a, b = 0.5 * v, 0.5
    x, y = v / (v + t * t), t * t / (v + t * t)
    lbeta = math.lgamma(0.5) - _half_gamma_ratio(a)
    front = math.exp(-a * math.log1p(t * t / v) + b * math.log(y) - lbeta) if y > 0 else 0.0
    if x < (a + 1.0) / (a + b + 2.0):
        sf = 0.5 * front * _beta_cf(a, b, x) / a
    else:
        sf = 0.5 - 0.5 * front * _beta_cf(b, a, y) / b
    pdf = math.exp(-lbeta - 0.5 * math.log(v) - (a + 0.5) * math.log1p(t * t / v))
    return sf, pdf


def student_t_isf(p, dof):
    """t with P(T > t) = `p` for Student's t with `dof` degrees of freedom: scipy's
    ``t.isf`` to 1e-12 relative (tests), from the standard
    library (importing scipy.stats costs ~1 s, scipy.special ~0.15 s, of a command that needs
    one quantile).

    Newton steps in ln t on ln P(T > t) from the normal quantile: a straight line in the
    power-law tail of a few degrees of freedom, so few steps at any `p`.
    """
    p, v = float(p), float(dof)
    if not (0.0 < p < 1.0 and v > 0.0):
        raise PitotcalError(f"`p` must be in (0, 1) and `dof` > 0, got {p!r} and {v!r}")
    if p == 0.5:                # the median: the widening below divides by z = 0
        return 0.0
    if p > 0.5:
        return -student_t_isf(1.0 - p, v)
    z = normal_isf(p)
    if v > _EXPANSION_DOF:      # the Cornish-Fisher series: its next term is below 1e-14
        return z * student_t_widening(v, z)
    t, last = max(z, 1e-3), math.inf
    for _ in range(200):
        try:        # t² overflows or the density underflows in a tail far below 1e-150
            sf, pdf = _t_sf_pdf(t, v)
            step = (math.log(sf) - math.log(p)) * sf / (pdf * t)   # Newton in log t on log sf
        except (ArithmeticError, ValueError):
            raise PitotcalError(f"`p` {p!r} is too small a tail probability to invert for "
                                f"`dof` {v!r}", param="p") from None
        step = max(min(step, 2.0), -2.0)
        # quadratic convergence: a step that no longer shrinks below 1e-10 is rounding
        if abs(step) <= 1e-14 or (abs(step) >= last and last < 1e-10):
            return t * math.exp(step)
        t, last = t * math.exp(step), abs(step)
    raise PitotcalError(f"no Student's t quantile found for `p` {p!r}, `dof` {v!r}")
