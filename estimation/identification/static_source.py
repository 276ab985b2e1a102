"""Static-source products of a compressible calibration.

The "all error in the static source" reduction of USAF TPS / NTPS practice: the pitot's total
pressure is exact, so the fitted pressure error is the static-source error,

    Δp_p = p_s,ind − p_s = q_c − q_ci,     Δp_p / q_cic = f / (1 − f)   (q_cic = q_ci),

and at each instrument-corrected indicated airspeed V_ic (standard CAS of q_ci) follow

    M_ic  = M(q_ci, p_s,ind)          indicated Mach (`pitotcal.core.airdata.mach_from_qc`)
    ΔM_pc = M(q_c, p_s) − M_ic        Mach position-error correction
    ΔH_pc = H(p_s) − H(p_s,ind)       altimeter correction (`altimeter_correction_m`)

at the flight's median indicated pressure altitude (the median of the static source's
`ps_pa`). Their 2-sigma bands propagate the coefficients' covariance by the same central
differences as the ΔV band (`estimation.propagation`).

With an independent reference static pressure (`ps_ref_pa`), nothing is assumed: the static
error is measured, Δp_p = p_s,ind − p_s,ref, and fitted by the same structure,
Δp_p / q_c = f(q_ci; k_s) (`static_error_fit`, least squares with the colored-residual
covariance); the total-pressure error is the rest, δp_T = p_T,ind − p_T = Δp_p − (q_c − q_ci).
ΔM_pc and ΔH_pc then use the measured static error, and the rows add δp_T / q_cic.

Each product exists only where its law does: Mach up to `airdata.MACH_MAX` (the Rayleigh
pitot law above Mach 1) and pressure altitudes in the ISA (−2,000 ft to 32 km). Elsewhere it is
NaN (null in the JSON) and `unavailable_warning` names it, so a
calibration far out (a short or rough record) is still returned with what can be computed.
"""

import numpy as np

from pitotcal.core import airdata
from pitotcal.core.models import get_model, qc_from_qci_pa
from pitotcal.core.propagation import band, gradient
from pitotcal.core.units import kt_to_mps, m_to_ft

__all__ = ["ASSUMED_STATIC", "MEASURED_STATIC", "air_data_lines", "calibrated_mach",
           "fitted_static_error",
           "plot_altimeter_correction",
           "plot_static_error", "pressure_altitude_ic_m", "static_error_fit",
           "static_source_products", "static_source_values", "static_statement",
           "static_table_lines", "unavailable_warning"]

ASSUMED_STATIC = ("all pressure error in the static source: total pressure exact, "
                  "dp_p = q_c - q_ci = p_s,ind - p_s")
MEASURED_STATIC = ("static-source error measured against the reference static pressure "
                   "ps_ref_pa (dp_p = ps_pa - ps_ref_pa, fitted as dp_p/q_c = f(q_ci; k_static)); "
                   "total-pressure error dp_T = dp_p - (q_c - q_ci); q_c predicted from ps_ref_pa")


def pressure_altitude_ic_m(result):
    """The flight's median indicated pressure altitude H_ic, m (None without `ps_pa`)."""
    if result.ps_pa is None:
        return None
    ps = float(np.median(result.ps_pa))
    return float(airdata.pressure_altitude_m(ps)) if _in_isa(ps) else None


def _in_isa(ps_pa):
    """Where `airdata.pressure_altitude_m` is defined (numpy bool, the shape of `ps_pa`)."""
    lo, hi = (float(airdata.static_pressure_pa(h)) for h in (airdata.PRESSURE_ALTITUDE_MAX_M,
                                                             airdata.PRESSURE_ALTITUDE_MIN_M))
    ps = np.asarray(ps_pa, dtype=float)
    return np.isfinite(ps) & (ps >= lo) & (ps <= hi)


