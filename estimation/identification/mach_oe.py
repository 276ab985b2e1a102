"""Output error with a Mach-dependent static position error and the temperature probe's recovery.

For a jet's level test point through the transonic region: the static source's error
Δp_p/p_s = g(M_ic) is a natural cubic spline in M_ic (`pitotcal.core.models.mach_spline_basis`;
the unknowns are its values at the knots), the total pressure p_T is exact, and a
total-temperature probe of unknown recovery r is a second output. With the GPS velocity V_g,
the wind W (north, east) and the static temperature along the test point
T_s(h) = T̄ − L (h − h̄) (L the standard lapse; constant without a GPS height):

    p_s = p_si (1 − g(M_ic)),          M_ic = M(q_ci / p_si)
    V_t = |V_g − W|,                   M = V_t / a(T_s)
    r_q = q_c(M, p_s) − (p_T − p_s)    (Pa)
    r_T = T_s (1 + 0.2 r M²) − T_t     (K)

q_c(M, p_s) is the pitot law of `pitotcal.core.airdata` (Rayleigh above M 1), so every sample
through Mach 1 enters. The second output is what makes r and the OAT estimable: in level flight
the probe reads T_t = T̄ + r V_t² / (2 c_p), a straight line in the GPS airspeed squared whose
intercept is the OAT and whose slope is the recovery; without it r would trade against g(M).
The outputs are weighted by their residual variances (estimated, two passes); the covariance
is the colored-residual one of `estimation.uncertainty.covariance`. r is bounded by
`recovery_bounds` (a probe recovers at most the whole stagnation rise: r <= 1).
"""

import dataclasses

import numpy as np
from scipy.optimize import least_squares

from pitotcal.core import checks
from pitotcal.core.airdata import (GAMMA, QC_OVER_PS_MAX, cas_from_qc_mps, mach_from_qc,
                                   pressure_altitude_m, qc_from_mach_pa)
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import mach_knots, mach_spline_basis
from pitotcal.core.moist_air import total_temperature_ratio
from pitotcal.core.units import ISA_LAPSE_KPM, R_AIR_JKGK, m_to_ft, mps_to_kt

from ..uncertainty.covariance import colored_covariance

__all__ = ["MACH_GRID", "RECOVERY_BOUNDS", "MachFitResult", "identify_mach",
           "position_corrections"]

# A probe recovers at most the whole stagnation rise (r = 1); an unshielded one about 0.6-0.8.
RECOVERY_BOUNDS = (0.5, 1.0)
# M_ic where the curve is tabulated (within the data's range).
MACH_GRID = tuple(np.round(np.arange(0.4, 3.0001, 0.025), 3))
_CP_JKGK = GAMMA * R_AIR_JKGK / (GAMMA - 1.0)
# The first pass's output scales (Pa, K): a 0.3 m/s airspeed at 250 m/s and 0.5 kg/m³, a probe's
# fraction of a kelvin; the second pass uses the first's residual RMS.
_PRIOR_SIGMAS = (40.0, 0.5)


@dataclasses.dataclass(frozen=True)
class MachFitResult:
    """What `identify_mach` found.

    Attributes
    ----------
    success, message : bool, str
        The solver's outcome.
    knots : ndarray (K,)
        M_ic of the spline's knots.
    dpp_ps_knots : ndarray (K,)
        Δp_p/p_s at the knots.
    wind_n_mps, wind_e_mps, recovery, oat_k : float
        The wind (the air mass's velocity), the probe's recovery factor, the static temperature
        at the median GPS height.
    covariance : ndarray (K + 4, K + 4)
        Of (dpp_ps_knots..., wind_n_mps, wind_e_mps, recovery, oat_k).
    recovery_at_bound : bool
        r sits on a bound of `recovery_bounds`; the covariance is the local one there.
    spe : list of dict
        The curve on `MACH_GRID` within the data: {"mach_ic", "dpp_ps", "dpp_ps_2sigma",
        "dv_kt", "dm", "dh_ft"} (ΔV_pc, ΔM_pc, ΔH_pc at the test point's median static pressure).
    sigma_q_pa, sigma_t_k : float
        RMS of the two outputs' residuals.
    n_fit : int
        Samples fitted (all of them).
    mach_ic_max : float
        The highest M_ic fitted.
    """

    success: bool
    message: str
    knots: np.ndarray
    dpp_ps_knots: np.ndarray
    wind_n_mps: float
    wind_e_mps: float
    recovery: float
    oat_k: float
    covariance: np.ndarray
    recovery_at_bound: bool
    spe: list
    sigma_q_pa: float
    sigma_t_k: float
    n_fit: int
    mach_ic_max: float

    def std(self, name):
        """1σ of "wind_n_mps", "wind_e_mps", "recovery" or "oat_k"."""
        i = self.knots.size + ("wind_n_mps", "wind_e_mps", "recovery", "oat_k").index(name)
        return float(np.sqrt(self.covariance[i, i]))

    def dpp_ps(self, mach_ic):
        """(Δp_p/p_s, its 2σ) at `mach_ic` (array)."""
        basis = mach_spline_basis(np.atleast_1d(np.asarray(mach_ic, dtype=float)), self.knots)
        k = self.knots.size
        var = np.einsum("ij,jk,ik->i", basis, self.covariance[:k, :k], basis)
        return basis @ self.dpp_ps_knots, 2.0 * np.sqrt(np.maximum(var, 0.0))

    def to_dict(self):
        """The JSON-ready summary."""
        return {"method": "output_error_mach", "success": self.success, "message": self.message,
                "knots_mach_ic": self.knots.tolist(), "dpp_ps_knots": self.dpp_ps_knots.tolist(),
                "wind_n_mps": self.wind_n_mps, "wind_e_mps": self.wind_e_mps,
                "wind_2sigma_mps": 2.0 * max(self.std("wind_n_mps"), self.std("wind_e_mps")),
                "recovery": self.recovery, "recovery_2sigma": 2.0 * self.std("recovery"),
                "recovery_at_bound": self.recovery_at_bound, "oat_k": self.oat_k,
                "oat_2sigma_k": 2.0 * self.std("oat_k"), "sigma_q_pa": self.sigma_q_pa,
                "sigma_t_k": self.sigma_t_k, "n_fit": self.n_fit,
                "mach_ic_max": self.mach_ic_max, "spe": self.spe}


