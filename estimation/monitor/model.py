"""What the airspeed monitor knows of a calibration: the model, the wind, the air data and the
residual noise model, and the ONE prediction of q_ci from GPS velocity (paper section VI.B).

The prediction inverts the calibration: V_t² from GPS and the wind (`core.measurement`), the
true impact pressure from it — ½ρV_t² (`core.measurement`, incompressible) or isentropic from
V_t², p_s and T_s (`core.airdata`, compressible) as the calibration's ``"air_data"`` says (absent:
incompressible) — then what the pitot reads through the identified pressure error.

The noise model (`noise_model`) describes the calibration's output residuals on the monitor's
block grid (BLOCK_S): the relative residual e = (q_ci − predicted)/predicted of each block, and
the same in airspeed, ΔV_i = e V_i/2 (the unit the monitor tests in: turbulence moves the
airspeed by about the same m/s at every speed, so its fraction of q_ci changes along a speed
sweep, and icing lowers V_i by kt/min), are autoregressive (turbulence is colored: correlation
times of seconds), e_k = Σ φ_i e_{k−i} + w_k, and the log of the in-block (detrended) variance
of the measured q_ci, the signal's high-frequency "liveness", is roughly normal. `pitotcal identify --json` writes it as ``"noise_model"``.
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model, qci_from_qc_pa
from pitotcal.core.units import (
    R_AIR_JKGK,
    RHO0_KGM3,
    incompressible_cas_mps,
    isa_pressure_pa,
    kt_to_mps,
    wind_vector_mps,
)

__all__ = [
    "BLOCK_S",
    "Blocks",
    "Calibration",
    "airspeed_residual_mps",
    "block_stats",
    "noise_model",
    "predict_qci_pa",
]

BLOCK_S = 0.5          # the monitor's block: long enough to average GPS noise, short for speed
_MIN_PER_BLOCK = 4     # samples a block needs (the detrended variance has n - 2 dof)
# When the calibration carries no noise model (older result JSON): correlation of 0.5-s block
# means in the simulator's 0.5 m/s Dryden turbulence (measured, T-2 maneuver: 0.91).
_DEFAULT_AR1 = 0.9
# Order of the residual's autoregressive model. Block means of turbulence are smoother at short
# lags and decorrelate faster at long ones than one AR(1) coefficient (fitted at lag one) says:
# AR(2) follows both, and the ramp test's information grows by ~20 % (docs/measured.md).
AR_ORDER = 2


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
    def from_result(cls, result, air_data="incompressible"):
        """From an `IdentificationResult` in memory (its noise model as `identify` computed it;
        computed here for a result made without `identify`)."""
        wn, we = result.internal_params[-2:]
        noise = getattr(result, "monitor_noise", None) or noise_model(result)
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
    """(p_s, T_s) arrays for the compressible relation: the flight's own static pressure and
    temperature when it has them, else ISA pressure at its altitude and T = p/(R ρ); None when
    neither is there."""
    ps, oat = getattr(flight, "ps_pa", None), getattr(flight, "oat_k", None)
    if ps is not None and oat is not None:
        return np.asarray(ps, float), np.asarray(oat, float)
    if flight.alt_m is not None and np.all(np.isfinite(flight.alt_m)):
        ps = isa_pressure_pa(flight.alt_m)
        return ps, ps / (R_AIR_JKGK * flight.rho_kgm3)
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
    air : (ps_pa, oat_k) or None
        Static pressure and temperature (`air_inputs`); needed by a compressible calibration
        (without it the incompressible relation is used).
    wind_ne : (float, float), optional
        Air-mass velocity north/east (the way it blows TO), m/s; default the calibration's.

    Notes
    -----
    q_ci = q_c (1 − f(q_ci; k)), q_c = ½ρV_t² or p_s[(1 + 0.2 V_t²/(γRT_s))^3.5 − 1].
    """
    from pitotcal.core.measurement import impact_pressure_pa, tas_squared

    wn, we = (cal.wind_n_mps, cal.wind_e_mps) if wind_ne is None else wind_ne
    v2 = tas_squared(np.asarray(vn, float), np.asarray(ve, float), wn, we, vd_sq)
    if cal.air_data == "compressible" and air is not None:
        from pitotcal.core.airdata import qc_from_tas_sq_pa
        qc = qc_from_tas_sq_pa(v2, air[0], air[1])
    else:
        qc = impact_pressure_pa(np.asarray(rho, float), v2)
    return qci_from_qc_pa(get_model(cal.model), cal.k, qc)


@dataclass(frozen=True)
class Blocks:
    """A record cut into BLOCK_S blocks: `start`/`stop` sample indices, `time_s` (block end,
    when its decision is known), `qci_pa` (block mean) and `band_rel_var` (variance of q_ci
    about its in-block linear trend, over the block mean squared)."""

    start: np.ndarray
    stop: np.ndarray
    time_s: np.ndarray
    qci_pa: np.ndarray
    band_rel_var: np.ndarray


