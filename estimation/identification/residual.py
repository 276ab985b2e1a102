"""The output residual of the output-error problem, written once for numpy and CasADi.

With the measurement model of `pitotcal.core.measurement` (paper eqs. 1-4),

    V_t^2 = |V_g - W|^2 [+ V_gd^2],   q_ci = (1 - f(q_ci; k)) q_c(V_t^2),

the residual is the measured minus the predicted impact pressure, with f evaluated at the
measured q_ci (the regressor of eq. 4) and the mean c_eiv = n sigma_v^2 that GPS velocity noise
adds to V_t^2 taken out (`estimation.identification.oe`, Notes):

    r = q_ci - (1 - f(q_ci; k)) q_c(V_t^2 - c_eiv),   a = (1 - f) dq_c/dV_t^2 = dq_ci/dV_t^2.

The air data give q_c(V_t^2) (`air` below, the types of `pitotcal.core.measurement`):
`IncompressibleAir` (the paper's eq. 2, q_c = rho/2 V_t^2, so a = (1 - f) rho/2 and
r = q_ci - a (V_t^2 - c_eiv)); `TotalPressureAir` (p_T = p_s,ind + q_ci measured, all the
pressure error in the static source, so p_T is exact); `StaticAir` (a reference static
pressure). Compressible, a is the local derivative.

`residual_terms` is plain arithmetic: the same lines evaluate numpy arrays (start values,
sensitivities, the instrumental-variable steps) and build the problem's MX graph
(`residual_function`).
"""

from pitotcal.core.measurement import (
    AIR_CHANNELS,
    Channels,
    IncompressibleAir,
    StaticAir,
    TotalPressureAir,
    as_air,
    flight_channels,
    qci_terms,
    ratio_columns,
    sensitivities,
    tas_squared,
)

from .unknowns import COEFS, WIND_E, WIND_N

__all__ = [
    "AIR_CHANNELS", "Channels", "ReferenceAir", "TotalAir", "flight_channels",
    "ratio_columns", "residual", "residual_function", "residual_terms", "sensitivities",
    "slope", "spread_weights",
]

# The estimator's names of the measurement model's compressible air-data types.
TotalAir = TotalPressureAir
ReferenceAir = StaticAir


def slope(model, k, qci, air, tas_sq=None, c_eiv=0.0):
    """a = dq_ci / dV_t^2 = (1 - f(q_ci; k)) dq_c/dV_t^2.

    Incompressible, q_c = rho/2 V_t^2 is linear in V_t^2 and `tas_sq` is not needed.
    Compressible: the local derivative at V_t^2 - c_eiv (`tas_sq` required).
    """
    air = as_air(air)
    if isinstance(air, IncompressibleAir):
        return air.qc_pa(1.0 - model(k, qci))
    return (1.0 - model(k, qci)) * air.derivatives(tas_sq - c_eiv)[0]


def residual_terms(model, theta, qci, vn, ve, air, vd2=None, c_eiv=0.0):
    """(r, a, V_t^2) at the unknowns `theta` (`estimation.identification.unknowns`); numpy or CasADi MX.

    Parameters
    ----------
    model : PressureErrorModel
    theta : array or MX, shape (p,)
        Coefficients, then wind_n, wind_e (m/s).
    qci, vn, ve : arrays or MX, shape (N,)
        Measured impact pressure (Pa), GPS velocity north / east (m/s).
    air : air data of `pitotcal.core.measurement` (or what its `as_air` takes)
        Density rho (kg/m^3; incompressible), `TotalPressureAir` (p_T, T_s) or `StaticAir`.
    vd2 : array or MX, shape (N,), or None
        GPS vertical speed squared, m^2/s^2 (None without a vertical channel).
    c_eiv : float or MX
        n sigma_v^2, m^2/s^2: the mean GPS noise adds to V_t^2.
    """
    air = as_air(air)
    tas_sq = tas_squared(vn, ve, theta[WIND_N], theta[WIND_E], vd2)
    if isinstance(air, IncompressibleAir):
        # linear in V_t^2: the slope does not depend on the wind (a smaller graph)
        a = slope(model, theta[COEFS], qci, air)
        return qci - a * (tas_sq - c_eiv), a, tas_sq
    predicted, a, _ = qci_terms(model, theta[COEFS], qci, tas_sq - c_eiv, air)
    return qci - predicted, a, tas_sq


