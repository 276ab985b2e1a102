"""Static-source products of a compressible calibration (issue 9, item 3).

The "all error in the static source" reduction of USAF TPS / NTPS practice: the pitot's total
pressure is exact, so the fitted pressure error is the static-source error,

    Δp_p = p_s,ind − p_s = q_c − q_ci,     Δp_p / q_cic = f / (1 − f)   (q_cic = q_ci),

and at each instrument-corrected indicated airspeed V_ic (standard CAS of q_ci) follow

    M_ic  = M(q_ci, p_s,ind)          indicated Mach (`pitotcal.core.airdata.mach_from_qc`)
    ΔM_pc = M(q_c, p_s) − M_ic        Mach position-error correction
    ΔH_pc = H(p_s) − H(p_s,ind)       altimeter correction (`altimeter_correction_m`)

at the flight's median indicated pressure altitude (the median of the static source's
`ps_pa`). Their 2-sigma bands propagate the coefficients' covariance by the same central
differences as the ΔV band (`estimation.result`).
"""

import numpy as np

from pitotcal.core import airdata
from pitotcal.core.models import get_model, qc_from_qci_pa
from pitotcal.core.units import kt_to_mps, m_to_ft

from .propagation import band, gradient

__all__ = ["ASSUMED_STATIC", "plot_altimeter_correction", "plot_static_error",
           "pressure_altitude_ic_m", "static_source_products"]

ASSUMED_STATIC = ("all pressure error in the static source: total pressure exact, "
                  "dp_p = q_c - q_ci = p_s,ind - p_s")


def pressure_altitude_ic_m(result):
    """The flight's median indicated pressure altitude H_ic, m (None without `ps_pa`)."""
    if result.ps_pa is None:
        return None
    return float(airdata.pressure_altitude_m(np.median(result.ps_pa)))


def _products(model, k, vi_kt, ps_ind_pa):
    """(Δp_p/q_cic, M_ic, ΔM_pc, ΔH_pc in m) at V_ic = `vi_kt` for coefficients k."""
    qci = airdata.qc_from_cas_pa(kt_to_mps(np.asarray(vi_kt, dtype=float)))
    qc = qc_from_qci_pa(model, k, qci)
    dp = qc - qci
    mach_i = airdata.mach_from_qc(qci, ps_ind_pa)
    dmach = airdata.mach_from_qc(qc, ps_ind_pa - dp) - mach_i
    h_ic = airdata.pressure_altitude_m(ps_ind_pa)
    return dp / qci, mach_i, dmach, airdata.altimeter_correction_m(dp, h_ic)


def static_source_products(result, vi_kt, plain=False):
    """Static-source position errors at indicated airspeeds `vi_kt` (V_ic, kt).

    Parameters
    ----------
    result : IdentificationResult
        A compressible result (with `ps_pa`).
    vi_kt : array_like
        Instrument-corrected indicated airspeeds V_ic, kt.
    plain : bool
        2-sigma from the plain Hessian covariance instead of the colored-residual one.

    Returns
    -------
    dict of ndarray
        dpp_qcic, dpp_qcic_2sigma (Δp_p/q_cic), mach_i, dmach, dmach_2sigma, dh_ft,
        dh_2sigma_ft; and pressure_altitude_ic_ft, the altitude ΔH_pc is for.
    """
    model = get_model(result.model)
    k = result.coefficients
    ps_ind = float(np.median(result.ps_pa))
    ratio, mach_i, dmach, dh_m = _products(model, k, vi_kt, ps_ind)
    cov = result._coef_cov(plain)
    bands = [2.0 * band(gradient(lambda kk, j=j: _products(model, kk, vi_kt, ps_ind)[j], k),
                        cov) for j in (0, 2, 3)]
    return {"dpp_qcic": ratio, "dpp_qcic_2sigma": bands[0], "mach_i": mach_i,
            "dmach": dmach, "dmach_2sigma": bands[1], "dh_ft": m_to_ft(dh_m),
            "dh_2sigma_ft": m_to_ft(bands[2]),
            "pressure_altitude_ic_ft": float(m_to_ft(airdata.pressure_altitude_m(ps_ind)))}


def plot_static_error(ax, result, implied_ratio, vi_range_kt):
    """Δp_p/q_cic vs M_ic with its 2σ band, and each sample's ratio from the residuals.

    `implied_ratio` is the per-sample Δp/q_c (`estimation.report`); Δp_p/q_cic = g / (1 - g).
    `vi_range_kt` the (lowest, highest) V_ic flown.
    """
    qci = np.asarray(result.qci_pa, dtype=float)
    g = np.asarray(implied_ratio, dtype=float)
    mach = airdata.mach_from_qc(qci, np.asarray(result.ps_pa, dtype=float))
    pick = np.arange(0, qci.size, max(1, qci.size // 4000))
    with np.errstate(divide="ignore", invalid="ignore"):
        ax.plot(mach[pick], (g / (1.0 - g))[pick], ".", color="0.6", ms=2, alpha=0.3,
                rasterized=True, label="per sample (from residuals)")
    grid = static_source_products(result, np.linspace(*vi_range_kt, 100))
    ratio, band = grid["dpp_qcic"], grid["dpp_qcic_2sigma"]
    ax.fill_between(grid["mach_i"], ratio - band, ratio + band, color="tab:red", alpha=0.3,
                    label="2σ")
    ax.plot(grid["mach_i"], ratio, color="tab:red", lw=2, label="Δp_p / q_cic")
    finite = (g / (1.0 - g))[np.isfinite(g)]
    if finite.size:     # zoom on the curve, keep the cloud's bulk
        p5, p95 = np.percentile(finite, [5, 95])
        span = max(p95 - p5, 4 * float(np.max(band)), 1e-4)
        mid = 0.5 * (float(np.min(ratio)) + float(np.max(ratio)))
        ax.set_ylim(mid - span, mid + span)
    ax.set(xlabel="indicated Mach M_ic", ylabel="Δp_p / q_cic",
           title="Static-source error (all error assumed static)")
    ax.legend(fontsize=8, loc="best")


def plot_altimeter_correction(ax, result, vi_range_kt):
    """ΔH_pc vs V_ic with its 2σ band, at the flight's median pressure altitude."""
    vi = np.linspace(*vi_range_kt, 100)
    grid = static_source_products(result, vi)
    dh, band = grid["dh_ft"], grid["dh_2sigma_ft"]
    ax.fill_between(vi, dh - band, dh + band, color="tab:green", alpha=0.3, label="2σ")
    ax.plot(vi, dh, color="tab:green", lw=2, label="ΔH_pc = H_c − H_ic")
    ax.set(xlabel="indicated airspeed V_ic (kt)", ylabel="ΔH_pc (ft)",
           title=f"Altimeter correction at {grid['pressure_altitude_ic_ft']:.0f} ft "
                 "pressure altitude")
    ax.legend(fontsize=8, loc="best")