def block_stats(time_s, qci_pa, block_s=BLOCK_S, t0=None):
    """Cut a record into blocks of `block_s` from `t0` (default its first time) on; blocks with
    fewer than 4 samples are left out."""
    t = np.asarray(time_s, float)
    q = np.asarray(qci_pa, float)
    idx = np.floor((t - (t[0] if t0 is None else t0)) / block_s + 1e-9).astype(np.int64)
    cuts = np.flatnonzero(np.diff(idx)) + 1
    starts = np.concatenate([[0], cuts])
    stops = np.concatenate([cuts, [t.size]])
    keep = (stops - starts) >= _MIN_PER_BLOCK
    starts, stops = starts[keep], stops[keep]
    means, band = np.empty(starts.size), np.empty(starts.size)
    for j, (a, b) in enumerate(zip(starts, stops)):
        tt, qq = t[a:b] - t[a], q[a:b]
        coef = np.polyfit(tt, qq, 1)
        resid = qq - np.polyval(coef, tt)
        means[j] = qq.mean()
        band[j] = resid @ resid / max(b - a - 2, 1) / max(means[j] ** 2, 1e-9)
    return Blocks(starts, stops, t[stops - 1], means, band)


def noise_model(result, block_s=BLOCK_S):
    """The calibration's residual noise model on the monitor's block grid.

    Returns
    -------
    dict
        block_s; rel_std (std of the blocks' relative residual e); ar1 (a, lag-one
        correlation of e); ar (φ_1..φ_p, least-squares AR(AR_ORDER) coefficients of e);
        innovation_rel_std (robust std of w = e_k − Σ φ_i e_{k−i}); std_mps, ar_mps and
        innovation_std_mps (the same of the residual in airspeed, ΔV_i = e V_i / 2, m/s: the
        unit the monitor tests in); band_log_mean and band_log_std (median and robust std of
        log of the blocks' relative band variance); n_blocks.
    """
    qci = np.asarray(result.qci_pa, float)
    pred = qci - np.asarray(result.residuals_pa, float)
    blocks = block_stats(result.time_s, qci, block_s)
    pred_b = np.array([pred[a:b].mean() for a, b in zip(blocks.start, blocks.stop)])
    e = (blocks.qci_pa - pred_b) / pred_b
    if e.size < 10:
        raise PitotcalError(f"a noise model needs >= 10 blocks of {block_s:g} s, got {e.size}")
    e = e - e.mean()
    a, phi, w = _ar_model(e)
    dv = airspeed_residual_mps(e, pred_b)      # the same in airspeed: the monitor's unit
    _, phi_v, w_v = _ar_model(dv - dv.mean())
    log_band = np.log(blocks.band_rel_var)
    return {"block_s": block_s, "rel_std": float(np.std(e)), "ar1": a, "ar": list(phi),
            "innovation_rel_std": _robust_std(w),
            "std_mps": float(np.std(dv)), "ar_mps": list(phi_v),
            "innovation_std_mps": _robust_std(w_v),
            "band_log_mean": float(np.median(log_band)), "band_log_std": _robust_std(log_band),
            "n_blocks": int(e.size)}


def airspeed_residual_mps(e, pred_pa):
    """The relative residual `e` of q_ci as airspeed, ΔV_i = e V_i / 2 (q_ci ∝ V_i², V_i of the
    predicted q_ci `pred_pa`), m/s: the unit the monitor tests in."""
    return e * 0.5 * incompressible_cas_mps(pred_pa)


def _ar_model(e):
    """(lag-one correlation, AR(AR_ORDER) coefficients, innovations) of `e`; AR(1) at the
    lag-one correlation when the AR(AR_ORDER) fit is not stationary."""
    a = float(np.clip(np.corrcoef(e[:-1], e[1:])[0, 1], 0.0, 0.98))
    phi, w = _ar_fit(e, AR_ORDER)
    if phi is None:
        phi, w = [a], e[1:] - a * e[:-1]
    return a, phi, w


def _ar_fit(e, p):
    """Least-squares AR(p) coefficients of `e` and its innovations; (None, None) when the fit is
    not stationary (a root of 1 − Σ φ_i z^i inside the unit circle)."""
    x = np.column_stack([e[p - i:e.size - i] for i in range(1, p + 1)])
    phi, *_ = np.linalg.lstsq(x, e[p:], rcond=None)
    roots = np.roots(np.concatenate([-phi[::-1], [1.0]]))
    if np.any(np.abs(roots) <= 1.0 / 0.995):
        return None, None
    return [float(v) for v in phi], e[p:] - x @ phi


def _robust_std(x):
    """1.4826 × median absolute deviation: the std of normal data, unmoved by outliers."""
    x = np.asarray(x, float)
    return float(1.4826 * np.median(np.abs(x - np.median(x))))
