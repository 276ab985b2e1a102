"""The standard air-data relations (subsonic, ISA troposphere), written once for numpy and CasADi.

    M    = V_t / sqrt(γ R T_s)                              Mach number
    q_c  = p_s [(1 + 0.2 M²)^3.5 − 1]                       impact pressure (isentropic)
    V_c  = a₀ sqrt(5 [(q_c/p₀ + 1)^(2/7) − 1])              calibrated airspeed
    H    = (T₀/L) [1 − (p_s/p₀)^(R L/g₀)]                   pressure altitude (geopotential)

γ = 1.4, p₀ = 101,325 Pa, T₀ = 288.15 K, a₀ = sqrt(γ R T₀) = 340.294 m/s, L = 0.0065 K/m,
R and g₀ from `pitotcal.core.units` (the one place of the atmosphere constants and of the ISA
formula, which `static_pressure_pa` and `pressure_altitude_m` check the range of). 0.2 and 3.5
are (γ − 1)/2 and γ/(γ − 1) for γ = 1.4.

Each function takes `lib` (numpy by default, or `casadi`): only its `sqrt`, `sign` and `fabs`
are used, and powers and products are plain arithmetic, so the same expressions evaluate numpy
arrays and build the output-error problem's MX graph. With numpy the inputs are checked against
the validity range (subsonic; ISA troposphere) and refused with a `PitotcalError`; symbolic
inputs cannot be checked.

The paper's eq. 2 (q_c = ½ ρ V_t², `pitotcal.core.measurement`) is the incompressible limit:
q_c = ½ ρ V_t² (1 + M²/4 + M⁴/40 + ...).
"""

import math

import numpy as np

from .errors import PitotcalError
from .units import (
    FT_TO_M,
    ISA_P0_PA,
    ISA_T0_K,
    R_AIR_JKGK,
    RHO0_KGM3,
    incompressible_cas_mps,
    incompressible_qc_pa,
    isa_altitude_m,
    isa_pressure_pa,
)

__all__ = [
    "A0_MPS",
    "GAMMA",
    "P0_PA",
    "PRESSURE_ALTITUDE_MAX_M",
    "PRESSURE_ALTITUDE_MIN_M",
    "QC_SONIC_PA",
    "RHO0_KGM3",
    "T0_K",
    "airspeed_law",
    "altimeter_correction_m",
    "cas_from_qc_mps",
    "mach_from_qc",
    "mach_from_tas",
    "pressure_altitude_m",
    "qc_from_cas_pa",
    "qc_from_mach_pa",
    "qc_from_tas_pa",
    "qc_from_tas_sq_derivatives",
    "qc_from_tas_sq_pa",
    "qc_from_total_derivatives",
    "qc_from_total_pa",
    "speed_of_sound_mps",
    "static_pressure_pa",
]

GAMMA = 1.4
P0_PA = ISA_P0_PA
T0_K = ISA_T0_K
A0_MPS = math.sqrt(GAMMA * R_AIR_JKGK * T0_K)      # 340.294 m/s
# ISA troposphere as the ICAO tables give it: -2,000 ft up to the tropopause (11 km
# geopotential, 36,089 ft); above it the temperature no longer falls and the law changes.
PRESSURE_ALTITUDE_MIN_M = -2000.0 * FT_TO_M
PRESSURE_ALTITUDE_MAX_M = 11000.0

_QC_OVER_P_SONIC = (1.0 + 0.2) ** 3.5 - 1.0         # 0.8929: q_c/p at M = 1
# The largest impact pressure the calibrated-airspeed law takes (V_c = a0), Pa.
QC_SONIC_PA = _QC_OVER_P_SONIC * P0_PA


def _numeric(lib):
    return lib is np


def _floats(lib, *values):
    """The inputs as float arrays with numpy (lists and scalars alike); MX as they are."""
    return tuple(np.asarray(v, dtype=float) for v in values) if _numeric(lib) else values


