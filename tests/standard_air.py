"""Independent standard air data for the tests: flightcondition's airspeed chain, ambiance's
ICAO atmosphere, and the pitot relations written out from the normal-shock relations."""

import numpy as np

EARTH_RADIUS_M = 6356766.0      # geopotential to geometric height, as the ISA defines it


def reference(alt_m, **speed_kt):
    """flightcondition's FlightCondition at geopotential `alt_m` (m) and one airspeed in knots
    (``CAS=``, ``EAS=`` or ``TAS=``, scalar or array)."""
    from flightcondition import FlightCondition, unit

    h_m = EARTH_RADIUS_M * alt_m / (EARTH_RADIUS_M - alt_m)
    (name, value), = speed_kt.items()
    return FlightCondition(h=h_m * unit("m"), **{name: np.asarray(value) * unit("knots")})


# --- an independent pitot and airspeed chain, from the gas-dynamics relations themselves ------
# γ = 1.4 and the ISA sea level (p0, a0 from T0 = 288.15 K, R = 287.05287) as ICAO defines them;
# nothing below comes from pitotcal: the normal-shock relations (NACA Report 1135, eqs. 93-99)
# and the isentropic stagnation pressure, solved for Mach by bisection.
GAMMA = 1.4
P0_PA = 101325.0
A0_MPS = (GAMMA * 287.05287 * 288.15) ** 0.5


def pitot_pressure_ratio(mach):
    """p_pitot / p_s: isentropic stagnation below Mach 1; above, the stagnation pressure behind
    a normal shock (static pressure ratio across it, then isentropic from the Mach behind)."""
    m2 = np.asarray(mach, dtype=float) ** 2
    g = GAMMA
    stagnation = lambda msq: (1.0 + 0.5 * (g - 1.0) * msq) ** (g / (g - 1.0))   # noqa: E731
    sub = stagnation(m2)
    shock_m2 = np.maximum(m2, 1.0)
    p2_p1 = 1.0 + 2.0 * g / (g + 1.0) * (shock_m2 - 1.0)
    behind_m2 = (1.0 + 0.5 * (g - 1.0) * shock_m2) / (g * shock_m2 - 0.5 * (g - 1.0))
    return np.where(m2 > 1.0, p2_p1 * stagnation(behind_m2), sub)


def mach_of_ratio(ratio):
    """The Mach number of a pitot pressure ratio, by bisection on [0, 5] (60 halvings)."""
    ratio = np.asarray(ratio, dtype=float)
    lo, hi = np.zeros(ratio.shape), np.full(ratio.shape, 5.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        low = pitot_pressure_ratio(mid) < ratio
        lo, hi = np.where(low, mid, lo), np.where(low, hi, mid)
    return 0.5 * (lo + hi)


def qc_of_mach(mach, ps_pa):
    return np.asarray(ps_pa, dtype=float) * (pitot_pressure_ratio(mach) - 1.0)


def mach_of_qc(qc_pa, ps_pa):
    return mach_of_ratio(np.asarray(qc_pa, dtype=float) / np.asarray(ps_pa, dtype=float) + 1.0)


def cas_of_qc(qc_pa):
    """Calibrated airspeed, m/s: the Mach at sea-level standard p0 of q_c, times a0."""
    return A0_MPS * mach_of_qc(qc_pa, P0_PA)


def qc_of_cas(cas_mps):
    return qc_of_mach(np.asarray(cas_mps, dtype=float) / A0_MPS, P0_PA)


def isa(alt_m):
    """ambiance's ICAO 1993 atmosphere at geopotential `alt_m` (m)."""
    from ambiance import Atmosphere

    return Atmosphere(Atmosphere.geop2geom_height(np.asarray(alt_m, dtype=float)))


def pressure_altitude_m(ps_pa):
    """ambiance's geopotential altitude of a static pressure (its own inverse)."""
    from ambiance import Atmosphere

    return Atmosphere.from_pressure(np.asarray(ps_pa, dtype=float)).H
