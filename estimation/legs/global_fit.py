"""One global fit over every leg: the pressure-error model and the winds (the paper's argument,
on leg data).

Each leg i flies at the true airspeed the model predicts from its own q_ci, pressure altitude and
OAT (compressible, `pitotcal.core.airdata`; the position error taken as static-source error as
in `estimation.legs.points`):

    q_c,i = q_ci,i / (1 − f(q_ci,i; k)),  p_s,i = p_s,ind,i − (q_c,i − q_ci,i),
    V_i(k) = a(T_i) M(q_c,i, p_s,i)

and its ground velocity lies on the circle of that radius about its wind w_b (one wind per
altitude band, or per point). The leg's heading is a nuisance that drops out: the residual is
radial, r_i = (|g_i − w_b| − V_i(k)) / σ_i, minimised by `scipy.optimize.least_squares`
(trust-region reflective, Jacobian by finite differences).

σ_i is each leg's stated `groundspeed_sd_kt` when every leg has it (the covariance is then
(JᵀJ)⁻¹ and the half-widths 2σ); otherwise one σ for all legs from the residuals,
s² = Σ r² / (m − p), covariance s² (JᵀJ)⁻¹ and the half-widths Student t₀.₉₇₅(m − p) σ.
The data must determine every unknown: a rank-deficient Jacobian (too few points or legs for the
winds asked) is refused with an `ObservabilityError` naming the counts.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from pitotcal.core import airdata
from pitotcal.core.errors import ObservabilityError, PitotcalError
from pitotcal.core.measurement import TotalPressureAir
from pitotcal.core.models import delta_v_kt, get_model, qc_from_qci_pa
from pitotcal.core.propagation import band, gradient
from pitotcal.core.units import KT_TO_MPS, m_to_ft, wind_polar

__all__ = ["WIND_MODES", "LegFit", "fit_legs", "wind_groups"]

WIND_MODES = ("per-band", "per-point")
BAND_FT = 1000.0          # width of an altitude band for `per-band` winds


def wind_groups(legs, mode, band_ft=BAND_FT):
    """(group index of each leg, group labels): per point, or per pressure-altitude band (each
    point by its legs' mean altitude; a band spans `band_ft` up from its lowest point, the next
    begins at the first point above), labelled by the band's mean altitude."""
    points = legs.points()
    alt_ft = m_to_ft(np.array([np.mean(legs.pressure_alt_m[legs.indices(p)]) for p in points]))
    if mode == "per-point":
        keys = list(range(len(points)))
    else:
        # bands grow upward from the lowest point: a point more than `band_ft` above its band's
        # lowest starts the next one (points 25 ft apart never straddle a fixed boundary)
        keys, start = [0] * len(points), None
        for rank, i in enumerate(np.argsort(alt_ft, kind="stable")):
            if start is None or alt_ft[i] - start > band_ft + 1e-9:
                start = alt_ft[i]
                band = rank
            keys[i] = band
    order = list(dict.fromkeys(keys))
    group = np.empty(legs.n, dtype=int)
    for p, key in zip(points, keys):
        group[legs.indices(p)] = order.index(key)
    if mode == "per-point":
        return group, [f"point {p}" for p in points]
    labels = [f"{np.mean([a for a, k in zip(alt_ft, keys) if k == key]):.0f} ft"
              for key in order]
    return group, labels


def predicted_tas_mps(model, k, qci_pa, ps_ind_pa, oat_k):
    """True airspeed a leg flies at by the model (module docstring): the measurement model
    inverted, V_t² of q_c = q_ci / (1 − f(q_ci; k)) at the total pressure p_s,ind + q_ci
    (`pitotcal.core.measurement.TotalPressureAir`)."""
    qci_pa = np.asarray(qci_pa, dtype=float)
    air = TotalPressureAir(np.asarray(ps_ind_pa, dtype=float) + qci_pa,
                           np.asarray(oat_k, dtype=float))
    tas_sq = air.tas_sq(qc_from_qci_pa(model, k, qci_pa))
    return np.sign(tas_sq) * np.sqrt(np.abs(tas_sq))      # signed, as the Mach of a negative q_c


