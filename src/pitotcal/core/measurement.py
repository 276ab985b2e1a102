"""The measurement model (paper eqs. 1-4), written once for numpy arrays and CasADi alike.

    V_t² = |V_g − W|² [+ V_gd²]       W = air-mass velocity (the way the wind blows TO)
    q_c  = q_c(V_t²; air data)        the air-data types below
    q_ci = (1 − f(q_ci; k)) q_c       Δp = q_c − q_ci, Δp/q_c = f(q_ci; k)

The air data say how the true impact pressure follows from the true airspeed:

- `IncompressibleAir` (ρ): q_c = ½ ρ V_t², the paper's eq. 2;
- `TotalPressureAir` (p_T, T_s): isentropic at a measured total pressure. With all the pressure
  error in the static source the static port reads p_s,ind = p_s + Δp and the transducer
  q_ci = q_c − Δp, so p_T = p_s,ind + q_ci is exact and q_c follows from V_t without Δp;
- `StaticAir` (p_s, T_s): isentropic at a known static pressure (the simulator's truth, or an
  independent reference static pressure).

Each gives q_c(V_t²), dq_c/dV_t², d²q_c/d(V_t²)² and the inverse V_t²(q_c) with numpy or
CasADi (`pitotcal.core.airdata` holds the standard relations). `predict_qci_pa` is the one
predictor of q_ci from ground velocity, wind, the pressure-error model and the air data;
`flight_air` the one constructor of a flight's air data. The mode names `AIR_DATA_MODES` and
the default `DEFAULT_AIR_DATA` (shared by `simulate` and `identify`) are defined in the
numpy-free `pitotcal.core.scenario` and given out here.
"""

from typing import NamedTuple

import numpy as np

from . import airdata
from .errors import FlightDataError
from .models import qci_from_qc_pa
from .scenario import AIR_DATA_MODES, DEFAULT_AIR_DATA
from .units import (
    ISA_EXPONENT,
    ISA_P0_PA,
    ISA_T0_K,
    R_AIR_JKGK,
    isa_density_kgm3,
    isa_pressure_pa,
    isa_temperature_k,
)

__all__ = [
    "AIR_CHANNELS",
    "AIR_DATA_MODES",
    "DEFAULT_AIR_DATA",
    "IncompressibleAir",
    "StaticAir",
    "TotalPressureAir",
    "as_air",
    "flight_air",
    "impact_pressure_pa",
    "is_compressible",
    "isa_air",
    "isa_air_of_density",
    "predict_qci_pa",
    "qci_terms",
    "tas_squared",
]

# The flight's data channels of each air-data type (`flight_air`), by the estimator's mode:
# "reference" is the compressible fit from an independent reference static pressure.
AIR_CHANNELS = {"incompressible": ("rho",), "compressible": ("pt", "oat"),
                "reference": ("ps_ref", "oat")}


def tas_squared(gps_vn, gps_ve, wind_n, wind_e, gps_vd_sq=None):
    """True airspeed squared, m²/s², from GPS ground velocity and the air-mass velocity.

    `gps_vd_sq` (the vertical speed squared) is added when given; None (no vertical channel)
    spares a whole-array addition of zero.
    """
    v2 = (gps_vn - wind_n) ** 2 + (gps_ve - wind_e) ** 2
    return v2 if gps_vd_sq is None else v2 + gps_vd_sq


def impact_pressure_pa(rho_kgm3, tas_sq):
    """Impact pressure q_c = ½ ρ V_t² of a true airspeed squared (incompressible)."""
    return 0.5 * rho_kgm3 * tas_sq


def _lib(x):
    """numpy for arrays and numbers, casadi for symbols (the air-data relations take `lib`)."""
    if isinstance(x, (np.ndarray, float, int, np.floating)):
        return np
    import casadi as ca
    return ca