def residual(model, theta, qci, vn, ve, air, vd2=None, c_eiv=0.0):
    """The output residual r, Pa (`residual_terms` without keeping a and V_t^2: on numpy at
    N = 1e6 that keeps the solve's peak memory 30 MB lower, measured)."""
    air = as_air(air)
    if not isinstance(air, IncompressibleAir):
        return residual_terms(model, theta, qci, vn, ve, air, vd2, c_eiv)[0]
    a = slope(model, theta[COEFS], qci, air)
    return qci - a * (tas_squared(vn, ve, theta[WIND_N], theta[WIND_E], vd2) - c_eiv)


def spread_weights(model, theta, ch):
    """(c, w) with -1/2 d(spread)/d(wind_n) = c sum w (V_gn - wind_n) (likewise east), numpy.

    The objective's GPS-noise spread is sum a^2 (4 sigma_v^2 V_t^2 - 2 n sigma_v^4)
    (`estimation.identification.oe`). Incompressible, a does not depend on the wind: c = 4 sigma_v^2,
    w = a^2. Compressible, a = (1 - f) q_c'(V_t^2 - c_eiv) does, which adds
    2 a (1 - f) q_c'' (4 sigma_v^2 V_t^2 - 2 n sigma_v^4) to w = 4 sigma_v^2 a^2 (c = 1; the
    extra term is about M^2 of the first).
    """
    k = theta[COEFS]
    air = ch.air
    if isinstance(air, IncompressibleAir):
        return 4.0 * ch.var_v, slope(model, k, ch.qci, air) ** 2
    tas_sq = tas_squared(ch.vn, ch.ve, theta[WIND_N], theta[WIND_E], ch.vd2)
    gain = 1.0 - model(k, ch.qci)
    d1, d2 = air.derivatives(tas_sq - ch.c_eiv)
    a = gain * d1
    spread = 4.0 * ch.var_v * tas_sq - 2.0 * ch.n_comp * ch.var_v ** 2
    return 1.0, 4.0 * ch.var_v * a ** 2 + 2.0 * a * gain * d2 * spread


def residual_function(model, n, has_vd, air_data="incompressible"):
    """The residual as a named ``ca.Function`` of whole-vector MX, one symbol per data channel.

    Parameters
    ----------
    model : PressureErrorModel
    n : int
        Samples (CasADi symbols have a fixed size).
    has_vd : bool
        Whether the flight has a vertical speed; without it `vd2` is a scalar (pass 0; it is
        left out of the graph when the problem inlines this function).
    air_data : {"incompressible", "compressible", "reference"}
        The air channels (`pitotcal.core.measurement.AIR_CHANNELS`): ``rho``, ``pt`` and
        ``oat``, or ``ps_ref`` and ``oat``.

    Returns
    -------
    casadi.Function
        ``residual(theta, qci, vn, ve, <air>, vd2, c_eiv) -> (r, a, tas_sq)``: the residual,
        its slope a = dq_ci/dV_t^2 and V_t^2 (the objective's noise term needs both), shape
        (N,). The graph has a few dozen nodes whatever N is.
    """
    import casadi as ca

    theta = ca.MX.sym("theta", len(model.params) + 2)
    qci, vn, ve = (ca.MX.sym(name, n) for name in ("qci", "vn", "ve"))
    names = AIR_CHANNELS[air_data]
    air_syms = [ca.MX.sym(name, n) for name in names]
    air = {"incompressible": IncompressibleAir, "compressible": TotalPressureAir,
           "reference": StaticAir}[air_data](*air_syms)
    vd2 = ca.MX.sym("vd2", n if has_vd else 1)
    c_eiv = ca.MX.sym("c_eiv")
    r, a, tas_sq = residual_terms(model, theta, qci, vn, ve, air, vd2, c_eiv)
    return ca.Function("residual", [theta, qci, vn, ve, *air_syms, vd2, c_eiv], [r, a, tas_sq],
                       ["theta", "qci", "vn", "ve", *names, "vd2", "c_eiv"],
                       ["r", "a", "tas_sq"])