@dataclass(frozen=True)
class LegFit:
    """The global fit (SI inside). `to_dict()` gives the identify result's JSON form."""

    model: str
    wind_mode: str
    coefficients: np.ndarray
    coef_cov: np.ndarray
    group_labels: tuple
    winds_ne_mps: np.ndarray
    winds_cov: np.ndarray
    half_width_factor: float
    noise_std_mps: float
    noise_source: str
    dof: int
    n_samples: int
    success: bool
    message: str
    iterations: int
    vi_range_kt: tuple
    residuals_mps: np.ndarray
    warnings: tuple = field(default_factory=tuple)

    @property
    def converged(self):
        return self.success

    def delta_v_kt(self, vi_kt):
        """ΔV (kt) at `vi_kt` and its half-width (`half_width_factor` × σ, delta method)."""
        model = get_model(self.model)
        k = self.coefficients
        # ΔV_pc by the standard (compressible) CAS law, `core.models.delta_v_kt`
        dv = delta_v_kt(model, k, vi_kt, "compressible")
        g = gradient(lambda kk: delta_v_kt(model, kk, vi_kt, "compressible"), k)
        return dv, self.half_width_factor * band(g, self.coef_cov)

    def correction_table(self, step_kt=None):
        """Rows {vi_kt, dv_kt, dv_2sigma_kt, vc_kt} from the lowest to the highest V_ic flown."""
        from ..identification.view import default_step_kt

        lo, hi = self.vi_range_kt
        step = step_kt or default_step_kt(hi - lo)
        lo_r, hi_r = math.ceil(lo * 10) / 10, math.floor(hi * 10) / 10
        inner = np.arange(math.floor(lo_r / step) + 1, math.ceil(hi_r / step)) * step
        grid = np.unique(np.r_[lo_r, inner[(inner > lo_r) & (inner < hi_r)], max(hi_r, lo_r)])
        dv, half = self.delta_v_kt(grid)
        return [{"vi_kt": float(v), "dv_kt": float(d), "dv_2sigma_kt": float(b),
                 "vc_kt": float(v + d)} for v, d, b in zip(grid, dv, half)]

    def to_dict(self):
        """model, formula, air_data, wind_mode, parameters {name: {value, std, unit}},
        covariance {names, matrix}, winds [{group, wind_speed_kt, wind_from_deg,
        wind_2sigma_kt}], n_samples (legs), dof, noise_std_kt, noise_source,
        half_width_factor, converged, message, iterations, warnings, airspeed_correction."""
        from pitotcal.io.jsonfile import json_ready

        model = get_model(self.model)
        std = np.sqrt(np.diag(self.coef_cov))
        winds = []
        for j, label in enumerate(self.group_labels):
            speed, frm = wind_polar(*self.winds_ne_mps[j])
            c = self.winds_cov[2 * j:2 * j + 2, 2 * j:2 * j + 2]
            winds.append({"group": label, "wind_speed_kt": float(speed) / KT_TO_MPS,
                          "wind_from_deg": float(frm),
                          "wind_2sigma_kt": self.half_width_factor
                          * math.sqrt(max(np.trace(c) / 2.0, 0.0)) / KT_TO_MPS})
        out = {
            "model": self.model, "formula": model.formula, "air_data": "compressible",
            "wind_mode": self.wind_mode,
            "parameters": {n: {"value": self.coefficients[i], "std": std[i], "unit": u}
                           for i, (n, u) in enumerate(zip(model.params, model.units))},
            "covariance": {"names": list(model.params), "matrix": self.coef_cov},
            "winds": winds, "n_samples": self.n_samples, "dof": self.dof,
            "noise_std_kt": self.noise_std_mps / KT_TO_MPS, "noise_source": self.noise_source,
            "half_width_factor": self.half_width_factor,
            "converged": bool(self.success), "message": self.message,
            "iterations": self.iterations, "warnings": list(self.warnings),
            "airspeed_correction": self.correction_table()}
        return json_ready(out)


def fit_legs(legs, model="inverse", wind="per-band", initial_winds=None):
    """Fit the pressure-error model and the winds to every leg (module docstring).

    Parameters
    ----------
    legs : pitotcal.io.legs_csv.LegData
    model : str
        A structure of `pitotcal.core.models.MODELS`.
    wind : {"per-band", "per-point"}
    initial_winds : dict, optional
        Point label -> (w_N, w_E) m/s to start from (e.g. the classic solutions).

    Returns
    -------
    LegFit

    Raises
    ------
    PitotcalError
        Unknown model or wind mode.
    ObservabilityError
        More unknowns than the legs determine (rank-deficient Jacobian).
    """
    from scipy.optimize import least_squares

    if wind not in WIND_MODES:
        raise PitotcalError(f"wind {wind!r} is not one of {', '.join(WIND_MODES)}", param="wind")
    try:
        pe = get_model(model)
    except ValueError as exc:
        raise PitotcalError(str(exc), param="model") from None
    group, labels = wind_groups(legs, wind)
    nk, ng = len(pe.params), len(labels)
    scales = np.asarray(pe.scales, dtype=float)
    g = legs.velocity_ne_mps()
    ps_ind = airdata.static_pressure_pa(legs.pressure_alt_m)
    # a zero accuracy would weigh a leg infinitely: no statement, like a missing one
    stated = bool(np.all(np.isfinite(legs.groundspeed_sd_mps) & (legs.groundspeed_sd_mps > 0)))
    sigma = legs.groundspeed_sd_mps if stated else np.ones(legs.n)
    _check_counts(legs, nk, ng, wind, stated)

    def residuals(z):
        k = z[:nk] * scales
        w = z[nk:].reshape(ng, 2)[group]
        oat = legs.static_oat_k(qc_from_qci_pa(pe, k, legs.qci_pa))  # a tat_k's true Mach
        v = predicted_tas_mps(pe, k, legs.qci_pa, ps_ind, oat)
        return (np.hypot(*(g - w).T) - v) / sigma

    z0 = np.zeros(nk + 2 * ng)
    for j in range(ng):
        start = [initial_winds[p] for p in legs.points() if initial_winds
                 and p in initial_winds and group[legs.indices(p)[0]] == j]
        if start:
            z0[nk + 2 * j:nk + 2 * j + 2] = np.mean(start, axis=0)
    sol = least_squares(residuals, z0, method="trf", x_scale="jac", xtol=1e-12, ftol=1e-12)
    return _result(legs, pe, wind, labels, sol, scales, sigma, stated)


