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
`flight_air` the one constructor of a flight's air data; `flight_channels` a flight's data as
the output-error residual uses it and `sensitivities` that residual's derivatives. The mode
names `AIR_DATA_MODES` and the default `DEFAULT_AIR_DATA` (shared by `simulate` and
`identify`) are defined in the numpy-free `pitotcal.core.scenario` (the command line's parser
quotes them) and given out here.

Example
-------
>>> air = StaticAir(101325.0, 288.15)                  # sea level, ISA
>>> round(float(air.qc_pa(102.8889 ** 2)), 1)          # 200 kt true airspeed
6633.5
>>> round(float(air.tas_sq(6633.5)) ** 0.5, 3)
102.889
"""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from . import airdata
from .errors import FlightDataError, PitotcalError
from .gps_velocity import estimate_gps_noise_std, interpolate_held
from .models import qci_from_qc_pa
from .scenario import AIR_DATA_MODES, DEFAULT_AIR_DATA
from .units import (
    R_AIR_JKGK,
    isa_density_kgm3,
    isa_pressure_pa,
    isa_state_of_density,
    isa_temperature_k,
)

__all__ = [
    "AIR_CHANNELS",
    "AIR_DATA_MODES",
    "Channels",
    "DEFAULT_AIR_DATA",
    "INCOMPRESSIBLE_MACH_MAX",
    "IncompressibleAir",
    "StaticAir",
    "TotalPressureAir",
    "as_air",
    "flight_air",
    "flight_channels",
    "flight_mach",
    "impact_pressure_pa",
    "isa_air",
    "isa_air_of_density",
    "predict_qci_pa",
    "qci_terms",
    "ratio_columns",
    "sensitivities",
    "tas_squared",
]

# Above this Mach number the incompressible relation q_c = ½ρV_t² is short of the impact
# pressure by more than M²/4 = 2.25 %: an incompressible fit is then warned about.
INCOMPRESSIBLE_MACH_MAX = 0.3

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


def _lib(*operands):
    """casadi when any operand is a CasADi type (MX, SX, DM), else numpy (arrays, lists and
    numbers, which the air-data relations then check): the relations take `lib`."""
    if any(type(x).__module__.startswith("casadi") for x in operands):
        import casadi as ca
        return ca
    return np


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
        return airdata.qc_from_total_pa(tas_sq, self.pt, self.oat,
                                        _lib(tas_sq, self.pt, self.oat))

    def derivatives(self, tas_sq):
        return airdata.qc_from_total_derivatives(tas_sq, self.pt, self.oat,
                                                 _lib(tas_sq, self.pt, self.oat))

    def tas_sq(self, qc_pa):
        """The inverse at p_s = p_T − q_c; a negative q_c gives a negative V_t²."""
        lib = _lib(qc_pa, self.pt, self.oat)
        pt, qc = (np.asarray(v, float) for v in (self.pt, qc_pa)) if lib is np else (self.pt, qc_pa)
        return _tas_sq_of_mach(airdata.mach_from_qc(qc, pt - qc, lib), self.oat)


class StaticAir(NamedTuple):
    """Static pressure p_s (Pa) and temperature T_s (K): q_c = p_s [(1 + 0.2 M²)^3.5 − 1]."""

    ps: object
    oat: object

    def qc_pa(self, tas_sq):
        return airdata.qc_from_tas_sq_pa(tas_sq, self.ps, self.oat,
                                         _lib(tas_sq, self.ps, self.oat))

    def derivatives(self, tas_sq):
        return airdata.qc_from_tas_sq_derivatives(tas_sq, self.ps, self.oat,
                                                  _lib(tas_sq, self.ps, self.oat))

    def tas_sq(self, qc_pa):
        """The inverse; a negative q_c gives a negative V_t²."""
        return _tas_sq_of_mach(airdata.mach_from_qc(qc_pa, self.ps, _lib(qc_pa, self.ps, self.oat)),
                               self.oat)


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
        raise PitotcalError(f"air_data {air_data!r} is not one of {', '.join(AIR_CHANNELS)}",
                            param="air_data")
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


def flight_mach(flight, wind_n_mps, wind_e_mps):
    """The true Mach number of each sample of `flight`, ndarray (N,).

    V_t from the GPS ground velocity less the air-mass velocity (`tas_squared`, the vertical
    speed included when logged); the speed of sound from the flight's `oat_k`, or without it
    from the ISA temperature of its density (`isa_state_of_density`). NaN where the
    temperature is not positive.
    """
    vd_sq = None if flight.gps_vd_mps is None else np.asarray(flight.gps_vd_mps, float) ** 2
    tas_sq = tas_squared(np.asarray(flight.gps_vn_mps, float), np.asarray(flight.gps_ve_mps, float),
                         wind_n_mps, wind_e_mps, vd_sq)
    oat = flight.oat_k if flight.oat_k is not None else isa_state_of_density(flight.rho_kgm3)[1]
    with np.errstate(invalid="ignore", divide="ignore"):     # a bad cell gives NaN there
        return np.sqrt(tas_sq) / airdata.speed_of_sound_mps(np.asarray(oat, float))


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
    state of that density (`pitotcal.core.units.isa_state_of_density`: in the troposphere
    T = T₀ (ρ/ρ₀)^(1/(n − 1)), p = ρ R T, n = g₀/(R L); the layers above to 32 km likewise).

    For callers that carry only a density (the design's schedules): the compressible relation
    then needs the pressure and temperature that go with it.
    """
    rho = np.asarray(rho_kgm3, float)
    if air_data == "incompressible":
        return IncompressibleAir(rho)
    return StaticAir(*isa_state_of_density(rho))