def _refuse_outside(name, value, lo, hi, what):
    """PitotcalError naming `name` if any finite-checked value lies outside [lo, hi]."""
    x = np.asarray(value, dtype=float)
    bad = ~np.isfinite(x) | (x < lo) | (x > hi)
    if np.any(bad):
        first = float(x[bad].flat[0]) if x.ndim else float(x)
        raise PitotcalError(f"{name} {first:g} is outside {what} [{lo:g}, {hi:g}]", param=name)


def speed_of_sound_mps(oat_k, lib=np):
    """Speed of sound a = sqrt(γ R T_s), m/s, at static air temperature `oat_k` (K)."""
    (oat_k,) = _floats(lib, oat_k)
    return lib.sqrt(GAMMA * R_AIR_JKGK * oat_k)


def mach_from_tas(tas_mps, oat_k, lib=np):
    """Mach number M = V_t / sqrt(γ R T_s) of a true airspeed (m/s) at static temperature (K)."""
    (tas_mps,) = _floats(lib, tas_mps)
    return tas_mps / speed_of_sound_mps(oat_k, lib)


def qc_from_mach_pa(mach, ps_pa, lib=np):
    """Impact pressure q_c = p_s [(1 + 0.2 M²)^3.5 − 1], Pa, subsonic (isentropic).

    Parameters
    ----------
    mach : array_like or casadi.MX
        Mach number, 0 ≤ M < 1.
    ps_pa : array_like or casadi.MX
        Static pressure, Pa.
    lib : module
        numpy (checked) or casadi.
    """
    mach, ps_pa = _floats(lib, mach, ps_pa)
    if _numeric(lib):
        _refuse_outside("mach", np.abs(mach), 0.0, 1.0, "the subsonic range")
    return ps_pa * ((1.0 + 0.2 * mach ** 2) ** 3.5 - 1.0)


def qc_from_tas_sq_pa(tas_sq, ps_pa, oat_k, lib=np):
    """Impact pressure, Pa, of a true airspeed squared V_t² (m²/s²) at p_s (Pa) and T_s (K).

    Notes
    -----
    q_c = p_s [(1 + 0.2 V_t² / (γ R T_s))^3.5 − 1]. Takes V_t² because the measurement model
    (`pitotcal.core.measurement.tas_squared`) builds it without a square root.
    """
    tas_sq, ps_pa, oat_k = _floats(lib, tas_sq, ps_pa, oat_k)
    mach_sq = tas_sq / (GAMMA * R_AIR_JKGK * oat_k)
    if _numeric(lib):
        _refuse_outside("mach", np.sqrt(np.abs(mach_sq)), 0.0, 1.0, "the subsonic range")
    return ps_pa * ((1.0 + 0.2 * mach_sq) ** 3.5 - 1.0)


def qc_from_tas_sq_derivatives(tas_sq, ps_pa, oat_k, lib=np):
    """(dq_c/dV_t², d²q_c/d(V_t²)²) of `qc_from_tas_sq_pa` at fixed p_s and T_s.

    Notes
    -----
    With c = 0.2 / (γ R T_s): dq_c/dV_t² = 3.5 c p_s (1 + c V_t²)^2.5 (→ ½ρ as M → 0) and
    d²q_c/d(V_t²)² = 2.5 c (dq_c/dV_t²) / (1 + c V_t²).
    """
    tas_sq, ps_pa, oat_k = _floats(lib, tas_sq, ps_pa, oat_k)
    c = 0.2 / (GAMMA * R_AIR_JKGK * oat_k)
    base = 1.0 + c * tas_sq
    slope = 3.5 * c * ps_pa * base ** 2.5
    return slope, 2.5 * c * slope / base


