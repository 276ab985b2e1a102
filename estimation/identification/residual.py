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

from dataclasses import dataclass

import numpy as np

from pitotcal.core.measurement import (
    AIR_CHANNELS,
    IncompressibleAir,
    StaticAir,
    TotalPressureAir,
    as_air,
    flight_air,
    is_compressible,
    qci_terms,
    tas_squared,
)

from .eiv import estimate_gps_noise_std, interpolate_held
from .unknowns import COEFS, WIND_E, WIND_N

__all__ = [
    "AIR_CHANNELS", "Channels", "ReferenceAir", "TotalAir", "flight_channels", "impact_pressure", "is_compressible",
    "ratio_columns", "residual", "residual_function", "residual_terms", "sensitivities",
    "slope", "spread_weights",
]

# The estimator's names of the measurement model's compressible air-data types.
TotalAir = TotalPressureAir
ReferenceAir = StaticAir


@dataclass(frozen=True)
class Channels:
    """A flight's data as the residual uses it, SI, arrays of shape (N,).

    GPS velocity is interpolated where the log held it (`estimation.identification.eiv.interpolate_held`);
    `var_v` is the GPS noise variance per component after that interpolation. `oat` (static
    temperature, K) and either `pt` (total pressure p_s,ind + q_ci, Pa) or `ps_ref` (a
    reference static pressure, Pa) are set for the compressible problem only.
    """

    qci: np.ndarray
    vn: np.ndarray
    ve: np.ndarray
    rho: np.ndarray
    vd2: np.ndarray | None   # GPS vertical speed squared, m^2/s^2 (None: no vertical channel)
    sigma_v: float       # GPS velocity noise per component, m/s
    var_v: float         # m^2/s^2
    n_comp: int          # velocity components: 2, or 3 with a vertical speed
    pt: np.ndarray | None = None
    oat: np.ndarray | None = None
    ps_ref: np.ndarray | None = None

    @property
    def c_eiv(self):
        """n sigma_v^2 (after interpolation): the mean GPS noise adds to V_t^2, m^2/s^2."""
        return self.n_comp * self.var_v

    @property
    def air(self):
        """The air data of the prediction (`pitotcal.core.measurement`): `IncompressibleAir`,
        `TotalPressureAir` or `StaticAir`."""
        if self.ps_ref is not None:
            return StaticAir(self.ps_ref, self.oat)
        return IncompressibleAir(self.rho) if self.pt is None else TotalPressureAir(self.pt,
                                                                                    self.oat)

    @property
    def args(self):
        """(qci, vn, ve, air, vd2, c_eiv): the data arguments of `residual_terms`."""
        return self.qci, self.vn, self.ve, self.air, self.vd2, self.c_eiv


def flight_channels(flight, gps_noise_std_mps=None, air_data="incompressible"):
    """The `Channels` of `flight`; sigma_v estimated from the data when not given.

    The air data come from `pitotcal.core.measurement.flight_air`: "compressible" needs the
    flight's `ps_pa` and `oat_k`, "reference" its `ps_ref_pa` and `oat_k`
    (`estimation.identify` checks and chooses).
    """
    gps = (flight.gps_vn_mps, flight.gps_ve_mps)
    if flight.gps_vd_mps is not None:
        gps += (flight.gps_vd_mps,)
    if gps_noise_std_mps is None:
        sigma_v = estimate_gps_noise_std(flight.time_s, *gps)
    else:
        sigma_v = float(gps_noise_std_mps)
    vel, noise_factor = interpolate_held(flight.time_s, *gps)
    air = flight_air(flight, air_data)
    extra = {}
    if isinstance(air, TotalPressureAir):
        extra = {"pt": air.pt, "oat": air.oat}
    elif isinstance(air, StaticAir):
        extra = {"ps_ref": air.ps, "oat": air.oat}
    return Channels(qci=flight.qci_pa, vn=vel[0], ve=vel[1], rho=flight.rho_kgm3,
                    vd2=vel[2] ** 2 if len(vel) == 3 else None, sigma_v=float(sigma_v),
                    var_v=noise_factor * sigma_v ** 2, n_comp=len(vel), **extra)


def impact_pressure(air, tas_sq):
    """(q_c, dq_c/dV_t^2) of the air data `air` at V_t^2 = `tas_sq`."""
    air = as_air(air)
    return air.qc_pa(tas_sq), air.derivatives(tas_sq)[0]


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


def ratio_columns(model, k, qci):
    """d f(q_ci; k) / d k_i for each coefficient, by central differences (exact when f is
    linear in k, as every registered structure is)."""
    cols = []
    for i, h in enumerate(model.scales):
        up, dn = k.copy(), k.copy()
        up[i] += h
        dn[i] -= h
        cols.append((model(up, qci) - model(dn, qci)) / (2 * h))
    return cols


def sensitivities(model, theta, qci, vn, ve, air, vd2=None, c_eiv=0.0):
    """Output sensitivities S = dr/dtheta at theta, numpy, shape (N, p).

    Closed form for the wind, dr/dwind_n = 2 a (V_gn - wind_n) with the local slope a; the
    coefficients as the predicted q_c times the model's ratio columns (`ratio_columns`).
    """
    k = theta[COEFS]
    tas_sq = tas_squared(vn, ve, theta[WIND_N], theta[WIND_E], vd2) - c_eiv
    _, a, qc = qci_terms(model, k, qci, tas_sq, air)
    cols = [qc * col for col in ratio_columns(model, k, qci)]
    cols += [2.0 * a * (vn - theta[WIND_N]), 2.0 * a * (ve - theta[WIND_E])]
    return np.column_stack(cols)


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