@dataclass(frozen=True)
class Channels:
    """A flight's data as the output-error residual uses it, SI, arrays of shape (N,).

    GPS velocity is interpolated where the log held it (`core.gps_velocity.interpolate_held`);
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
        """The air data of the prediction: `IncompressibleAir`, `TotalPressureAir` or
        `StaticAir`."""
        if self.ps_ref is not None:
            return StaticAir(self.ps_ref, self.oat)
        return IncompressibleAir(self.rho) if self.pt is None else TotalPressureAir(self.pt,
                                                                                    self.oat)

    @property
    def args(self):
        """(qci, vn, ve, air, vd2, c_eiv): the data arguments of the residual."""
        return self.qci, self.vn, self.ve, self.air, self.vd2, self.c_eiv


def flight_channels(flight, gps_noise_std_mps=None, air_data="incompressible", held=None):
    """The `Channels` of `flight`; sigma_v estimated from the data when not given.

    The air data come from `flight_air`: "compressible" needs the flight's `ps_pa` and
    `oat_k`, "reference" its `ps_ref_pa` and `oat_k` (`estimation.identify` checks and
    chooses). `held`: (channels, noise factor) of `interpolate_held` on the flight's GPS
    velocity when already known (a copy of a flight with other channels changed).
    """
    gps = (flight.gps_vn_mps, flight.gps_ve_mps)
    if flight.gps_vd_mps is not None:
        gps += (flight.gps_vd_mps,)
    if gps_noise_std_mps is None:
        sigma_v = estimate_gps_noise_std(flight.time_s, *gps)
    else:
        sigma_v = float(gps_noise_std_mps)
    vel, noise_factor = interpolate_held(flight.time_s, *gps) if held is None else held
    air = flight_air(flight, air_data)
    extra = {}
    if isinstance(air, TotalPressureAir):
        extra = {"pt": air.pt, "oat": air.oat}
    elif isinstance(air, StaticAir):
        extra = {"ps_ref": air.ps, "oat": air.oat}
    return Channels(qci=flight.qci_pa, vn=vel[0], ve=vel[1], rho=flight.rho_kgm3,
                    vd2=vel[2] ** 2 if len(vel) == 3 else None, sigma_v=float(sigma_v),
                    var_v=noise_factor * sigma_v ** 2, n_comp=len(vel), **extra)


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
    """Output sensitivities S = dr/dtheta of the residual r = q_ci − predicted at theta =
    (k..., wind_n, wind_e), numpy, shape (N, p + 2).

    Closed form for the wind, dr/dwind_n = 2 a (V_gn - wind_n) with the local slope
    a = dq_ci/dV_t² (`qci_terms`); the coefficients as the predicted q_c times the model's
    ratio columns (`ratio_columns`).
    """
    k, wind_n, wind_e = theta[:-2], theta[-2], theta[-1]
    tas_sq = tas_squared(vn, ve, wind_n, wind_e, vd2) - c_eiv
    _, a, qc = qci_terms(model, k, qci, tas_sq, air)
    cols = [qc * col for col in ratio_columns(model, k, qci)]
    cols += [2.0 * a * (vn - wind_n), 2.0 * a * (ve - wind_e)]
    return np.column_stack(cols)