def identify_mach(flight, *, knots=None, recovery_bounds=RECOVERY_BOUNDS):
    """Fit the Mach-dependent static error, the wind, the recovery and the OAT (module notes).

    Parameters
    ----------
    flight : Flight
        With `ps_pa` (the static port), `tat_k` (a total-temperature probe) and `qci_pa`
        (p_T − p_s measured); `alt_m` (GPS height) when known, for the lapse along the path.
    knots : sequence of float, optional
        M_ic of the spline's knots, increasing, at least 2; chosen from the data when None
        (`pitotcal.core.models.mach_knots`: dense through the transonic region).
    recovery_bounds : (float, float)
        Lowest and highest recovery factor of the probe.

    Returns
    -------
    MachFitResult
    """
    r_lo, r_hi = checks.recovery_bounds(recovery_bounds)
    data = _data(flight)
    knots = mach_knots(data["mach_ic"]) if knots is None else _knots(knots)
    data["basis"] = mach_spline_basis(data["mach_ic"], knots)
    k = knots.size
    scale = np.r_[np.full(k, 0.01), 1.0, 1.0, 0.1, 10.0]
    start = np.r_[np.full(k, 0.01), _ram_line(data, r_lo, r_hi)]
    lower = np.r_[np.full(k + 2, -np.inf), r_lo, 150.0]
    upper = np.r_[np.full(k + 2, np.inf), max(r_hi, r_lo + 1e-9), 350.0]   # low = high: r fixed
    weights = _PRIOR_SIGMAS
    for _ in range(2):          # the outputs' variances from the previous pass
        sol = least_squares(_residual, start / scale, args=(data, scale, weights),
                            bounds=(lower / scale, upper / scale), method="trf", x_scale=1.0)
        rq, rt = _outputs(sol.x * scale, data)
        weights = (float(np.sqrt(np.mean(rq ** 2))), float(np.sqrt(np.mean(rt ** 2))))
        start = sol.x * scale
    x = sol.x * scale
    cov = colored_covariance(sol.jac, sol.fun, window="exponential").covariance \
        * np.outer(scale, scale)
    result = MachFitResult(
        success=bool(sol.success), message=str(sol.message), knots=knots,
        dpp_ps_knots=x[:k], wind_n_mps=float(x[k]), wind_e_mps=float(x[k + 1]),
        recovery=float(x[k + 2]), oat_k=float(x[k + 3]), covariance=cov,
        recovery_at_bound=bool(min(x[k + 2] - r_lo, r_hi - x[k + 2]) < 1e-6), spe=[],
        sigma_q_pa=weights[0], sigma_t_k=weights[1], n_fit=int(data["mach_ic"].size),
        mach_ic_max=float(np.max(data["mach_ic"])))
    return dataclasses.replace(result, spe=_table(result, data))


def _ram_line(data, r_lo, r_hi):
    """Start values (wind 0, r, T̄) from the probe against the ground speed squared: T_t = T̄ +
    r V² / (2 c_p), r within its bounds."""
    v2 = np.sum(data["vg"] ** 2, axis=1) / (2.0 * _CP_JKGK)
    slope, intercept = np.polyfit(v2, data["tat_k"], 1)
    return np.array([0.0, 0.0, min(max(float(slope), r_lo), r_hi), float(intercept)])


