"""Unit conversions and atmosphere constants: the one place they live.

SI inside the library; knots and feet only at the edges (reports, pilot cards, CLI options).
"""

import numpy as np

__all__ = [
    "FT_TO_M",
    "G0_MPS2",
    "ISA_EXPONENT",
    "ISA_LAPSE_KPM",
    "ISA_LAYERS",
    "ISA_LAYER_BASES",
    "ISA_P0_PA",
    "ISA_T0_K",
    "ISA_TOP_M",
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
    "isa_state_of_density",
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


# International Standard Atmosphere (ICAO 1993): the one place of its formula. Layers of
# constant lapse rate in geopotential altitude H: the troposphere (T falls 6.5 K/km) to 11 km,
# the isothermal layer (216.65 K) to 20 km and the lower stratosphere (T rises 1 K/km) to
# 32 km. Each layer's base pressure follows from the one below, so p(H) is continuous with its
# slope −ρ g₀ (the temperature has a kink at each base). Unchecked, so the simulator may
# evaluate it anywhere (the top layer's law continues above 32 km, the troposphere's below
# 0); `pitotcal.core.airdata` (static_pressure_pa, pressure_altitude_m) adds the validity
# range and is what data should go through.
ISA_T0_K = 288.15
ISA_P0_PA = 101325.0
ISA_LAPSE_KPM = 0.0065
ISA_EXPONENT = G0_MPS2 / (R_AIR_JKGK * ISA_LAPSE_KPM)   # 5.2559: p/p0 = (T/T0)^n
# (base geopotential altitude m, dT/dH K/m) of each layer, from sea level up
ISA_LAYERS = ((0.0, -ISA_LAPSE_KPM), (11000.0, 0.0), (20000.0, 0.001))
ISA_TOP_M = 32000.0                  # the top of the last layer


def _floats(value, lib):
    """A float array with numpy; a CasADi symbol as it is (`lib` is casadi)."""
    return np.asarray(value, dtype=float) if lib is np else value


def _layer_t_p(base, dh, lib):
    """(T K, p Pa) dh (m) above a layer's base (H_b, T_b, p_b, lapse)."""
    _, t_b, p_b, lapse = base
    if lapse == 0.0:
        return t_b + 0.0 * dh, p_b * lib.exp(-G0_MPS2 * dh / (R_AIR_JKGK * t_b))
    t = t_b + lapse * dh
    return t, p_b * (t / t_b) ** (-G0_MPS2 / (R_AIR_JKGK * lapse))


def _layer_h(base, p, lib):
    """Geopotential altitude (m) of pressure `p` (Pa) in a layer (H_b, T_b, p_b, lapse)."""
    h_b, t_b, p_b, lapse = base
    if lapse == 0.0:
        return h_b - R_AIR_JKGK * t_b / G0_MPS2 * lib.log(p / p_b)
    return h_b + t_b / lapse * ((p / p_b) ** (-R_AIR_JKGK * lapse / G0_MPS2) - 1.0)


def _layer_bases():
    """((H_b, T_b, p_b, lapse), ...) of `ISA_LAYERS`, each base from the layer below."""
    bases = [(0.0, ISA_T0_K, ISA_P0_PA, ISA_LAYERS[0][1])]
    for h_b, lapse in ISA_LAYERS[1:]:
        t_b, p_b = _layer_t_p(bases[-1], h_b - bases[-1][0], np)
        bases.append((h_b, float(t_b), float(p_b), lapse))
    return tuple(bases)


# 11 km: 216.65 K, 22,632.06 Pa; 20 km: 216.65 K, 5,474.89 Pa
ISA_LAYER_BASES = _layer_bases()


def _choose(lib, inside, upper, lower):
    """`upper` where `inside`, else `lower`: numpy `where` or CasADi `if_else`."""
    return np.where(inside, upper, lower) if lib is np else lib.if_else(inside, upper, lower)


def _isa_state(alt_m, lib):
    """(T K, p Pa) at geopotential altitudes (m), each in its layer."""
    h = _floats(alt_m, lib)
    t, p = _layer_t_p(ISA_LAYER_BASES[0], h, lib)
    for base in ISA_LAYER_BASES[1:]:
        # the base itself clipped in: the unused branch stays finite, for CasADi's derivatives
        t_up, p_up = _layer_t_p(base, _fmax(lib, h, base[0]) - base[0], lib)
        t, p = _choose(lib, h >= base[0], t_up, t), _choose(lib, h >= base[0], p_up, p)
    return t, p


def _fmax(lib, a, b):
    return np.maximum(a, b) if lib is np else lib.fmax(a, b)


def isa_temperature_k(alt_m, lib=np):
    """ISA temperature, K, at a geopotential altitude H (m): T₀ − 6.5 K/km H to 11 km,
    216.65 K to 20 km, then +1 K/km (ICAO 1993).

    `lib` is numpy (the default) or casadi, as in `pitotcal.core.airdata`.
    """
    return _isa_state(alt_m, lib)[0]


def isa_pressure_pa(alt_m, lib=np):
    """ISA static pressure, Pa, at a geopotential altitude (m): p₀ (T/T₀)^n, n = g₀/(R L), in
    the troposphere; p_b exp(−g₀ (H − H_b)/(R T_b)) in the isothermal layer; the gradient law
    from the 20 km base above it."""
    return _isa_state(alt_m, lib)[1]


def isa_altitude_m(ps_pa, lib=np):
    """ISA pressure altitude, m (geopotential), of a static pressure (Pa): in the troposphere
    H = (T₀/L) [1 − (p/p₀)^(1/n)], and each layer's own law above.

    The inverse of `isa_pressure_pa`.
    """
    p = _floats(ps_pa, lib)
    h = _layer_h(ISA_LAYER_BASES[0], p, lib)
    for base in ISA_LAYER_BASES[1:]:
        below_base = p <= base[2]
        p_in = p if lib is np else lib.fmin(p, base[2])
        with np.errstate(invalid="ignore", divide="ignore"):
            h = _choose(lib, below_base, _layer_h(base, p_in, lib), h)
    return h


def isa_density_kgm3(alt_m):
    """ISA density ρ = p / (R T), kg/m³, at a geopotential altitude (m)."""
    return density_kgm3(isa_pressure_pa(alt_m), isa_temperature_k(alt_m))


def isa_state_of_density(rho_kgm3):
    """(p Pa, T K) of the ISA state of density ρ (kg/m³), numpy: in a layer of lapse L,
    T = T_b (ρ/ρ_b)^(1/(n − 1)) with n = −g₀/(R L); T = T_b in the isothermal layer."""
    rho = np.asarray(rho_kgm3, dtype=float)
    t = None
    for h_b, t_b, p_b, lapse in ISA_LAYER_BASES:
        rho_b = p_b / (R_AIR_JKGK * t_b)
        if lapse == 0.0:
            t_layer = np.full(rho.shape, t_b)
        else:
            n = -G0_MPS2 / (R_AIR_JKGK * lapse)
            t_layer = t_b * (rho / rho_b) ** (1.0 / (n - 1.0))
        t = t_layer if t is None else np.where(rho <= rho_b, t_layer, t)
    oat = t[()]
    return rho * R_AIR_JKGK * oat, oat