class IncompressibleAir(NamedTuple):
    """Density ρ (kg/m³): q_c = ½ ρ V_t² (the paper's eq. 2), linear in V_t²."""

    rho: object

    def qc_pa(self, tas_sq):
        return impact_pressure_pa(self.rho, tas_sq)

    def derivatives(self, tas_sq):
        """(dq_c/dV_t², d²q_c/d(V_t²)²) = (½ρ, 0)."""
        return impact_pressure_pa(self.rho, 1.0), 0.0 * tas_sq

    def tas_sq(self, qc_pa):
        """The inverse: V_t² = 2 q_c / ρ."""
        return qc_pa / impact_pressure_pa(self.rho, 1.0)


class TotalPressureAir(NamedTuple):
    """Measured total pressure p_T = p_s,ind + q_ci (Pa) and static temperature T_s (K):
    q_c = p_T [1 − (1 + 0.2 M²)^−3.5], M² = V_t² / (γ R T_s)."""

    pt: object
    oat: object

    def qc_pa(self, tas_sq):
        return airdata.qc_from_total_pa(tas_sq, self.pt, self.oat, _lib(self.pt))

    def derivatives(self, tas_sq):
        return airdata.qc_from_total_derivatives(tas_sq, self.pt, self.oat, _lib(self.pt))

    def tas_sq(self, qc_pa):
        """The inverse at p_s = p_T − q_c; a negative q_c gives a negative V_t²."""
        return _tas_sq_of_mach(airdata.mach_from_qc(qc_pa, self.pt - qc_pa, _lib(self.pt)),
                               self.oat)


class StaticAir(NamedTuple):
    """Static pressure p_s (Pa) and temperature T_s (K): q_c = p_s [(1 + 0.2 M²)^3.5 − 1]."""

    ps: object
    oat: object

    def qc_pa(self, tas_sq):
        return airdata.qc_from_tas_sq_pa(tas_sq, self.ps, self.oat, _lib(self.ps))

    def derivatives(self, tas_sq):
        return airdata.qc_from_tas_sq_derivatives(tas_sq, self.ps, self.oat, _lib(self.ps))

    def tas_sq(self, qc_pa):
        """The inverse; a negative q_c gives a negative V_t²."""
        return _tas_sq_of_mach(airdata.mach_from_qc(qc_pa, self.ps, _lib(self.ps)), self.oat)


def _tas_sq_of_mach(mach, oat_k):
    """Signed V_t² = M |M| γ R T_s (a signed Mach from a negative q_c stays signed)."""
    return mach * abs(mach) * airdata.GAMMA * R_AIR_JKGK * oat_k


_AIR_TYPES = (IncompressibleAir, TotalPressureAir, StaticAir)


def as_air(air):
    """`air` as one of the air-data types: a type as it is, a plain pair (p_T, T_s) as
    `TotalPressureAir`, anything else (an array, number or symbol) as the density ρ."""
    if isinstance(air, _AIR_TYPES):
        return air
    if isinstance(air, tuple):
        return TotalPressureAir(*air)
    return IncompressibleAir(air)


def is_compressible(air):
    """Whether `air` (any form `as_air` takes) is isentropic air data, not a density."""
    return not isinstance(as_air(air), IncompressibleAir)


def qci_terms(model, k, qci_pa, tas_sq, air):
    """(predicted q_ci, a = dq_ci/dV_t², q_c) with f at the measured q_ci; numpy or MX.

    The output-error form of eq. 4: the ratio f is evaluated at the measured `qci_pa` (the
    regressor), so the prediction is (1 − f(q_ci; k)) q_c(V_t²) and a = (1 − f) dq_c/dV_t².
    """
    air = as_air(air)
    gain = 1.0 - model(k, qci_pa)
    qc = air.qc_pa(tas_sq)
    return gain * qc, gain * air.derivatives(tas_sq)[0], qc


