"""The output residual of the output-error problem, written once for numpy and CasADi.

With the measurement model of `pitotcal.core.measurement` (paper eqs. 1-4),

    V_t^2 = |V_g - W|^2 [+ V_gd^2],   q_ci = (1 - f(q_ci; k)) q_c(V_t^2),

the residual is the measured minus the predicted impact pressure, with f evaluated at the
measured q_ci (the regressor of eq. 4) and the mean c_eiv = n sigma_v^2 that GPS velocity noise
adds to V_t^2 taken out (`estimation.identification.oe`, Notes):

    r = q_ci - (1 - f(q_ci; k)) q_c(V_t^2 - c_eiv),   a = (1 - f) dq_c/dV_t^2 = dq_ci/dV_t^2.

The air data give q_c(V_t^2) (`air` below):

- incompressible (the paper's eq. 2, `air` the density array rho): q_c = rho/2 V_t^2, so
  a = (1 - f) rho/2 and r = q_ci - a (V_t^2 - c_eiv);
- compressible (`air` the pair (p_T, T_s)): q_c = p_T [1 - (1 + 0.2 M^2)^-3.5],
  M^2 = V_t^2 / (gamma R T_s) (`pitotcal.core.airdata.qc_from_total_pa`), with the total
  pressure p_T = p_s,ind + q_ci measured: all the pressure error taken in the static source,
  p_T is exact and the prediction does not depend on k. a is then the local derivative.

`residual_terms` is plain arithmetic: the same lines evaluate numpy arrays (start values,
sensitivities, the instrumental-variable steps) and build the problem's MX graph
(`residual_function`).
"""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from pitotcal.core.airdata import (
    qc_from_tas_sq_derivatives,
    qc_from_tas_sq_pa,
    qc_from_total_derivatives,
    qc_from_total_pa,
)
from pitotcal.core.measurement import impact_pressure_pa, tas_squared

from .eiv import estimate_gps_noise_std, interpolate_held
from .unknowns import COEFS, WIND_E, WIND_N

__all__ = [
    "AIR_CHANNELS", "Channels", "ReferenceAir", "TotalAir", "flight_channels", "impact_pressure", "is_compressible",
    "ratio_columns", "residual", "residual_function", "residual_terms", "sensitivities",
    "slope", "spread_weights",
]


class TotalAir(NamedTuple):
    """Compressible air data with all the pressure error in the static source: the measured
    total pressure p_T = p_s,ind + q_ci (Pa) and the static temperature (K)."""

    pt: object
    oat: object


class ReferenceAir(NamedTuple):
    """Compressible air data from an independent reference static pressure p_s (Pa) and the
    static temperature (K): no assumption on where the pressure error is."""

    ps: object
    oat: object


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
        """The air data of the prediction: rho (incompressible), `TotalAir` or `ReferenceAir`."""
        if self.ps_ref is not None:
            return ReferenceAir(self.ps_ref, self.oat)
        return self.rho if self.pt is None else TotalAir(self.pt, self.oat)

    @property
    def args(self):
        """(qci, vn, ve, air, vd2, c_eiv): the data arguments of `residual_terms`."""
        return self.qci, self.vn, self.ve, self.air, self.vd2, self.c_eiv


def flight_channels(flight, gps_noise_std_mps=None, air_data="incompressible"):
    """The `Channels` of `flight`; sigma_v estimated from the data when not given.

    With `air_data` "compressible" the flight must carry `ps_pa` and `oat_k`
    (`estimation.identify` checks it); "reference" uses its `ps_ref_pa` and `oat_k`.
    """
    gps = (flight.gps_vn_mps, flight.gps_ve_mps)
    if flight.gps_vd_mps is not None:
        gps += (flight.gps_vd_mps,)
    if gps_noise_std_mps is None:
        sigma_v = estimate_gps_noise_std(flight.time_s, *gps)
    else:
        sigma_v = float(gps_noise_std_mps)
    vel, noise_factor = interpolate_held(flight.time_s, *gps)
    extra = {}
    if air_data == "compressible":
        extra = {"pt": flight.ps_pa + flight.qci_pa, "oat": np.asarray(flight.oat_k, float)}
    elif air_data == "reference":
        extra = {"ps_ref": np.asarray(flight.ps_ref_pa, float),
                 "oat": np.asarray(flight.oat_k, float)}
    return Channels(qci=flight.qci_pa, vn=vel[0], ve=vel[1], rho=flight.rho_kgm3,
                    vd2=vel[2] ** 2 if len(vel) == 3 else None, sigma_v=float(sigma_v),
                    var_v=noise_factor * sigma_v ** 2, n_comp=len(vel), **extra)


def is_compressible(air):
    """Whether `air` is compressible air data (`TotalAir`, `ReferenceAir`), not a density."""
    return isinstance(air, tuple)


def _derivatives(air, tas_sq):
    """(dq_c/dV_t^2, d^2q_c/d(V_t^2)^2) of the compressible prediction."""
    lib = _lib(air[0])
    if isinstance(air, ReferenceAir):
        return qc_from_tas_sq_derivatives(tas_sq, *air, lib)
    return qc_from_total_derivatives(tas_sq, *air, lib)          # TotalAir, or a plain pair