def qc_from_total_pa(tas_sq, pt_pa, oat_k, lib=np):
    """Impact pressure, Pa, of V_t² (m²/s²) at a known total pressure p_T (Pa) and T_s (K).

    Notes
    -----
    p_T / p_s = (1 + 0.2 M²)^3.5 with p_T = p_s + q_c, so

        q_c = p_T [1 − (1 + 0.2 M²)^−3.5],   M² = V_t² / (γ R T_s).

    The calibration's prediction (`estimation.identification.residual`): the static port reads
    p_s,ind = p_s + Δp_p and the transducer q_ci = q_c − Δp_p, so their sum p_s,ind + q_ci is
    the true total pressure whatever the static-source error, and q_c follows from V_t
    without knowing Δp_p. As M → 0 this tends to ½ρV_t² with ρ = p_T / (R T_s).
    """
    tas_sq, pt_pa, oat_k = _floats(lib, tas_sq, pt_pa, oat_k)
    mach_sq = tas_sq / (GAMMA * R_AIR_JKGK * oat_k)
    if _numeric(lib):
        _refuse_outside("mach", np.sqrt(np.abs(mach_sq)), 0.0, 1.0, "the subsonic range")
    return pt_pa * (1.0 - (1.0 + 0.2 * mach_sq) ** -3.5)


def qc_from_total_derivatives(tas_sq, pt_pa, oat_k, lib=np):
    """(dq_c/dV_t², d²q_c/d(V_t²)²) of `qc_from_total_pa` at fixed p_T and T_s.

    Notes
    -----
    With c = 0.2 / (γ R T_s): dq_c/dV_t² = 3.5 c p_T (1 + c V_t²)^−4.5 (→ ½ρ as M → 0) and
    d²q_c/d(V_t²)² = −4.5 c (dq_c/dV_t²) / (1 + c V_t²).
    """
    tas_sq, pt_pa, oat_k = _floats(lib, tas_sq, pt_pa, oat_k)
    c = 0.2 / (GAMMA * R_AIR_JKGK * oat_k)
    base = 1.0 + c * tas_sq
    slope = 3.5 * c * pt_pa * base ** -4.5
    return slope, -4.5 * c * slope / base


def qc_from_tas_pa(tas_mps, ps_pa, oat_k, lib=np):
    """Impact pressure, Pa, of a true airspeed (m/s) at static pressure (Pa) and temperature (K).

    Example
    -------
    >>> round(float(qc_from_tas_pa(102.8889, 101325.0, 288.15)), 1)   # 200 kt, sea level
    6633.5
    """
    (tas_mps,) = _floats(lib, tas_mps)
    return qc_from_tas_sq_pa(tas_mps ** 2, ps_pa, oat_k, lib)


def mach_from_qc(qc_pa, ps_pa, lib=np):
    """Mach number from impact and static pressure, M = sqrt(5 [(q_c/p_s + 1)^(2/7) − 1]).

    The inverse of `qc_from_mach_pa`; a negative q_c (noise near zero airspeed) gives the
    negative of the Mach number of |q_c|, so a curve stays continuous through zero.
    """
    qc_pa, ps_pa = _floats(lib, qc_pa, ps_pa)
    if _numeric(lib):
        _refuse_outside("qc_pa / ps_pa", np.abs(qc_pa) / ps_pa,
                        0.0, _QC_OVER_P_SONIC, "the subsonic range")
    ratio = abs(qc_pa) / ps_pa
    return lib.sign(qc_pa) * lib.sqrt(5.0 * ((ratio + 1.0) ** (2.0 / 7.0) - 1.0))


def cas_from_qc_mps(qc_pa, lib=np):
    """Calibrated airspeed, m/s, from impact pressure (Pa): the standard airspeed-indicator law.

    Notes
    -----
    V_c = a₀ sqrt(5 [(q_c/p₀ + 1)^(2/7) − 1]), a₀ = 340.294 m/s, p₀ = 101,325 Pa: the airspeed
    whose isentropic impact pressure at sea-level standard conditions is q_c. Differs from
    `pitotcal.core.units.incompressible_cas_mps` (sqrt(2 q_c/ρ₀), the incompressible convention) by
    about −V_c (V_c/a₀)²/8. A negative q_c gives the negative of the speed of |q_c|.

    Example
    -------
    >>> round(float(cas_from_qc_mps(6633.546)) / 0.514444, 2)                # knots
    200.0
    """
    (qc_pa,) = _floats(lib, qc_pa)
    if _numeric(lib):
        _refuse_outside("qc_pa", np.abs(qc_pa), 0.0, QC_SONIC_PA,
                        "the subsonic range")
    return A0_MPS * mach_from_qc(qc_pa, P0_PA, lib)


