"""The law behind every "KCAS" the planner, the pilot card and the simulator's tracking use.

Calibrated airspeed is the standard airspeed-indicator law applied to the isentropic impact
pressure of the true airspeed at the flight's static pressure and temperature; in the ISA at a
geopotential altitude H:

    q_c = p_s(H) [(1 + 0.2 V_t² / (γ R T_s(H)))^3.5 − 1]     (`airdata.qc_from_tas_pa`)
    V_c = a₀ sqrt(5 [(q_c/p₀ + 1)^(2/7) − 1])               (`airdata.cas_from_qc_mps`)

and back, V_t = a(T_s) M with M = sqrt(5 [(q_c/p_s + 1)^(2/7) − 1]). Equivalent airspeed,
V_t sqrt(ρ/ρ₀), is a different speed: at 10,000 ft and 260 KEAS the CAS is 262.2 kt, at
25,000 ft and 250 KEAS 257.3 kt (the compressibility correction grows with Mach and falls
with p_s); near sea level the two agree to ~0.01 kt at light-aircraft speeds.

Above Mach 1 the impact pressure is the Rayleigh pitot law's (`airdata.pitot_pressure_ratio`),
and a CAS above a₀ (661.5 kt) too. Altitudes are checked against the ISA's range, −2,000 ft to
32 km (`airdata.static_pressure_pa`).
"""

import numpy as np

from .airdata import (
    cas_from_qc_mps,
    mach_from_qc,
    qc_from_cas_pa,
    qc_from_tas_pa,
    qc_from_tas_sq_derivatives,
    speed_of_sound_mps,
    static_pressure_pa,
)
from .units import isa_temperature_k

__all__ = [
    "cas_from_tas_mps",
    "qc_from_tas_isa_pa",
    "qc_slope_per_tas",
    "tas_from_cas_mps",
    "tas_from_qc_mps",
]


def qc_from_tas_isa_pa(tas_mps, altitude_m):
    """Isentropic impact pressure, Pa, of a true airspeed (m/s) at an ISA altitude (m)."""
    return qc_from_tas_pa(tas_mps, static_pressure_pa(altitude_m), isa_temperature_k(altitude_m))


def tas_from_qc_mps(qc_pa, altitude_m):
    """True airspeed, m/s, whose isentropic impact pressure at an ISA altitude (m) is `qc_pa`.

    The inverse of `qc_from_tas_isa_pa`.
    """
    mach = mach_from_qc(qc_pa, static_pressure_pa(altitude_m))
    return mach * speed_of_sound_mps(isa_temperature_k(altitude_m))


def cas_from_tas_mps(tas_mps, altitude_m):
    """Calibrated airspeed, m/s, of a true airspeed (m/s) at an ISA altitude (m).

    Example
    -------
    >>> round(float(cas_from_tas_mps(tas_from_cas_mps(100.0, 3048.0), 3048.0)), 9)
    100.0
    """
    return cas_from_qc_mps(qc_from_tas_isa_pa(tas_mps, altitude_m))


def tas_from_cas_mps(cas_mps, altitude_m):
    """True airspeed, m/s, of a calibrated airspeed (m/s) at an ISA altitude (m).

    Example
    -------
    >>> round(float(tas_from_cas_mps(51.444, 244.0)), 2)          # 100 KCAS at 800 ft
    52.05
    """
    cas_mps = np.asarray(cas_mps, dtype=float)
    # qc_from_cas_pa squares the speed: a negative CAS keeps its sign, as the inverses do
    return np.sign(cas_mps) * tas_from_qc_mps(qc_from_cas_pa(np.abs(cas_mps)), altitude_m)


def qc_slope_per_tas(tas_mps, altitude_m):
    """dq_c/dV_t, Pa per m/s, of `qc_from_tas_isa_pa` (→ ρ V_t as M → 0)."""
    tas = np.asarray(tas_mps, dtype=float)
    slope_sq, _ = qc_from_tas_sq_derivatives(tas ** 2, static_pressure_pa(altitude_m),
                                             isa_temperature_k(altitude_m))
    return 2.0 * tas * slope_sq
