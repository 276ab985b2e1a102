"""Temperature and humidity inputs of the air data: total to static temperature, moist air.

    T_s  = T_t / (1 + r 0.2 M²)                                 (static from total temperature)
    e_s  = 610.94 exp(17.625 t / (t + 243.04)) Pa, t in °C      (saturation over water)
    e    = (RH / 100) e_s(T_s)
    T_v  = T_s / (1 − (e / p_s)(1 − ε)),   ε = R_d / R_v = 0.622 (virtual temperature)
    ρ    = p_s / (R_d T_v),   a = sqrt(γ R_d T_v)

r is the probe's recovery factor (1 for an ideal total-temperature probe: it reads the
stagnation temperature; 0.95-1 for real probes, from the probe's data sheet). The saturation
law is the Magnus form of Alduchov and Eskridge (1996), "Improved Magnus form approximation of
saturation vapor pressure", J. Appl. Meteor. 35, 601-609, eq. 21: within 0.4 % of the
Wexler/Hyland-Wexler tables from −40 to +50 °C (the tests compare it with ASHRAE's formula
through psychrolib and with table values). Water vapour (ε = 0.622) makes air lighter at the
same pressure and temperature: humid air is 0.3-1.6 % less dense than dry at 15-30 °C, 100 %
RH. γ is taken as 1.4 for moist air too (the change is below 0.1 %).

`with_static_air` turns a `Flight` with these columns into the Flight the estimator needs:
`oat_k` the static temperature (virtual when humid: the compressible relations take it for
both the density and the speed of sound) and `rho_kgm3` = p_s / (R T_v), once, when
`pitotcal.io.read_flight` reads the flight. M is then the indicated Mach (q_ci / p_s,ind): the
calibration's is not known yet. `identify` makes T_s again at the calibrated (true) Mach
(`at_mach`) and fits again until T_s settles. A static `oat_k` that rises with airspeed as a
total temperature does (its ram rise 0.2 M² T) gets a warning (`ram_rise_note`).
"""

import dataclasses
import warnings

import numpy as np

from .airdata import QC_OVER_PS_MAX, mach_from_qc, pressure_altitude_m
from .checks import number
from .errors import FlightDataError, PitotcalError
from .units import R_AIR_JKGK, isa_temperature_k

__all__ = [
    "EPSILON",
    "at_mach",
    "check_air_options",
    "moist_density_kgm3",
    "ram_rise_note",
    "saturation_vapour_pressure_pa",
    "static_temperature_k",
    "total_temperature_ratio",
    "virtual_temperature_k",
    "with_static_air",
]

EPSILON = 0.622                       # R_d / R_v, molar mass of water over that of dry air
_C_TO_K = 273.15
# Flight.meta keys describing the conversion (written out, never read back)
_OAT_SOURCE = "oat_k_source"          # how oat_k was obtained
_OAT_VIRTUAL = "oat_k_is"             # present when oat_k is virtual
# Alduchov & Eskridge (1996) eq. 21, over water
_AE_A_PA, _AE_B, _AE_C_C = 610.94, 17.625, 243.04


def saturation_vapour_pressure_pa(t_k):
    """Saturation vapour pressure over water, Pa, at temperature `t_k` (K); Magnus-AE 1996.

    Example
    -------
    >>> round(float(saturation_vapour_pressure_pa(293.15)))        # table: 2339 Pa at 20 °C
    2333
    """
    t_c = np.asarray(t_k, dtype=float) - _C_TO_K
    return _AE_A_PA * np.exp(_AE_B * t_c / (t_c + _AE_C_C))


def virtual_temperature_k(t_k, ps_pa, rh_pct):
    """Virtual temperature T_v = T / (1 − (e/p)(1 − ε)), K: the dry-air temperature of equal density.

    Parameters
    ----------
    t_k : array_like
        Static air temperature, K.
    ps_pa : array_like
        Static pressure, Pa.
    rh_pct : array_like
        Relative humidity over water, percent (0-100).
    """
    e_pa = np.asarray(rh_pct, dtype=float) / 100.0 * saturation_vapour_pressure_pa(t_k)
    return np.asarray(t_k, dtype=float) / (1.0 - e_pa / np.asarray(ps_pa, dtype=float)
                                           * (1.0 - EPSILON))


def moist_density_kgm3(ps_pa, t_k, rh_pct=0.0):
    """Density of moist air, ρ = p_s / (R_d T_v), kg/m³."""
    return np.asarray(ps_pa, dtype=float) / (R_AIR_JKGK * virtual_temperature_k(t_k, ps_pa,
                                                                                rh_pct))


