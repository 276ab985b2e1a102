"""What the airspeed monitor knows of a calibration: the model, the wind, the air data and the
statistics of its residuals, and the ONE prediction of q_ci from GPS velocity (paper section VI.B).

The prediction is the measurement model's (`core.measurement.predict_qci_pa`): V_t² from GPS
and the wind, the true impact pressure from it with the air data the calibration's
``"air_data"`` names (absent: incompressible), then what the pitot reads through the identified
pressure error.

The block residual statistics (`estimation.uncertainty.block_noise`) describe the calibration's
output residuals on the monitor's block grid (BLOCK_S): the relative residual
e = (q_ci − predicted)/predicted of each block, and the same in airspeed, ΔV_i = e V_i/2 (the
unit the monitor tests in: turbulence moves the airspeed by about the same m/s at every speed, so
its fraction of q_ci changes along a speed sweep, and icing lowers V_i by kt/min), are
autoregressive (turbulence is colored: correlation times of seconds), e_k = Σ φ_i e_{k−i} + w_k,
and the log of the in-block (detrended) variance of the measured q_ci, the signal's
high-frequency "liveness", is roughly normal.
`pitotcal identify --json` writes them as ``"noise_model"``.
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core.measurement import IncompressibleAir, StaticAir, flight_air
from pitotcal.core.measurement import predict_qci_pa as predict_measured_qci_pa
from pitotcal.core.models import get_model
from pitotcal.core.units import (
    R_AIR_JKGK,
    RHO0_KGM3,
    isa_pressure_pa,
    kt_to_mps,
    wind_vector_mps,
)

from ..uncertainty.block_noise import BLOCK_S, block_residual_stats

__all__ = ["Calibration", "air_inputs", "predict_qci_pa"]

# When the calibration carries no noise model (older result JSON): correlation of 0.5-s block
# means in the simulator's 0.5 m/s Dryden turbulence (measured, T-2 maneuver: 0.91).
_DEFAULT_AR1 = 0.9


@dataclass(frozen=True)
class Calibration:
    """A calibration as the monitor uses it (from a result JSON or an IdentificationResult);
    `notes` say what an older record lacked."""

    model: str
    k: tuple
    wind_n_mps: float
    wind_e_mps: float
    air_data: str
    noise: dict
    source: str = "<memory>"
    notes: tuple = ()

    @classmethod
    def from_dict(cls, d, source="<memory>"):
        """From the record of `pitotcal identify --json` (docs/interfaces.md §3), validated by
        `pitotcal.io.result_record.read_result` (a PitotcalError naming `source` and the key
        otherwise). A record without a noise model (one written before the record had it,
        or of a flight too short for it) gets one from its residual RMS, and a note saying so.
        """
        from pitotcal.io.result_record import (
            RECORD_KEYS, missing_record_keys, read_result, record_calibration)

        d = read_result(d, name=source, table=False)
        name, k, speed, from_deg, air = record_calibration(d, source)
        wn, we = wind_vector_mps(speed, from_deg)
        noise, notes = d.get("noise_model"), ()
        if noise is None:
            noise = _fallback_noise(d)
            # a record that has the other keys of its time lacks it for a short flight
            why = ("written before the record had one"
                   if set(missing_record_keys(d)) == set(RECORD_KEYS)
                   else "its flight was too short for one")
            notes = (f"{source}: no noise_model in the calibration ({why}); residual scale "
                     "from noise_std_pa, correlation assumed",)
        return cls(name, k, float(wn), float(we), air, dict(noise), source, notes)

    @classmethod
    def from_result(cls, result, air_data=None):
        """From an `IdentificationResult` in memory (its noise model as `identify` computed it;
        computed here for a result made without `identify`); the air data the result was
        fitted with unless `air_data` is given."""
        wn, we = result.internal_params[-2:]
        air_data = getattr(result, "air_data", "incompressible") if air_data is None else air_data
        noise = getattr(result, "monitor_noise", None) or block_residual_stats(result)
        return cls(result.model, tuple(map(float, result.coefficients)), float(wn), float(we),
                   air_data, noise)


def _fallback_noise(d):
    """A noise model from the residual RMS alone (a record without "noise_model")."""
    rows = d.get("airspeed_correction") or []
    vi = [r["vi_kt"] for r in rows if r.get("vi_kt")]
    q_pa = 0.5 * RHO0_KGM3 * float(kt_to_mps(np.mean(vi))) ** 2 if vi else 1000.0
    rel = float(d.get("noise_std_pa") or 0.02 * q_pa) / q_pa
    a = _DEFAULT_AR1
    return {"block_s": BLOCK_S, "rel_std": rel, "ar1": a,
            "innovation_rel_std": rel * float(np.sqrt(1 - a * a)),
            "band_log_mean": None, "band_log_std": None, "n_blocks": 0, "fallback": True}


def air_inputs(flight):
    """The air data of a compressible calibration's prediction for `flight`: the estimator's
    (`pitotcal.core.measurement.flight_air`: total pressure p_s,ind + q_ci and T_s) when it has
    its static pressure and temperature, else `StaticAir` at the ISA pressure of its altitude
    and T = p/(R ρ); None when neither is there."""
    if getattr(flight, "ps_pa", None) is not None and getattr(flight, "oat_k", None) is not None:
        return flight_air(flight, "compressible")
    if flight.alt_m is not None and np.all(np.isfinite(flight.alt_m)):
        ps = isa_pressure_pa(flight.alt_m)
        return StaticAir(ps, ps / (R_AIR_JKGK * flight.rho_kgm3))
    return None


def predict_qci_pa(cal, vn, ve, vd_sq, rho, air=None, wind_ne=None):
    """The q_ci a sound pitot-static system reads, Pa, by the calibration `cal`.

    Parameters
    ----------
    cal : Calibration
    vn, ve : array_like
        GPS ground velocity north / east, m/s.
    vd_sq : array_like or None
        GPS vertical velocity squared, m²/s² (None: not measured).
    rho : array_like
        Air density, kg/m³.
    air : air data of `pitotcal.core.measurement`, optional
        What `air_inputs` gives; needed by a compressible calibration (without it the
        incompressible relation is used).
    wind_ne : (float, float), optional
        Air-mass velocity north/east (the way it blows TO), m/s; default the calibration's.

    Notes
    -----
    `pitotcal.core.measurement.predict_qci_pa`: q_ci = q_c (1 − f(q_ci; k)), the fixed point.
    """
    wn, we = (cal.wind_n_mps, cal.wind_e_mps) if wind_ne is None else wind_ne
    if cal.air_data != "compressible" or air is None:
        air = IncompressibleAir(np.asarray(rho, float))
    return predict_measured_qci_pa(get_model(cal.model), cal.k, np.asarray(vn, float),
                                   np.asarray(ve, float), wn, we, air, vd_sq)