def predict_qci_pa(model, k, gps_vn, gps_ve, wind_n, wind_e, air, gps_vd_sq=None,
                   qci_pa=None):
    """The q_ci a pitot-static system with pressure error f(q_ci; k) reads, Pa.

    Parameters
    ----------
    model : pitotcal.core.models.PressureErrorModel
    k : sequence of float
        Its coefficients.
    gps_vn, gps_ve : array_like (N,)
        Ground velocity north / east, m/s.
    wind_n, wind_e : float or array_like (N,)
        Air-mass velocity (the way it blows TO), m/s.
    air : IncompressibleAir, TotalPressureAir, StaticAir (or what `as_air` takes)
    gps_vd_sq : array_like (N,) or None
        Vertical speed squared, m²/s², when measured.
    qci_pa : array_like (N,), optional
        The measured q_ci: f is then evaluated there (the output-error regressor,
        `qci_terms`); without it q_ci solves q_ci = (1 − f(q_ci; k)) q_c (numpy only), what
        the sensor itself reads.

    Notes
    -----
    Both forms agree where the measured q_ci is the one the sensor reads.
    """
    tas_sq = tas_squared(gps_vn, gps_ve, wind_n, wind_e, gps_vd_sq)
    if qci_pa is not None:
        return qci_terms(model, k, qci_pa, tas_sq, air)[0]
    return qci_from_qc_pa(model, tuple(k), as_air(air).qc_pa(tas_sq))


def flight_air(flight, air_data=DEFAULT_AIR_DATA):
    """The air data of `flight` for the estimator's mode `air_data`.

    "incompressible": its density ρ; "compressible": `TotalPressureAir` from its `ps_pa`
    (as the static port reads it) + `qci_pa` and `oat_k`; "reference": `StaticAir` from its
    `ps_ref_pa` and `oat_k`. A missing channel is a `FlightDataError` naming it.
    """
    if air_data not in AIR_CHANNELS:
        raise ValueError(f"air_data {air_data!r} is not one of {', '.join(AIR_CHANNELS)}")
    if air_data == "incompressible":
        return IncompressibleAir(np.asarray(flight.rho_kgm3, float))
    names = ("ps_pa", "oat_k") if air_data == "compressible" else ("ps_ref_pa", "oat_k")
    for name in names:
        if getattr(flight, name, None) is None:
            raise FlightDataError(f"{flight.source}: no column {name} for the {air_data} "
                                  "air data")
    oat = np.asarray(flight.oat_k, float)
    if air_data == "compressible":
        return TotalPressureAir(np.asarray(flight.ps_pa, float) + flight.qci_pa, oat)
    return StaticAir(np.asarray(flight.ps_ref_pa, float), oat)


def isa_air(alt_m, air_data=DEFAULT_AIR_DATA, oat_k=None):
    """The ISA air at geopotential altitude `alt_m` (m): `IncompressibleAir` of the density
    p/(R T) or `StaticAir` (p, T); `oat_k` replaces the ISA temperature when given (the
    simulator's virtual temperature of humid air)."""
    ps = isa_pressure_pa(alt_m)
    oat = isa_temperature_k(alt_m) if oat_k is None else np.asarray(oat_k, float)
    if air_data == "incompressible":
        return IncompressibleAir(isa_density_kgm3(alt_m) if oat_k is None
                                 else ps / (R_AIR_JKGK * oat))
    return StaticAir(ps, oat)


def isa_air_of_density(rho_kgm3, air_data=DEFAULT_AIR_DATA):
    """The ISA air of density ρ (kg/m³): `IncompressibleAir` (ρ) or `StaticAir` at the ISA
    troposphere state of that density, T = T₀ (ρ/ρ₀)^(1/(n − 1)), p = ρ R T (n = g₀/(R L)).

    For callers that carry only a density (the design's schedules): the compressible relation
    then needs the pressure and temperature that go with it.
    """
    rho = np.asarray(rho_kgm3, float)
    if air_data == "incompressible":
        return IncompressibleAir(rho)
    rho0 = ISA_P0_PA / (R_AIR_JKGK * ISA_T0_K)
    oat = ISA_T0_K * (rho / rho0) ** (1.0 / (ISA_EXPONENT - 1.0))
    return StaticAir(rho * R_AIR_JKGK * oat, oat)