def _lib(x):
    """numpy for arrays and numbers, casadi for symbols (the air-data relations take `lib`)."""
    if isinstance(x, (np.ndarray, float, int)):
        return np
    import casadi as ca
    return ca


def impact_pressure(air, tas_sq):
    """(q_c, dq_c/dV_t^2) predicted at V_t^2 = `tas_sq` from the air data `air`."""
    if not is_compressible(air):
        return impact_pressure_pa(air, tas_sq), impact_pressure_pa(air, 1.0)
    lib = _lib(air[0])
    if isinstance(air, ReferenceAir):
        qc = qc_from_tas_sq_pa(tas_sq, *air, lib)
    else:
        qc = qc_from_total_pa(tas_sq, *air, lib)
    return qc, _derivatives(air, tas_sq)[0]


def slope(model, k, qci, air, tas_sq=None, c_eiv=0.0):
    """a = dq_ci / dV_t^2 = (1 - f(q_ci; k)) dq_c/dV_t^2.

    Incompressible: q_c = rho/2 V_t^2 is linear in V_t^2, so (1 - f) q_c(rho, V_t^2) =
    q_c(rho, 1 - f) V_t^2 and `tas_sq` is not needed. Compressible: the local derivative at
    V_t^2 - c_eiv (`tas_sq` required).
    """
    if not is_compressible(air):
        return impact_pressure_pa(air, 1.0 - model(k, qci))
    return (1.0 - model(k, qci)) * impact_pressure(air, tas_sq - c_eiv)[1]


def residual_terms(model, theta, qci, vn, ve, air, vd2=None, c_eiv=0.0):
    """(r, a, V_t^2) at the unknowns `theta` (`estimation.identification.unknowns`); numpy or CasADi MX.

    Parameters
    ----------
    model : PressureErrorModel
    theta : array or MX, shape (p,)
        Coefficients, then wind_n, wind_e (m/s).
    qci, vn, ve : arrays or MX, shape (N,)
        Measured impact pressure (Pa), GPS velocity north / east (m/s).
    air : array or MX, shape (N,), or a pair of them
        Density rho (kg/m^3; incompressible), or (p_T, T_s): total pressure (Pa) and static
        temperature (K) (compressible).
    vd2 : array or MX, shape (N,), or None
        GPS vertical speed squared, m^2/s^2 (None without a vertical channel).
    c_eiv : float or MX
        n sigma_v^2, m^2/s^2: the mean GPS noise adds to V_t^2.
    """
    if not is_compressible(air):
        a = slope(model, theta[COEFS], qci, air)
        tas_sq = tas_squared(vn, ve, theta[WIND_N], theta[WIND_E], vd2)
        return qci - a * (tas_sq - c_eiv), a, tas_sq
    tas_sq = tas_squared(vn, ve, theta[WIND_N], theta[WIND_E], vd2)
    qc, dqc = impact_pressure(air, tas_sq - c_eiv)
    gain = 1.0 - model(theta[COEFS], qci)
    return qci - gain * qc, gain * dqc, tas_sq


def residual(model, theta, qci, vn, ve, air, vd2=None, c_eiv=0.0):
    """The output residual r, Pa (`residual_terms` without keeping a and V_t^2: on numpy at
    N = 1e6 that keeps the solve's peak memory 30 MB lower, measured)."""
    if is_compressible(air):
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
    if not is_compressible(ch.air):
        return 4.0 * ch.var_v, slope(model, k, ch.qci, ch.rho) ** 2
    tas_sq = tas_squared(ch.vn, ch.ve, theta[WIND_N], theta[WIND_E], ch.vd2)
    gain = 1.0 - model(k, ch.qci)
    d1, d2 = _derivatives(ch.air, tas_sq - ch.c_eiv)
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
    if is_compressible(air):
        qc, dqc = impact_pressure(
            air, tas_squared(vn, ve, theta[WIND_N], theta[WIND_E], vd2) - c_eiv)
        a = (1.0 - model(k, qci)) * dqc
    else:
        qc = impact_pressure_pa(air, tas_squared(vn, ve, theta[WIND_N], theta[WIND_E], vd2)
                                - c_eiv)
        a = slope(model, k, qci, air)
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
    air_data : {"incompressible", "compressible"}
        The air channels: ``rho``, or ``pt`` and ``oat`` (`residual_terms`).

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
    air = {"compressible": TotalAir, "reference": ReferenceAir}.get(
        air_data, lambda rho: rho)(*air_syms)
    vd2 = ca.MX.sym("vd2", n if has_vd else 1)
    c_eiv = ca.MX.sym("c_eiv")
    r, a, tas_sq = residual_terms(model, theta, qci, vn, ve, air, vd2, c_eiv)
    return ca.Function("residual", [theta, qci, vn, ve, *air_syms, vd2, c_eiv], [r, a, tas_sq],
                       ["theta", "qci", "vn", "ve", *names, "vd2", "c_eiv"],
                       ["r", "a", "tas_sq"])


# The data channels of the air, per mode (`Channels.air`).
AIR_CHANNELS = {"incompressible": ("rho",), "compressible": ("pt", "oat"),
                "reference": ("ps_ref", "oat")}