def _in_mach_range(qc_pa, ps_pa):
    """Where `airdata.mach_from_qc` is defined: |q_c| / p_s up to Mach `airdata.MACH_MAX`."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(qc_pa) / ps_pa
    return np.isfinite(ratio) & (np.asarray(ps_pa) > 0) \
        & (ratio <= airdata.QC_OVER_PS_MAX)


def _on(ok, fun, *args):
    """fun(*args) where `ok`, NaN elsewhere (each arg broadcast to ok's shape)."""
    ok = np.asarray(ok, dtype=bool)
    out = np.full(ok.shape, np.nan)
    if ok.any():
        out[ok] = fun(*(np.broadcast_to(np.asarray(a, dtype=float), ok.shape)[ok]
                        for a in args))
    return out


def calibrated_mach(result, flight):
    """The true Mach of each sample of `flight` by the calibration `result`, ndarray (N,).

    q_c = q_ci / (1 − f(q_ci; k)) and p_s = p_s,ind − (q_c − q_ci) (all the error in the static
    source), or the reference static pressure when the result used one; the indicated Mach
    (q_ci / p_s,ind) where the calibration gives none.
    """
    qci = np.asarray(flight.qci_pa, dtype=float)
    ps_ind = np.asarray(flight.ps_pa, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        qc = qc_from_qci_pa(get_model(result.model), result.coefficients, qci)
    ps = (np.asarray(flight.ps_ref_pa, dtype=float)
          if result.ps_ref_pa is not None and flight.ps_ref_pa is not None
          else ps_ind - (qc - qci))
    mach = _on(_in_mach_range(qc, ps), airdata.mach_from_qc, qc, ps)
    indicated = _on(_in_mach_range(qci, ps_ind), airdata.mach_from_qc, qci, ps_ind)
    return np.where(np.isfinite(mach), mach, np.nan_to_num(indicated))


def static_error_fit(result):
    """(k_static, covariance) of the measured static error Δp_p = ps_pa − ps_ref_pa.

    Δp_p = q_c f(q_ci; k_static) with q_c = q_ci / (1 − f(q_ci; k)) from the calibration; every
    registered structure is linear in its coefficients, so one least-squares solve; the
    covariance is the colored-residual one (`estimation.uncertainty.covariance`).
    """
    from ..uncertainty.covariance import colored_covariance

    k_static, design, residuals = _static_least_squares(result)
    return k_static, colored_covariance(design, residuals).covariance


def _static_least_squares(result):
    """(k_static, design, residuals) of `static_error_fit`'s least squares."""
    from .residual import ratio_columns

    model = get_model(result.model)
    qci = np.asarray(result.qci_pa, dtype=float)
    qc = qc_from_qci_pa(model, result.coefficients, qci)
    dp = np.asarray(result.ps_pa, dtype=float) - np.asarray(result.ps_ref_pa, dtype=float)
    zero = np.zeros(len(model.params))
    design = np.column_stack(ratio_columns(model, zero, qci)) * qc[:, None]
    k_static = np.linalg.lstsq(design, dp - qc * model(zero, qci), rcond=None)[0]
    return k_static, design, dp - qc * model(k_static, qci)


def static_source_values(result, vi_kt):
    """{"dh_ft", "dmach"} of a compressible result at V_ic = `vi_kt`, without their bands (and
    so without the static-error fit's covariance): what a perturbed calibration needs."""
    model = get_model(result.model)
    kk = result.coefficients
    if result.ps_ref_pa is not None:
        fit = getattr(result, "static_fit", None)
        kk = np.concatenate([kk, _static_least_squares(result)[0] if fit is None else fit[0]])
    values = _products(model, kk, vi_kt, float(np.median(result.ps_pa)), len(model.params))
    return {"dh_ft": m_to_ft(values[3]), "dmach": values[2]}


def fitted_static_error(result):
    """The result's own static-error fit (`identify` fits it once: `result.static_fit`); fitted
    here only for a result made without `identify` (a budget re-solve, a live update)."""
    fit = getattr(result, "static_fit", None)
    return static_error_fit(result) if fit is None else fit


def _products(model, kk, vi_kt, ps_ind_pa, n_k):
    """(Δp_p/q_cic, M_ic, ΔM_pc, ΔH_pc m, δp_T/q_cic) at V_ic = `vi_kt`.

    kk holds the calibration's coefficients k, then (with a reference) k_static; without one
    the static error is the total one and δp_T is zero.
    """
    k, k_static = kk[:n_k], kk[n_k:]
    qci = airdata.qc_from_cas_pa(kt_to_mps(np.asarray(vi_kt, dtype=float)))
    with np.errstate(divide="ignore", invalid="ignore"):
        qc = qc_from_qci_pa(model, k, qci)
        dp = qc - qci if k_static.size == 0 else qc * model(k_static, qci)
    ps = ps_ind_pa - dp
    mach_i = _on(_in_mach_range(qci, ps_ind_pa), airdata.mach_from_qc, qci, ps_ind_pa)
    dmach = _on(_in_mach_range(qc, ps), airdata.mach_from_qc, qc, ps) - mach_i
    dh = _on(_in_isa(ps) & _in_isa(ps_ind_pa), lambda d: (
        airdata.altimeter_correction_m(d, airdata.pressure_altitude_m(ps_ind_pa))), dp)
    return dp / qci, mach_i, dmach, dh, (dp - (qc - qci)) / qci


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
        dh_2sigma_ft; with a reference static pressure also dpt_qcic, dpt_qcic_2sigma
        (δp_T/q_cic) and k_static, k_static_std; and pressure_altitude_ic_ft, the altitude
        ΔH_pc is for.
    """
    model = get_model(result.model)
    n_k = len(model.params)
    kk, cov = result.coefficients, result._coef_cov(plain)
    reference = result.ps_ref_pa is not None
    if reference:
        k_static, cov_static = fitted_static_error(result)
        kk = np.concatenate([kk, k_static])
        cov = np.block([[cov, np.zeros((n_k, n_k))], [np.zeros((n_k, n_k)), cov_static]])
    ps_ind = float(np.median(result.ps_pa))
    values = _products(model, kk, vi_kt, ps_ind, n_k)
    bands = [2.0 * band(gradient(lambda x, j=j: _products(model, x, vi_kt, ps_ind, n_k)[j],
                                 kk), cov) for j in (0, 2, 3, 4)]
    out = {"dpp_qcic": values[0], "dpp_qcic_2sigma": bands[0], "mach_i": values[1],
           "dmach": values[2], "dmach_2sigma": bands[1], "dh_ft": m_to_ft(values[3]),
           "dh_2sigma_ft": m_to_ft(bands[2]),
           "pressure_altitude_ic_ft": (float(m_to_ft(airdata.pressure_altitude_m(ps_ind)))
                                       if _in_isa(ps_ind) else None)}
    if reference:
        out.update(dpt_qcic=values[4], dpt_qcic_2sigma=bands[3], k_static=kk[n_k:],
                   k_static_std=np.sqrt(np.diag(cov[n_k:, n_k:])))
    return out


def plot_static_error(ax, result, implied_ratio, vi_range_kt):
    """Δp_p/q_cic vs M_ic with its 2σ band, and each sample's ratio from the residuals.

    `implied_ratio` is the per-sample Δp/q_c (`estimation.identification.view`); Δp_p/q_cic = g / (1 - g).
    `vi_range_kt` the (lowest, highest) V_ic flown.
    """
    qci = np.asarray(result.qci_pa, dtype=float)
    g = np.asarray(implied_ratio, dtype=float)
    mach = airdata.mach_from_qc(qci, np.asarray(result.ps_pa, dtype=float))
    pick = np.arange(0, qci.size, max(1, qci.size // 4000))
    with np.errstate(divide="ignore", invalid="ignore"):
        if result.ps_ref_pa is None:
            points, label = g / (1.0 - g), "per sample (from residuals)"
        else:
            points = (np.asarray(result.ps_pa) - np.asarray(result.ps_ref_pa)) / qci
            label = "per sample (ps_pa − ps_ref_pa)"
        ax.plot(mach[pick], points[pick], ".", color="0.6", ms=2, alpha=0.3,
                rasterized=True, label=label)
    grid = static_source_products(result, np.linspace(*vi_range_kt, 100))
    ratio, band = grid["dpp_qcic"], grid["dpp_qcic_2sigma"]
    ax.fill_between(grid["mach_i"], ratio - band, ratio + band, color="tab:red", alpha=0.3,
                    label="2σ")
    ax.plot(grid["mach_i"], ratio, color="tab:red", lw=2, label="Δp_p / q_cic")
    finite = points[np.isfinite(points)]
    if finite.size:     # zoom on the curve, keep the cloud's bulk
        p5, p95 = np.percentile(finite, [5, 95])
        span = max(p95 - p5, 4 * float(np.max(band)), 1e-4)
        mid = 0.5 * (float(np.min(ratio)) + float(np.max(ratio)))
        ax.set_ylim(mid - span, mid + span)
    kind = "all error assumed static" if result.ps_ref_pa is None else "measured: ps_ref_pa"
    ax.set(xlabel="indicated Mach M_ic", ylabel="Δp_p / q_cic",
           title=f"Static-source error ({kind})")
    ax.legend(fontsize=8, loc="best")


def plot_altimeter_correction(ax, result, vi_range_kt):
    """ΔH_pc vs V_ic with its 2σ band, at the flight's median pressure altitude."""
    vi = np.linspace(*vi_range_kt, 100)
    grid = static_source_products(result, vi)
    dh, band = grid["dh_ft"], grid["dh_2sigma_ft"]
    ax.fill_between(vi, dh - band, dh + band, color="tab:green", alpha=0.3, label="2σ")
    ax.plot(vi, dh, color="tab:green", lw=2, label="ΔH_pc = H_c − H_ic")
    h_ic = grid["pressure_altitude_ic_ft"]
    ax.set(xlabel="indicated airspeed V_i (kt)", ylabel="ΔH_pc (ft)",
           title="Altimeter correction " + ("not defined outside the ISA (-2,000 ft to 32 km)"
                                            if h_ic is None else
                                            f"at {h_ic:.0f} ft pressure altitude"))
    ax.legend(fontsize=8, loc="best")


# --- summary lines (estimation.identification.view) --------------------------------------------

def static_statement(result):
    """(what was assumed or measured, the static-error fit or None) of a compressible result."""
    if result.ps_ref_pa is None:
        return ASSUMED_STATIC, None
    k_static, cov = fitted_static_error(result)
    names = get_model(result.model).params
    return MEASURED_STATIC, {name: {"value": float(v), "std": float(np.sqrt(c))}
                             for name, v, c in zip(names, k_static, np.diag(cov))}


def air_data_lines(result):
    """The compressible summary's statement of what was computed and assumed."""
    return [
        ("Air data: compressible (isentropic q_c from V_t, Rayleigh pitot above Mach 1; the "
         "static port's p_s and T_s); "
         "KIAS = V_ic and KCAS = V_c by the standard CAS law, ΔV = ΔV_pc."),
        (f"{'Assumed' if result.ps_ref_pa is None else 'Measured'}: "
         f"{static_statement(result)[0]}."),
        "",
    ]


def static_table_lines(result, table):
    """Static-source position error per row: Δp_p/q_cic, M_ic, ΔM_pc, ΔH_pc with 2σ."""
    h_ic = pressure_altitude_ic_m(result)
    where = ("outside the ISA (-2,000 ft to 32 km): no altimeter correction" if h_ic is None
             else f"{m_to_ft(h_ic):.0f} ft")
    lines = [
        "",
        (f"Static-source position error (altimeter correction at the flight's median pressure "
         f"altitude {where}):"),
        (f"  {'KIAS':>7}{'M_ic':>8}{'Δp_p/q_cic':>12}{'±2σ':>9}{'ΔM_pc':>9}{'±2σ':>9}"
         f"{'ΔH_pc ft':>10}{'±2σ':>7}"),
    ]
    for row in table:
        cell = _cell(row)
        lines.append(f"  {row['vi_kt']:7.1f}{cell('mach_i', 8, '.4f')}"
                     f"{cell('dpp_qcic', 12, '+.4f')}{cell('dpp_qcic_2sigma', 9, '.4f')}"
                     f"{cell('dmach', 9, '+.4f')}{cell('dmach_2sigma', 9, '.5f')}"
                     f"{cell('dh_ft', 10, '+.1f')}{cell('dh_2sigma_ft', 7, '.1f')}"
                     + (f"   δp_T/q_cic {row['dpt_qcic']:+.4f} ±{row['dpt_qcic_2sigma']:.4f}"
                        if "dpt_qcic" in row else ""))
    return lines


def _cell(row):
    """cell(key, width, spec): the row's value formatted, "n/a" where the law gives none."""
    def cell(key, width, spec):
        value = row.get(key)
        text = "n/a" if value is None or not np.isfinite(value) else format(value, spec)
        return f"{text:>{width}}"
    return cell


def unavailable_warning(result, table):
    """The warning naming the static-source products the law does not give at some rows of
    `table` (`correction_table`'s rows of a compressible result), or None."""
    names = {"mach_i": "M_ic", "dmach": "dM_pc", "dh_ft": "dH_pc"}
    missing = {}
    for row in table:
        for key, name in names.items():
            value = row.get(key)
            if key in row and (value is None or not np.isfinite(value)):
                missing.setdefault(name, []).append(row["vi_kt"])
    if not missing:
        return None
    parts = [f"{name} at {len(vi)} of {len(table)} rows ({min(vi):.0f}-{max(vi):.0f} kt)"
             for name, vi in missing.items()]
    h_ic = pressure_altitude_ic_m(result)
    return (f"{result.source}: static-source products not computed: {'; '.join(parts)}: "
            "the calibration puts the static pressure there beyond Mach "
            f"{airdata.MACH_MAX:g} or outside the ISA (-2,000 ft to 32 km)" + (" (the flight's median static pressure is outside it)"
                                 if h_ic is None else "") + "; the airspeed correction stands")