def _check_counts(legs, nk, ng, wind, stated):
    m, p = legs.n, nk + 2 * ng
    need = p + (0 if stated else 1)
    n_speeds = len({round(float(v), 1) for v in legs.ias_kt})
    if n_speeds < nk:
        raise ObservabilityError(
            f"{legs.source}: {n_speeds} indicated airspeed{'s' * (n_speeds != 1)} cannot "
            f"determine the {nk} coefficients of the model: fly points at {nk} or more speeds, "
            f"or choose a model with fewer coefficients")
    if m < need:
        per = "per point" if wind == "per-point" else "per altitude band"
        hint = "one wind per altitude band (`wind` per-band), " if wind == "per-point" else ""
        raise ObservabilityError(
            f"{legs.source}: {m} legs cannot determine {nk} model coefficients and {ng} "
            f"wind{'s' * (ng != 1)} ({per}): {need} legs needed"
            f"{'' if stated else ' (one more to estimate the noise)'}; add points or legs, "
            f"{hint}or state groundspeed_sd_kt")


def _result(legs, pe, wind, labels, sol, scales, sigma, stated):
    from scipy.stats import t as student_t

    nk, m = len(pe.params), legs.n
    p = sol.x.size
    jac = sol.jac
    sv = np.linalg.svd(jac / np.linalg.norm(jac, axis=0).clip(1e-300), compute_uv=False)
    if sv[-1] / sv[0] < 1e-8:
        raise ObservabilityError(
            f"{legs.source}: the legs cannot separate the model coefficients from the winds "
            f"({wind}); fly points over a wider speed range, or more tracks per point")
    dof = m - p
    if stated:
        s2, factor, source = 1.0, 2.0, legs.sd_from
        noise = float(np.sqrt(np.mean(sigma ** 2)))
    else:
        s2 = float(np.sum(sol.fun ** 2) / dof)
        factor, source, noise = float(student_t.ppf(0.975, dof)), "scatter", math.sqrt(s2)
    cov_z = s2 * np.linalg.pinv(jac.T @ jac)
    scale = np.r_[scales, np.ones(p - nk)]
    cov = cov_z * np.outer(scale, scale)
    notes = []
    if stated and legs.sd_from == "stated" and dof > 0:
        chi2 = float(np.sum(sol.fun ** 2))
        from scipy.stats import chi2 as chi2_dist
        if chi2_dist.sf(chi2, dof) < 0.01:
            notes.append(f"the legs scatter more than the stated groundspeed_sd_kt "
                         f"(chi-square {chi2:.1f} for {dof} degrees of freedom, p < 0.01): "
                         f"the bounds are too small")
    if not sol.success:
        notes.append(f"the global fit did not converge ({sol.message})")
    return LegFit(model=pe.name, wind_mode=wind, coefficients=sol.x[:nk] * scales,
                  coef_cov=cov[:nk, :nk], group_labels=tuple(labels),
                  winds_ne_mps=sol.x[nk:].reshape(-1, 2), winds_cov=cov[nk:, nk:],
                  half_width_factor=factor, noise_std_mps=noise, noise_source=source, dof=dof,
                  n_samples=m, success=bool(sol.success), message=str(sol.message),
                  iterations=int(sol.nfev), residuals_mps=sol.fun * sigma,
                  vi_range_kt=(float(np.min(legs.ias_kt)), float(np.max(legs.ias_kt))),
                  warnings=tuple(notes))
