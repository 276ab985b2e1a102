"""The standard air-data relations (subsonic and supersonic pitot, ISA to 32 km), written once
for numpy and CasADi.

    M    = V_t / sqrt(γ R T_s)                              Mach number
    q_c  = p_s [(1 + 0.2 M²)^3.5 − 1]                       impact pressure, M ≤ 1 (isentropic)
    q_c  = p_s [166.92 M⁷ / (7 M² − 1)^2.5 − 1]             impact pressure, M ≥ 1 (Rayleigh)
    V_c  = a₀ M(q_c, p₀)                                    calibrated airspeed (either law)
    H    = the ISA pressure altitude of p_s (geopotential; `pitotcal.core.units`)

Above Mach 1 the pitot tube stands behind a normal shock: it reads the total pressure behind
the shock, the Rayleigh pitot formula (NACA Report 1135, eq. 100); 166.92 = 1.2^3.5 6^2.5 for
γ = 1.4. Both laws give the same q_c at M = 1, with the same first and second derivatives in
M² (the shock's entropy rise is of third order in M² − 1), so the joined relation is smooth
enough for IPOPT. The calibrated-airspeed law above a₀ (661.5 kt) is the Rayleigh law at
p₀ too.

γ = 1.4, p₀ = 101,325 Pa, T₀ = 288.15 K, a₀ = sqrt(γ R T₀) = 340.294 m/s; R, g₀ and the ISA
layers from `pitotcal.core.units` (the one place of the atmosphere constants and of the ISA
formula, which `static_pressure_pa` and `pressure_altitude_m` check the range of). 0.2 and 3.5
are (γ − 1)/2 and γ/(γ − 1) for γ = 1.4.

Each function takes `lib` (numpy by default, or `casadi`): only its `sqrt`, `sign`, `fabs`,
`fmax`, `log`, `exp` and `if_else` are used, so the same expressions evaluate numpy arrays and
build the output-error problem's MX graph. With numpy the inputs are checked against the
validity range (Mach 0 to `MACH_MAX`; the ISA from −2,000 ft to 32 km) and refused with a
`PitotcalError`; symbolic inputs cannot be checked.

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
    ISA_TOP_M,
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
    "MACH_MAX",
    "P0_PA",
    "PRESSURE_ALTITUDE_MAX_M",
    "PRESSURE_ALTITUDE_MIN_M",
    "QC_MAX_PA",
    "QC_OVER_PS_MAX",
    "QC_SONIC_PA",
    "RHO0_KGM3",
    "T0_K",
    "airspeed_law",
    "altimeter_correction_m",
    "cas_from_qc_mps",
    "mach_from_qc",
    "mach_from_tas",
    "pitot_pressure_ratio",
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
# The ISA as the ICAO tables give it: -2,000 ft up to the top of the layers in
# `pitotcal.core.units` (32 km geopotential, 104,987 ft).
PRESSURE_ALTITUDE_MIN_M = -2000.0 * FT_TO_M
PRESSURE_ALTITUDE_MAX_M = ISA_TOP_M
# The highest Mach number the relations take: air stays a perfect gas of γ = 1.4 to about
# there (the stagnation temperature reaches 2.8 T_s); nothing pitotcal calibrates flies faster.
MACH_MAX = 3.0

# Rayleigh pitot formula p_T2/p_s = _RAYLEIGH_K M⁷ / (7 M² − 1)^2.5, γ = 1.4
_RAYLEIGH_K = 1.2 ** 3.5 * 6.0 ** 2.5               # 166.9216
_QC_OVER_P_SONIC = (1.0 + 0.2) ** 3.5 - 1.0         # 0.8929: q_c/p at M = 1
# The impact pressure of V_c = a0, Pa (the two laws meet there).
QC_SONIC_PA = _QC_OVER_P_SONIC * P0_PA


def _choose(lib, cond, yes, no):
    return np.where(cond, yes, no) if lib is np else lib.if_else(cond, yes, no)


def _fmax(lib, a, b):
    return np.maximum(a, b) if lib is np else lib.fmax(a, b)


def pitot_pressure_ratio(mach_sq, lib=np):
    """(R, dR/dM², d²R/d(M²)²) of the pitot's total-to-static pressure ratio R = p_T/p_s.

    Notes
    -----
    R = (1 + 0.2 M²)^3.5 up to M = 1 (isentropic), R = 166.92 M⁷/(7 M² − 1)^2.5 above
    (Rayleigh: the total pressure behind a normal shock). Value, first and second derivative
    agree at M = 1. Unchecked; `mach_sq` may be a CasADi symbol.
    """
    x = mach_sq
    base = 1.0 + 0.2 * x
    sub = (base ** 3.5, 0.7 * base ** 2.5, 0.35 * base ** 1.5)
    xs = _fmax(lib, x, 1.0)          # the supersonic branch stays finite where it is not used
    rs = _RAYLEIGH_K * xs ** 3.5 * (7.0 * xs - 1.0) ** -2.5
    g = 3.5 / xs - 17.5 / (7.0 * xs - 1.0)                    # d ln R / dM²
    sup = (rs, rs * g, rs * (g * g - 3.5 / xs ** 2 + 122.5 / (7.0 * xs - 1.0) ** 2))
    return tuple(_choose(lib, x > 1.0, b, a) for a, b in zip(sub, sup))


def _mach_sq_of_ratio(ratio, lib):
    """M² of a pitot pressure ratio R = p_T/p_s ≥ 1: the isentropic inverse up to R(1), Newton
    on ln M² above (8 steps from the law's large-Mach asymptote reach 1e-15)."""
    sub = 5.0 * (ratio ** (2.0 / 7.0) - 1.0)
    r_sup = _fmax(lib, ratio, _QC_OVER_P_SONIC + 1.0)
    u = lib.log(_fmax(lib, (r_sup - 0.46) / 1.28756, 1.0))   # R → 1.28756 M² + 0.46
    target = lib.log(r_sup)
    for _ in range(8):
        x = lib.exp(u)
        value = math.log(_RAYLEIGH_K) + 3.5 * u - 2.5 * lib.log(7.0 * x - 1.0)
        u = u - (value - target) / (3.5 - 17.5 * x / (7.0 * x - 1.0))
    return _choose(lib, ratio > _QC_OVER_P_SONIC + 1.0, lib.exp(u), sub)


# The largest q_c/p_s the relations take (Mach `MACH_MAX`).
QC_OVER_PS_MAX = float(pitot_pressure_ratio(MACH_MAX ** 2)[0]) - 1.0
# The largest impact pressure the calibrated-airspeed law takes (V_c = MACH_MAX a0), Pa.
QC_MAX_PA = QC_OVER_PS_MAX * P0_PA


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


_MACH_RANGE = "the Mach range of the pitot relations"
_ISA_RANGE = "the ISA (-2,000 ft to 32 km)"


def _refuse_mach_sq(mach_sq):
    _refuse_outside("mach", np.sqrt(np.abs(mach_sq)), 0.0, MACH_MAX, _MACH_RANGE)


def qc_from_mach_pa(mach, ps_pa, lib=np):
    """Impact pressure q_c = p_s (R(M) − 1), Pa: isentropic below Mach 1, Rayleigh above.

    Parameters
    ----------
    mach : array_like or casadi.MX
        Mach number, 0 ≤ M ≤ `MACH_MAX`.
    ps_pa : array_like or casadi.MX
        Static pressure, Pa.
    lib : module
        numpy (checked) or casadi.
    """
    mach, ps_pa = _floats(lib, mach, ps_pa)
    if _numeric(lib):
        _refuse_mach_sq(mach ** 2)
    return ps_pa * (pitot_pressure_ratio(mach ** 2, lib)[0] - 1.0)


def _mach_sq_of_tas_sq(tas_sq, oat_k, lib):
    mach_sq = tas_sq / (GAMMA * R_AIR_JKGK * oat_k)
    if _numeric(lib):
        _refuse_mach_sq(mach_sq)
    return mach_sq, 1.0 / (GAMMA * R_AIR_JKGK * oat_k)


def qc_from_tas_sq_pa(tas_sq, ps_pa, oat_k, lib=np):
    """Impact pressure, Pa, of a true airspeed squared V_t² (m²/s²) at p_s (Pa) and T_s (K).

    Notes
    -----
    q_c = p_s (R(M²) − 1), M² = V_t² / (γ R T_s), R the pitot pressure ratio
    (`pitot_pressure_ratio`: isentropic, Rayleigh above Mach 1). Takes V_t² because the
    measurement model (`pitotcal.core.measurement.tas_squared`) builds it without a square root.
    """
    tas_sq, ps_pa, oat_k = _floats(lib, tas_sq, ps_pa, oat_k)
    mach_sq, _ = _mach_sq_of_tas_sq(tas_sq, oat_k, lib)
    return ps_pa * (pitot_pressure_ratio(mach_sq, lib)[0] - 1.0)


def qc_from_tas_sq_derivatives(tas_sq, ps_pa, oat_k, lib=np):
    """(dq_c/dV_t², d²q_c/d(V_t²)²) of `qc_from_tas_sq_pa` at fixed p_s and T_s.

    Notes
    -----
    With c = 1 / (γ R T_s): dq_c/dV_t² = p_s R' c (→ ½ρ as M → 0) and d²q_c/d(V_t²)² =
    p_s R'' c², R', R'' the derivatives of the pitot pressure ratio in M².
    """
    tas_sq, ps_pa, oat_k = _floats(lib, tas_sq, ps_pa, oat_k)
    c = 1.0 / (GAMMA * R_AIR_JKGK * oat_k)
    _, d1, d2 = pitot_pressure_ratio(c * tas_sq, lib)
    return ps_pa * d1 * c, ps_pa * d2 * c * c


def qc_from_total_pa(tas_sq, pt_pa, oat_k, lib=np):
    """Impact pressure, Pa, of V_t² (m²/s²) at a known total pressure p_T (Pa) and T_s (K).

    Notes
    -----
    p_T / p_s = R(M²) with p_T = p_s + q_c the pitot's pressure (behind the normal shock above
    Mach 1), so

        q_c = p_T [1 − 1/R(M²)],   M² = V_t² / (γ R T_s),

    below Mach 1 q_c = p_T [1 − (1 + 0.2 M²)^−3.5].

    The calibration's prediction (`estimation.identification.residual`): the static port reads
    p_s,ind = p_s + Δp_p and the transducer q_ci = q_c − Δp_p, so their sum p_s,ind + q_ci is
    the true total pressure whatever the static-source error, and q_c follows from V_t
    without knowing Δp_p. As M → 0 this tends to ½ρV_t² with ρ = p_T / (R T_s).
    """
    tas_sq, pt_pa, oat_k = _floats(lib, tas_sq, pt_pa, oat_k)
    mach_sq, _ = _mach_sq_of_tas_sq(tas_sq, oat_k, lib)
    return pt_pa * (1.0 - 1.0 / pitot_pressure_ratio(mach_sq, lib)[0])


def qc_from_total_derivatives(tas_sq, pt_pa, oat_k, lib=np):
    """(dq_c/dV_t², d²q_c/d(V_t²)²) of `qc_from_total_pa` at fixed p_T and T_s.

    Notes
    -----
    With c = 1 / (γ R T_s): dq_c/dV_t² = p_T c R'/R² (→ ½ρ as M → 0) and d²q_c/d(V_t²)² =
    p_T c² (R''/R² − 2 R'²/R³).
    """
    tas_sq, pt_pa, oat_k = _floats(lib, tas_sq, pt_pa, oat_k)
    c = 1.0 / (GAMMA * R_AIR_JKGK * oat_k)
    r, d1, d2 = pitot_pressure_ratio(c * tas_sq, lib)
    return pt_pa * c * d1 / r ** 2, pt_pa * c * c * (d2 / r ** 2 - 2.0 * d1 ** 2 / r ** 3)


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
    """Mach number from impact and static pressure: the inverse of `qc_from_mach_pa`.

    Below Mach 1 M = sqrt(5 [(q_c/p_s + 1)^(2/7) − 1]); above, the Rayleigh pitot formula
    solved for M. A negative q_c (noise near zero airspeed) gives the negative of the Mach
    number of |q_c|, so a curve stays continuous through zero.
    """
    qc_pa, ps_pa = _floats(lib, qc_pa, ps_pa)
    if _numeric(lib):
        _refuse_outside("qc_pa / ps_pa", np.abs(qc_pa) / ps_pa,
                        0.0, QC_OVER_PS_MAX, _MACH_RANGE)
    ratio = abs(qc_pa) / ps_pa
    return lib.sign(qc_pa) * lib.sqrt(_mach_sq_of_ratio(ratio + 1.0, lib))


def cas_from_qc_mps(qc_pa, lib=np):
    """Calibrated airspeed, m/s, from impact pressure (Pa): the standard airspeed-indicator law.

    Notes
    -----
    V_c = a₀ sqrt(5 [(q_c/p₀ + 1)^(2/7) − 1]) up to V_c = a₀ = 340.294 m/s (q_c =
    `QC_SONIC_PA`), the Rayleigh law at p₀ above it; p₀ = 101,325 Pa: the airspeed whose impact
    pressure at sea-level standard conditions is q_c. Differs from
    `pitotcal.core.units.incompressible_cas_mps` (sqrt(2 q_c/ρ₀), the incompressible
    convention) by about −V_c (V_c/a₀)²/8. A negative q_c gives the negative of the speed of
    |q_c|.

    Example
    -------
    >>> round(float(cas_from_qc_mps(6633.546)) / 0.514444, 2)                # knots
    200.0
    """
    (qc_pa,) = _floats(lib, qc_pa)
    if _numeric(lib):
        _refuse_outside("qc_pa", np.abs(qc_pa), 0.0, QC_MAX_PA, _MACH_RANGE)
    return A0_MPS * mach_from_qc(qc_pa, P0_PA, lib)


def qc_from_cas_pa(cas_mps, lib=np):
    """Impact pressure, Pa, of a calibrated airspeed (m/s): p₀ (R(V_c/a₀) − 1), the pitot
    pressure ratio R isentropic up to a₀, Rayleigh above."""
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
    """ISA pressure altitude, m (geopotential), of a static pressure (Pa).

    Notes
    -----
    In the troposphere H = (T₀/L) [1 − (p_s/p₀)^(1/n)], n = g₀/(R L) = 5.2559; above 11 km
    the isothermal and the +1 K/km layers' laws (`pitotcal.core.units.isa_altitude_m`). Valid
    from −2,000 ft to 32 km (104,987 ft), i.e. p_s from 868.0 Pa to 108,866 Pa; outside it a
    numpy input is refused with a PitotcalError.
    """
    (ps_pa,) = _floats(lib, ps_pa)
    if _numeric(lib):
        lo, hi = (float(static_pressure_pa(h)) for h in (PRESSURE_ALTITUDE_MAX_M,
                                                         PRESSURE_ALTITUDE_MIN_M))
        _refuse_outside("ps_pa", ps_pa, lo * (1 - 1e-12), hi * (1 + 1e-12), _ISA_RANGE)
    return isa_altitude_m(ps_pa, lib)


def static_pressure_pa(pressure_altitude_m, lib=np):
    """ISA static pressure, Pa, at a pressure altitude (m, geopotential), −2,000 ft to 32 km.

    The inverse of `pressure_altitude_m` (`pitotcal.core.units.isa_pressure_pa` with its
    range checked).
    """
    (pressure_altitude_m,) = _floats(lib, pressure_altitude_m)
    if _numeric(lib):
        _refuse_outside("pressure_altitude_m", pressure_altitude_m, PRESSURE_ALTITUDE_MIN_M,
                        PRESSURE_ALTITUDE_MAX_M, _ISA_RANGE)
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