def static_temperature_k(tat_k, qci_pa, ps_pa, recovery=1.0):
    """Static air temperature T_s = T_t / (1 + r 0.2 M²), K, from a total-temperature probe.

    Parameters
    ----------
    tat_k : array_like
        Total (probe) air temperature, K.
    qci_pa, ps_pa : array_like
        Impact and static pressure, Pa: the Mach number is M = sqrt(5[(q_c/p_s + 1)^(2/7) − 1]).
    recovery : float
        The probe's recovery factor r, 0-1 (1: an ideal stagnation probe).
    """
    return np.asarray(tat_k, dtype=float) / total_temperature_ratio(mach_from_qc(qci_pa, ps_pa),
                                                                     recovery)


def total_temperature_ratio(mach, recovery=1.0):
    """T_t / T_s = 1 + r (γ − 1)/2 M² of a temperature probe with recovery factor r."""
    return 1.0 + recovery * 0.2 * np.asarray(mach, dtype=float) ** 2


def at_mach(flight, mach):
    """`flight` with `oat_k` and `rho_kgm3` made again from its `tat_k` at the Mach numbers
    `mach` (ndarray (N,), the calibration's true Mach of each sample); None when its `oat_k`
    was not made from `tat_k` by `with_static_air`.

    The humidity `with_static_air` applied is applied again (virtual temperature).
    """
    source = flight.meta.get(_OAT_SOURCE, "")
    if flight.tat_k is None or flight.ps_pa is None or not source.startswith("tat_k"):
        return None
    reading = flight.reading or {}
    recovery = reading.get("temp_recovery")
    if recovery is None:                    # made in memory: the factor the source names
        recovery = float(source.rsplit(" ", 1)[-1])
    t_air = np.asarray(flight.tat_k, float) / total_temperature_ratio(mach, recovery)
    if flight.meta.get(_OAT_VIRTUAL) and flight.rh_pct is not None:
        t_air = virtual_temperature_k(t_air, flight.ps_pa, flight.rh_pct)
    return dataclasses.replace(flight, oat_k=t_air, rho_kgm3=flight.ps_pa / (R_AIR_JKGK * t_air))


# A static oat_k is suspected to be total when it follows at least this fraction of the ram
# rise 0.2 M² T over a flight whose ram rise spans at least _RAM_SPAN_K.
_RAM_FRACTION = 0.5
_RAM_SPAN_K = 2.0


def ram_rise_note(flight):
    """The warning of a static `oat_k` column that rises with airspeed as a total temperature
    does, or None.

    Regresses oat_k, less the ISA lapse over the flight's pressure altitudes, on the ram rise
    0.2 M_i² T (M_i from q_ci / p_s): a static temperature has no ram-rise term, a total one
    a slope near the probe's recovery factor (about 1). Needs `ps_pa` and a ram rise that spans _RAM_SPAN_K
    over the flight, so at low speed it says nothing.
    """
    if flight.oat_k is None or flight.ps_pa is None or flight.n < 10:
        return None
    t = np.asarray(flight.oat_k, float)
    ps = np.asarray(flight.ps_pa, float)
    ratio = np.clip(np.asarray(flight.qci_pa, float) / ps, 0.0, QC_OVER_PS_MAX)
    ok = np.isfinite(t) & np.isfinite(ratio) & (ps > 0)
    if ok.sum() < 10:
        return None
    rise = 0.2 * mach_from_qc(ratio[ok] * ps[ok], ps[ok]) ** 2 * t[ok]
    if np.ptp(np.percentile(rise, [2, 98])) < _RAM_SPAN_K:
        return None
    # the standard lapse rate taken out, not fitted: the static port's position error moves
    # the indicated altitude with the speed, so a fitted altitude term would take the ram rise
    alt = pressure_altitude_m(np.clip(ps[ok], 870.0, 1.08e5))
    level = t[ok] - (isa_temperature_k(alt) - isa_temperature_k(np.median(alt)))
    design = np.column_stack([np.ones(rise.size), rise])
    slope = float(np.linalg.lstsq(design, level, rcond=None)[0][1])
    if slope < _RAM_FRACTION:
        return None
    return (f"{flight.source}: column oat_k rises with airspeed as a total temperature does "
            f"(it follows {slope:.2f} of the ram rise 0.2 M² T, which reaches "
            f"{np.percentile(rise, 98):.1f} K at the top speeds; a static temperature does "
            "not rise): if it is the probe's total temperature, give it as column tat_k "
            "(with its recovery factor, `temp_recovery`), or the static temperature is too "
            "warm by that much")


def check_air_options(temp_recovery=1.0, rh_pct=None):
    """(temp_recovery, rh_pct) checked: the recovery factor in [0, 1], the humidity in
    [0, 100] % or None; a PitotcalError naming `temp_recovery` or `rh_percent`."""
    temp_recovery = number("temp_recovery", temp_recovery, 0.0, 1.0)
    if rh_pct is not None:
        rh_pct = number("rh_percent", rh_pct, 0.0, 100.0)
    return temp_recovery, rh_pct


