"""Unit conversions and atmosphere constants: the one place they live.

SI inside the library; knots and feet only at the edges (reports, pilot cards, CLI options).
"""

import numpy as np

__all__ = [
    "FT_TO_M",
    "G0_MPS2",
    "ISA_EXPONENT",
    "ISA_LAPSE_KPM",
    "ISA_P0_PA",
    "ISA_T0_K",
    "KT_TO_MPS",
    "NM_TO_M",
    "PA_PER_UNIT",
    "RAD_PER_UNIT",
    "M_PER_UNIT",
    "MPS_PER_UNIT",
    "S_PER_UNIT",
    "TEMPERATURE_UNITS",
    "RHO0_KGM3",
    "R_AIR_JKGK",
    "density_kgm3",
    "ft_to_m",
    "incompressible_cas_mps",
    "incompressible_qc_pa",
    "isa_altitude_m",
    "isa_density_kgm3",
    "isa_pressure_pa",
    "isa_temperature_k",
    "kt_to_mps",
    "m_to_ft",
    "mps_to_kt",
    "wind_polar",
    "wind_vector_mps",
]

KT_TO_MPS = 1852.0 / 3600.0          # international knot
FT_TO_M = 0.3048
NM_TO_M = 1852.0
RHO0_KGM3 = 1.225                    # sea-level standard density (docs/interfaces.md §2)
R_AIR_JKGK = 287.05287               # specific gas constant of dry air (docs/interfaces.md §1)
G0_MPS2 = 9.80665
PSI_TO_PA = 0.45359237 * G0_MPS2 / 0.0254 ** 2      # pound-force per square inch, 6894.757 Pa

# Units a data file may declare (a column mapping, docs/interfaces.md §1b): SI per unit.
S_PER_UNIT = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "min": 60.0}
MPS_PER_UNIT = {"m/s": 1.0, "ft/s": FT_TO_M, "kt": KT_TO_MPS, "km/h": 1.0 / 3.6,
                "mph": 0.44704, "cm/s": 0.01}
M_PER_UNIT = {"m": 1.0, "ft": FT_TO_M, "km": 1000.0}
RAD_PER_UNIT = {"rad": 1.0, "deg": np.pi / 180.0}
PA_PER_UNIT = {"Pa": 1.0, "hPa": 100.0, "mbar": 100.0, "mb": 100.0, "kPa": 1000.0,
               "psi": PSI_TO_PA, "psf": PSI_TO_PA / 144.0, "inHg": 3386.389,
               "mmHg": 133.3224, "inH2O": 249.089}
# temperature: (scale, offset) with T_K = scale * value + offset
TEMPERATURE_UNITS = {"K": (1.0, 0.0), "degC": (1.0, 273.15),
                     "degF": (5.0 / 9.0, 459.67 * 5.0 / 9.0), "degR": (5.0 / 9.0, 0.0)}


def kt_to_mps(v_kt):
    return np.multiply(v_kt, KT_TO_MPS)


def mps_to_kt(v_mps):
    return np.divide(v_mps, KT_TO_MPS)


def ft_to_m(h_ft):
    return np.multiply(h_ft, FT_TO_M)


def m_to_ft(h_m):
    return np.divide(h_m, FT_TO_M)


def density_kgm3(ps_pa, oat_k):
    """Air density from static pressure and outside air temperature, rho = p / (R T)."""
    return np.asarray(ps_pa, dtype=float) / (R_AIR_JKGK * np.asarray(oat_k, dtype=float))


def wind_vector_mps(speed_mps, from_deg):
    """(north, east) air-mass velocity, m/s, of a wind blowing FROM `from_deg` (deg true)."""
    a = np.radians(from_deg)
    return -np.multiply(speed_mps, np.cos(a)), -np.multiply(speed_mps, np.sin(a))


def wind_polar(wind_n_mps, wind_e_mps):
    """(speed_mps, from_deg in [0, 360)) of an air-mass velocity (the way it blows TO)."""
    speed = np.hypot(wind_n_mps, wind_e_mps)
    from_deg = np.degrees(np.arctan2(-np.asarray(wind_e_mps), -np.asarray(wind_n_mps))) % 360.0
    return speed, np.where(from_deg >= 360.0, 0.0, from_deg)[()]   # -1e-16 % 360 -> 360.0


def incompressible_cas_mps(qc_pa):
    """The incompressible airspeed of an impact pressure, V = sqrt(2 q / rho0), m/s.

    The convention of docs/interfaces.md §2 and of `--air incompressible` (the paper's eq. 2):
    the standard calibrated airspeed is `pitotcal.core.airdata.cas_from_qc_mps`, which is
    lower by about V (V/a0)^2 / 8.

    Negative pressures give a negative speed of the same magnitude rather than NaN, so a
    correction curve stays continuous near zero.
    """
    qc = np.asarray(qc_pa, dtype=float)
    return np.sign(qc) * np.sqrt(2.0 * np.abs(qc) / RHO0_KGM3)


def incompressible_qc_pa(cas_mps):
    """Impact pressure of an incompressible airspeed, q = rho0 V^2 / 2 (inverse of
    `incompressible_cas_mps`)."""
    return 0.5 * RHO0_KGM3 * np.asarray(cas_mps, dtype=float) ** 2


# International Standard Atmosphere, troposphere: the one place of its formula. Unchecked, so the
# simulator may evaluate it anywhere; `pitotcal.core.airdata` (static_pressure_pa,
# pressure_altitude_m) adds the validity range and is what data should go through.
ISA_T0_K = 288.15
ISA_P0_PA = 101325.0
ISA_LAPSE_KPM = 0.0065
ISA_EXPONENT = G0_MPS2 / (R_AIR_JKGK * ISA_LAPSE_KPM)   # 5.2559: p/p0 = (T/T0)^n


def _floats(value, lib):
    """A float array with numpy; a CasADi symbol as it is (`lib` is casadi)."""
    return np.asarray(value, dtype=float) if lib is np else value


def isa_temperature_k(alt_m, lib=np):
    """ISA temperature T = T₀ − L H, K, at a geopotential altitude H (m).

    `lib` is numpy (the default) or casadi, as in `pitotcal.core.airdata`.
    """
    return ISA_T0_K - ISA_LAPSE_KPM * _floats(alt_m, lib)


def isa_pressure_pa(alt_m, lib=np):
    """ISA static pressure p = p₀ (T/T₀)^n, Pa, n = g₀/(R L), at a geopotential altitude (m)."""
    return ISA_P0_PA * (isa_temperature_k(alt_m, lib) / ISA_T0_K) ** ISA_EXPONENT


def isa_altitude_m(ps_pa, lib=np):
    """ISA pressure altitude H = (T₀/L) [1 − (p/p₀)^(1/n)], m, of a static pressure (Pa).

    The inverse of `isa_pressure_pa`.
    """
    ratio = _floats(ps_pa, lib) / ISA_P0_PA
    return ISA_T0_K / ISA_LAPSE_KPM * (1.0 - ratio ** (1.0 / ISA_EXPONENT))


def isa_density_kgm3(alt_m):
    """ISA density ρ = p / (R T), kg/m³, at a geopotential altitude (m)."""
    return density_kgm3(isa_pressure_pa(alt_m), isa_temperature_k(alt_m))