def _knots(knots):
    k = np.asarray(knots, dtype=float).ravel()
    if k.size < 2 or not np.all(np.isfinite(k)) or np.any(np.diff(k) <= 0.0):
        raise PitotcalError(f"`knots` {list(k)!r} must be at least 2 increasing numbers",
                            param="knots")
    return k


def _data(flight):
    """The arrays the fit needs, SI (every sample)."""
    for name in ("ps_pa", "tat_k"):
        if getattr(flight, name) is None:
            raise PitotcalError(f"`flight` has no {name}: the Mach-dependent fit needs the "
                                "static port and a total-temperature probe", param="flight")
    ps = np.asarray(flight.ps_pa, dtype=float)
    qci = np.asarray(flight.qci_pa, dtype=float)
    for name in ("ps_pa", "tat_k", "qci_pa", "gps_vn_mps", "gps_ve_mps", "gps_vd_mps"):
        if getattr(flight, name) is None:       # the vertical channel is optional
            continue
        values = np.asarray(getattr(flight, name), dtype=float)
        if not np.all(np.isfinite(values)) or (name in ("ps_pa", "tat_k") and np.any(values <= 0)):
            raise PitotcalError(f"`flight` {name} has a sample that is not a positive finite "
                                "number", param="flight")
    ratio = np.clip(qci / ps, 0.0, QC_OVER_PS_MAX)
    mach_ic = mach_from_qc(ratio, 1.0)
    vd = flight.gps_vd_mps if flight.gps_vd_mps is not None else np.zeros(ps.size)
    h = np.asarray(flight.alt_m, dtype=float) if flight.alt_m is not None else np.zeros(ps.size)
    h = np.where(np.isfinite(h), h, np.nanmedian(h) if np.any(np.isfinite(h)) else 0.0)
    tat = np.asarray(flight.tat_k, dtype=float)
    return {"ps_pa": ps, "pt_pa": ps + qci, "tat_k": tat, "mach_ic": mach_ic,
            "dh_m": h - np.median(h), "vg": np.column_stack([flight.gps_vn_mps,
                                                             flight.gps_ve_mps, vd]),
            "oat0_k": float(np.mean(tat / total_temperature_ratio(mach_ic)))}


def _outputs(x, data):
    """(r_q Pa, r_T K) per sample at the unknowns `x` (module notes)."""
    k = data["basis"].shape[1]
    ps = data["ps_pa"] * (1.0 - data["basis"] @ x[:k])
    oat = x[k + 3] - ISA_LAPSE_KPM * data["dh_m"]
    tas = np.linalg.norm(data["vg"] - np.array([x[k], x[k + 1], 0.0]), axis=1)
    mach = np.minimum(tas / np.sqrt(GAMMA * R_AIR_JKGK * oat), 3.0)
    r_t = oat * total_temperature_ratio(mach, x[k + 2]) - data["tat_k"]
    r_q = qc_from_mach_pa(mach, ps) - (data["pt_pa"] - ps)
    return r_q, r_t


def _residual(xs, data, scale, weights):
    r_q, r_t = _outputs(xs * scale, data)
    return np.concatenate([r_q / weights[0], r_t / weights[1]])


def position_corrections(mach_ic, dpp_ps, psi_pa):
    """(ΔV_pc kt, ΔM_pc, ΔH_pc ft) of a static error Δp_p/p_s = (p_si − p_s)/p_si at M_ic and
    the indicated static pressure `psi_pa`, with p_T exact: q_c = q_ci + p_si Δp_p/p_s."""
    mach_ic = np.asarray(mach_ic, dtype=float)
    g = np.asarray(dpp_ps, dtype=float)
    qci = qc_from_mach_pa(mach_ic, psi_pa)
    ps = psi_pa * (1.0 - g)
    qc = qci + psi_pa * g
    dv = mps_to_kt(cas_from_qc_mps(qc) - cas_from_qc_mps(qci))
    dm = mach_from_qc(qc, ps) - mach_ic
    dh = m_to_ft(pressure_altitude_m(ps) - pressure_altitude_m(np.full(mach_ic.shape, psi_pa)))
    return dv, dm, dh


def _table(result, data):
    """The curve on `MACH_GRID` within the data, with ΔV_pc, ΔM_pc, ΔH_pc at the median p_si."""
    lo, hi = float(np.min(data["mach_ic"])), float(np.max(data["mach_ic"]))
    grid = np.array([m for m in MACH_GRID if lo - 1e-9 <= m <= hi + 1e-9])
    if grid.size == 0:
        return []
    g, g2s = result.dpp_ps(grid)
    dv, dm, dh = position_corrections(grid, g, float(np.median(data["ps_pa"])))
    return [{"mach_ic": float(m), "dpp_ps": float(a), "dpp_ps_2sigma": float(b),
             "dv_kt": float(v), "dm": float(d), "dh_ft": float(h)}
            for m, a, b, v, d, h in zip(grid, g, g2s, dv, dm, dh)]