def qc_from_cas_pa(cas_mps, lib=np):
    """Impact pressure, Pa, of a calibrated airspeed (m/s): p₀ [(1 + 0.2 (V_c/a₀)²)^3.5 − 1]."""
    (cas_mps,) = _floats(lib, cas_mps)
    return qc_from_mach_pa(cas_mps / A0_MPS, P0_PA, lib)


def airspeed_law(air_data):
    """(q_c of an airspeed, airspeed of a q_c): how an airspeed indicator turns impact pressure
    into V_i and V_c in the air-data mode `air_data` (`pitotcal.core.measurement`).

    "compressible": the standard calibrated-airspeed law (`qc_from_cas_pa`, `cas_from_qc_mps`);
    "incompressible": sqrt(2 q / ρ₀) (`pitotcal.core.units.incompressible_cas_mps`), the law
    that goes with the paper's eq. 2.
    """
    if air_data == "compressible":
        return qc_from_cas_pa, cas_from_qc_mps
    return incompressible_qc_pa, incompressible_cas_mps


def pressure_altitude_m(ps_pa, lib=np):
    """ISA pressure altitude, m (geopotential), of a static pressure (Pa); troposphere only.

    Notes
    -----
    H = (T₀/L) [1 − (p_s/p₀)^(1/n)], n = g₀/(R L) = 5.2559. Valid from −2,000 ft to the
    tropopause (11,000 m, 36,089 ft), i.e. p_s from 22,632 Pa to 108,866 Pa; outside it a
    numpy input is refused with a PitotcalError.
    """
    (ps_pa,) = _floats(lib, ps_pa)
    if _numeric(lib):
        lo, hi = (float(static_pressure_pa(h)) for h in (PRESSURE_ALTITUDE_MAX_M,
                                                         PRESSURE_ALTITUDE_MIN_M))
        _refuse_outside("ps_pa", ps_pa, lo * (1 - 1e-12), hi * (1 + 1e-12),
                        "the ISA troposphere")
    return isa_altitude_m(ps_pa, lib)


def static_pressure_pa(pressure_altitude_m, lib=np):
    """ISA static pressure, Pa, at a pressure altitude (m, geopotential); troposphere only.

    p_s = p₀ (1 − L H / T₀)^n, the inverse of `pressure_altitude_m`.
    """
    (pressure_altitude_m,) = _floats(lib, pressure_altitude_m)
    if _numeric(lib):
        _refuse_outside("pressure_altitude_m", pressure_altitude_m, PRESSURE_ALTITUDE_MIN_M,
                        PRESSURE_ALTITUDE_MAX_M, "the ISA troposphere")
    return isa_pressure_pa(pressure_altitude_m, lib)


def altimeter_correction_m(dp_static_pa, pressure_altitude_ic_m, lib=np):
    """Altimeter position-error correction ΔH_pc = H_c − H_ic, m, of a static-source error.

    Parameters
    ----------
    dp_static_pa : array_like or casadi.MX
        Static-source error Δp_p = p_s,ind − p_s, Pa (the static port reads high when > 0).
        With all the pressure error in the static source it equals q_c − q_ci.
    pressure_altitude_ic_m : array_like or casadi.MX
        Indicated (instrument-corrected) pressure altitude H_ic, m, of the static port's reading.

    Notes
    -----
    Exact through the pressure-altitude function: ΔH_pc = H(p(H_ic) − Δp_p) − H_ic. To first
    order this is +Δp_p / (ρ g₀) with ρ the ISA density at H_ic (dp/dH = −ρ g₀): a static port
    reading high shows an altitude too low, so the correction is positive.
    """
    ps_ind = static_pressure_pa(pressure_altitude_ic_m, lib)
    return pressure_altitude_m(ps_ind - dp_static_pa, lib) - pressure_altitude_ic_m
