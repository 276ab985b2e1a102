"""The outside air temperature of a log's density, from the best source it has.

In order (the first that applies; the result's ``oat_source`` names it):

1. `oat_k` given by the user (``--oat-c``): one measured temperature for the whole flight;
2. `oat_ground_k` given by the user (``--oat-ground-c``): the ground temperature at the
   take-off point carried up the standard lapse, T = T_ground − 6.5 K/km × (h − h_takeoff),
   with h the static pressure's ISA altitude (the GPS altitude when the log has no static
   pressure); AirspeedFit's default source;
3. an outside air temperature sensor the log has (ArduPilot ``TEMP``; PX4 logs none);
4. a pressure chip's own temperature (ArduPilot ``ARSP.Temp`` / ``BARO.Temp``, PX4
   ``differential_pressure.temperature`` ...), with a warning that says how far it is from
   ISA and what that does to ΔV and the airspeed ratio, and which argument fixes it;
5. ISA at the GPS altitude, when the log has no temperature at all.

A user's flag wins over a logged sensor: it is the user's statement about this flight (the
logged sensor's reading is then noted). A chip's temperature is kept as the default rather
than ISA: both are off by up to ~20 K (a board runs 0-20 K above the air; a day's air is
within ±20 K of ISA), the budget counts both with the same u(OAT), and a chip at least
follows the day's temperature; `--params` refuses to recommend a parameter from it.
"""

import numpy as np

from pitotcal.core.units import (ISA_LAPSE_KPM, incompressible_cas_mps, isa_altitude_m,
                                 isa_temperature_k, mps_to_kt)

from .timebase import clean

__all__ = ["GROUND_LAPSE_SOURCE", "oat_on_times", "takeoff_height_m"]

# the text that says a temperature came from a ground temperature and the standard lapse
GROUND_LAPSE_SOURCE = "standard lapse from the ground"


def oat_on_times(s, t, qci_pa, ps_pa, alt_m, oat_k=None, oat_ground_k=None):
    """(T, source) on the times `t`: the outside air temperature, K, and where it came from.

    Parameters
    ----------
    s : LogStreams
        The log's streams; every substitution is appended to ``s.conversions`` (warned).
    t, qci_pa, ps_pa, alt_m : ndarray, shape (N,)
        Sample times (s), impact pressure (Pa), static pressure (Pa) and GPS altitude (m).
    oat_k, oat_ground_k : float, optional
        A measured outside air temperature, K; a ground temperature at the take-off point, K.

    Returns
    -------
    (ndarray, str)
    """
    logged = _logged_oat(s, t)
    if oat_k is not None:
        _note_unused(s, logged, "`oat_k`")
        return np.full_like(t, float(oat_k)), f"oat_k={oat_k:g} K given by the user"
    if oat_ground_k is not None:
        _note_unused(s, logged, "`oat_ground_k`")
        h = _height_m(ps_pa, alt_m)
        h0 = takeoff_height_m(s)
        temp = float(oat_ground_k) - ISA_LAPSE_KPM * (h - h0)
        return temp, (f"oat_ground_k={oat_ground_k:g} K at the take-off point ({h0:.0f} m), "
                      f"{GROUND_LAPSE_SOURCE} ({1000 * ISA_LAPSE_KPM:g} K/km)")
    if logged is not None:
        return logged, f"{s.oat_source}: a logged outside air temperature"
    if s.temp_k is not None and s.temp_t.size >= 2:
        tt, tk = clean(np.asarray(s.temp_t, float), np.asarray(s.temp_k, float))
        temp = np.interp(t, tt, tk)
        s.conversions.append(_chip_warning(s.temp_source, temp, qci_pa, ps_pa, alt_m))
        return temp, f"{s.temp_source}: sensor temperature, not OAT"
    s.conversions.append("no temperature in the log: ISA temperature at the GPS altitude")
    return isa_temperature_k(alt_m), "ISA at GPS altitude (no temperature in the log)"


def takeoff_height_m(s):
    """The take-off point's height, m: the static pressure's ISA altitude (else the GPS
    altitude) on the ground before the autopilot first flies; without a flight state, or
    when the log starts in the air, the lowest height in the log."""
    if s.ps_pa is not None and s.static_t is not None and s.static_t.size:
        th, h = clean(np.asarray(s.static_t, float), isa_altitude_m(np.asarray(s.ps_pa, float)))
    elif s.gps_alt_m is not None and s.gps_t is not None:
        ok = np.asarray(s.gps_ok, bool) if s.gps_ok is not None else np.ones(s.gps_t.size, bool)
        th, h = clean(np.asarray(s.gps_t, float)[ok], np.asarray(s.gps_alt_m, float)[ok])
    else:
        return 0.0
    if h.size == 0:
        return 0.0
    if s.airborne_t is not None and np.any(s.airborne):
        first = float(np.asarray(s.airborne_t)[np.argmax(np.asarray(s.airborne, bool))])
        ground = th < first
        if ground.any():
            return float(np.median(h[ground]))
    return float(np.min(h))


def _height_m(ps_pa, alt_m):
    if ps_pa is not None and np.all(np.isfinite(ps_pa)):
        return isa_altitude_m(ps_pa)
    return np.asarray(alt_m, float)


def _logged_oat(s, t):
    """The logged outside air temperature sensor on the times `t`, K, or None."""
    if s.oat_k is None or s.oat_t is None or np.size(s.oat_t) < 2:
        return None
    tt, tk = clean(np.asarray(s.oat_t, float), np.asarray(s.oat_k, float))
    return np.interp(t, tt, tk) if tt.size >= 2 else None


def _note_unused(s, logged, argument):
    if logged is not None:
        s.conversions.append(f"the log's {s.oat_source} (mean {np.mean(logged) - 273.15:.1f} "
                             f"degC) not used: {argument} given")


def _chip_warning(source, temp_k, qci_pa, ps_pa, alt_m):
    """The warning for a chip's temperature: how far from ISA, and what it does to ΔV."""
    t_isa = isa_temperature_k(_height_m(ps_pa, alt_m))
    excess = float(np.median(temp_k - t_isa))
    ratio = excess / float(np.median(t_isa))            # the density's (and ratio's) error
    ias = incompressible_cas_mps(np.maximum(qci_pa, 0.0))
    ias_kt = float(mps_to_kt(np.median(ias)))
    dv_kt = 0.5 * ratio * ias_kt                         # TAS ~ sqrt(T): half the relative error
    return (f"no outside air temperature in the log: density uses {source}, a sensor "
            f"temperature, not OAT: it reads {np.median(temp_k) - 273.15:.1f} degC, "
            f"{excess:+.1f} K from ISA at the flight's altitude; if the air was at ISA, the "
            f"density is {abs(100 * ratio):.1f} % {'low' if ratio > 0 else 'high'}, which moves "
            f"dV by {abs(dv_kt):.2f} kt at the median {ias_kt:.0f} kt IAS and an airspeed ratio "
            f"by {abs(100 * ratio):.1f} %; give the outside air "
            "temperature (`oat_k`) or the ground temperature at take-off (`oat_ground_k`)")