def with_static_air(flight, *, temp_recovery=1.0, rh_pct=None):
    """The Flight the estimator needs: static `oat_k` and a density through the virtual temperature.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
        With `ps_pa`, and `oat_k` (static) or `tat_k` (total); `rh_pct` optional.
    temp_recovery : float
        Recovery factor of the total-temperature probe (`--temp-recovery`), used when the
        flight has `tat_k` and no `oat_k`.
    rh_pct : float, optional
        Relative humidity, percent (`--rh-percent`); overrides the flight's `rh_pct` column.

    Returns
    -------
    Flight
        `flight` itself when it has neither `tat_k` nor humidity (a copy with a warning when
        its static `oat_k` looks total, `ram_rise_note`); else a copy with `oat_k`
        the static temperature — the virtual temperature T_v when a humidity is known
        (`meta["oat_k_is"]` says so), as the compressible relations and the density both
        need it — `rho_kgm3` = p_s / (R T_v), and the humidity used in `rh_pct`. An `oat_k`
        converted from `tat_k` is described in `meta["oat_k_source"]`. The conversion is made
        once, from the raw columns, when the flight is read (`pitotcal.io.read_flight` with
        the temperature source, recovery factor and humidity as options).

    Raises
    ------
    PitotcalError
        `temp_recovery` outside [0, 1], `rh_pct` outside [0, 100]; a flight whose air data
        `read_flight` has made already (its `reading` has `temp_recovery`): read it again.
    FlightDataError
        `rh_pct` given for a flight without the static pressure. (Columns `tat_k` or `rh_pct`
        without `ps_pa` are ignored with a warning, also in `Flight.warnings`: the density is
        then the file's `rho_kgm3`.)
    """
    temp_recovery, rh_pct = check_air_options(temp_recovery, rh_pct)
    # a log reader's own record (its chosen windows) is no air data made yet
    if flight.reading is not None and "temp_recovery" in flight.reading:
        raise PitotcalError(f"{flight.source}: its air data was made when it was read "
                            f"(temp_recovery {flight.reading.get('temp_recovery')}, rh_pct "
                            f"{flight.reading.get('rh_pct')}); read it again with "
                            "read_flight(..., temp_recovery=, rh_pct=) for other values",
                            param="flight")
    tat, oat = flight.tat_k, flight.oat_k
    rh = flight.rh_pct if rh_pct is None else np.full(flight.n, rh_pct)
    note = ram_rise_note(flight) if oat is not None else None
    if note:
        warnings.warn(note, stacklevel=2)
        flight = dataclasses.replace(flight, warnings=(*flight.warnings, note))
    if tat is None and rh is None:
        return flight
    ps = flight.ps_pa
    if ps is None:
        what = "tat_k" if tat is not None and oat is None else "the humidity"
        message = (f"{flight.source}: {what} needs the static pressure (column ps_pa) to "
                   "convert it")
        if rh_pct is not None:            # asked for explicitly: cannot be honoured
            raise FlightDataError(message, param="rh_percent")
        message += "; ignored, the density is the file's rho_kgm3"
        warnings.warn(message, stacklevel=2)
        return dataclasses.replace(flight, warnings=(*flight.warnings, message))
    meta = {k: v for k, v in flight.meta.items() if k != _OAT_VIRTUAL}
    if oat is None:
        oat = static_temperature_k(tat, flight.qci_pa, ps, temp_recovery)
        meta[_OAT_SOURCE] = f"tat_k, recovery factor {temp_recovery:g}"
    if rh is not None and np.any((rh < 0) | (rh > 100)):
        bad = int(np.argmax((rh < 0) | (rh > 100)))
        raise FlightDataError(f"{flight.source}: column rh_pct, row {bad + 1}: {rh[bad]:g} is "
                              "outside 0-100 %")
    t_air = np.asarray(oat, dtype=float)
    if flight.meta.get(_OAT_VIRTUAL) and oat is flight.oat_k:
        # a file pitotcal wrote after converting: its oat_k is the virtual temperature already
        if rh_pct is not None:
            raise PitotcalError(f"{flight.source}: its oat_k is the virtual temperature of its "
                                "rh_pct already (# oat_k_is): a humidity cannot be applied "
                                "again; read the original file", param="rh_pct")
        meta[_OAT_VIRTUAL] = flight.meta[_OAT_VIRTUAL]
        rh = None
    if rh is not None:
        # the air-data relations take the virtual temperature: the dry-air temperature of
        # the same density (ρ = p/(R T_v)) and, within 0.1 %, speed of sound (a² = γ R T_v)
        t_air = virtual_temperature_k(t_air, ps, rh)
        meta[_OAT_VIRTUAL] = "virtual temperature (rh_pct applied)"
    return dataclasses.replace(flight, oat_k=t_air, rho_kgm3=ps / (R_AIR_JKGK * t_air),
                               rh_pct=flight.rh_pct if rh is None else rh, meta=meta)
