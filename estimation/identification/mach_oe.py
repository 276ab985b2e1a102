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

With the attitude (`attitude`: heading, pitch, roll and the sideslip vane), the airspeed's
direction u (`pitotcal.core.airspeed_direction`) gives a third output, the horizontal air
velocity across it,

    r_y = û_φ × (V_g − W)_h   (m/s),   û_φ = u_h turned by φ = δ + τ dψ/dt,

with two unknowns stated before any data are seen: δ, a constant misalignment of the heading
and the vane with the airspeed (an installation or vane offset: 1° is 4 m/s of wind at
250 m/s), and τ, the attitude's time offset against the GPS velocity (in a turn at rate dψ/dt
it turns the direction by τ dψ/dt). The magnitude alone finds the wind from the variation of
ground speed with heading; the direction adds the cross-track component at every sample. A
full turn separates δ and τ from the wind (both rotate with the aircraft, the wind does not);
on a single heading δ and the cross-track wind are one number.

The spline's representation error, what knots this far apart cannot follow, is not in the
fitted covariance. It is measured by fitting again with a knot added midway in every interval
the data fill (`pitotcal.core.models.denser_knots`): within each coarse interval the largest
squared difference of the two curves, less the part the denser fit's extra noise explains
(for nested fits Var(difference) = Var(dense) − Var(coarse)), is the variance of a 1σ there,
added to the curve's variance (`spline_sigma`). For a smooth curve the denser spline's own
error is an order smaller (a cubic spline's error falls with the fourth power of the
spacing), so the difference measures the coarse one's.
"""

import dataclasses

import numpy as np
from scipy.optimize import least_squares

from pitotcal.core import checks
from pitotcal.core.airdata import (GAMMA, QC_OVER_PS_MAX, cas_from_qc_mps, mach_from_qc,
                                   pressure_altitude_m, qc_from_mach_pa)
from pitotcal.core.airspeed_direction import (airspeed_direction, aligned_attitude,
                                              heading_rate_rps, rotated_horizontal)
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import denser_knots, mach_knots, mach_spline_basis
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
# The first pass's output scales (Pa, K, m/s): a 0.3 m/s airspeed at 250 m/s and 0.5 kg/m³, a
# probe's fraction of a kelvin, a metre per second across the airspeed; the second pass uses the
# first's residual RMS.
_PRIOR_SIGMAS = (40.0, 0.5, 1.0)
# the unknowns after the spline's: their names and scales
_NAMES = ("wind_n_mps", "wind_e_mps", "recovery", "oat_k", "misalignment_rad", "latency_s")
_SCALES = (1.0, 1.0, 0.1, 10.0, 0.01, 0.1)


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
    covariance : ndarray (K + 4, K + 4) or (K + 6, K + 6)
        Of (dpp_ps_knots..., wind_n_mps, wind_e_mps, recovery, oat_k[, misalignment_rad,
        latency_s]).
    recovery_at_bound : bool
        r sits on a bound of `recovery_bounds`; the covariance is the local one there.
    spe : list of dict
        The curve on `MACH_GRID` within the data: {"mach_ic", "dpp_ps", "dpp_ps_2sigma",
        "dpp_ps_spline_2sigma", "dv_kt", "dm", "dh_ft"} (the 2σ includes the spline's term,
        given alone too; ΔV_pc, ΔM_pc, ΔH_pc at the test point's median static pressure).
    sigma_q_pa, sigma_t_k : float
        RMS of the two outputs' residuals.
    airspeed_model : str
        "magnitude" (|V_g − W| = V_t) or "vector" (with the attitude: the direction too).
    misalignment_rad, latency_s, sigma_y_mps : float
        With the attitude: δ and τ (module notes) and the RMS of the cross-track output's
        residual, m/s; 0, 0 and NaN without.
    spline_sigma : ndarray (K − 1,)
        1σ of the spline's representation error in each knot interval (module notes); in the
        curve's 2σ.
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
    airspeed_model: str = "magnitude"
    misalignment_rad: float = 0.0
    latency_s: float = 0.0
    sigma_y_mps: float = float("nan")
    spline_sigma: np.ndarray = None

    def std(self, name):
        """1σ of "wind_n_mps", "wind_e_mps", "recovery", "oat_k", "misalignment_rad" or
        "latency_s" (0 for the last two without the attitude)."""
        i = self.knots.size + _NAMES.index(name)
        return float(np.sqrt(self.covariance[i, i])) if i < len(self.covariance) else 0.0

    def dpp_ps(self, mach_ic, spline=True):
        """(Δp_p/p_s, its 2σ) at `mach_ic` (array); the 2σ with the spline's representation
        error unless `spline` is False."""
        m = np.atleast_1d(np.asarray(mach_ic, dtype=float))
        basis = mach_spline_basis(m, self.knots)
        k = self.knots.size
        var = np.einsum("ij,jk,ik->i", basis, self.covariance[:k, :k], basis)
        if spline and self.spline_sigma is not None:
            var = var + self.spline_sigma[_interval(m, self.knots)] ** 2
        return basis @ self.dpp_ps_knots, 2.0 * np.sqrt(np.maximum(var, 0.0))

    def summary(self):
        """A few lines in knots, kelvin and degrees, and the curve every 0.05 of M_ic."""
        w2 = mps_to_kt(2.0 * max(self.std("wind_n_mps"), self.std("wind_e_mps")))
        lines = [f"Mach-dependent output error: {self.n_fit} samples through M_ic "
                 f"{self.mach_ic_max:.3f} ({'converged' if self.success else self.message})",
                 f"Wind: {mps_to_kt(self.wind_n_mps):.1f} kt north, "
                 f"{mps_to_kt(self.wind_e_mps):.1f} kt east (2-sigma {w2:.1f} kt)",
                 f"OAT {self.oat_k:.2f} K (2-sigma {2 * self.std('oat_k'):.2f}); probe recovery "
                 f"{self.recovery:.3f} (2-sigma {2 * self.std('recovery'):.3f})"
                 + (" at its bound" if self.recovery_at_bound else "")]
        if self.airspeed_model == "vector":
            lines.append(f"Airspeed direction: misalignment {np.degrees(self.misalignment_rad):.2f}"
                         f" deg (2-sigma {np.degrees(2 * self.std('misalignment_rad')):.2f}), "
                         f"attitude time offset {self.latency_s:+.2f} s (2-sigma "
                         f"{2 * self.std('latency_s'):.2f})")
        lines.append("  M_ic  dpp/ps   2-sigma (spline)  dV_pc kt  dM_pc   dH_pc ft")
        for s in self.spe:
            if abs(s["mach_ic"] * 20.0 - round(s["mach_ic"] * 20.0)) < 1e-6:
                lines.append(f"  {s['mach_ic']:.2f}  {s['dpp_ps']:7.4f}  {s['dpp_ps_2sigma']:.4f} "
                             f"({s['dpp_ps_spline_2sigma']:.4f})  {s['dv_kt']:+7.1f}  "
                             f"{s['dm']:+.4f}  {s['dh_ft']:+7.0f}")
        return "\n".join(lines)

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
                "mach_ic_max": self.mach_ic_max, "airspeed_model": self.airspeed_model,
                "misalignment_deg": float(np.degrees(self.misalignment_rad)),
                "misalignment_2sigma_deg": float(np.degrees(2.0 * self.std("misalignment_rad"))),
                "latency_s": self.latency_s, "latency_2sigma_s": 2.0 * self.std("latency_s"),
                "sigma_y_mps": None if np.isnan(self.sigma_y_mps) else self.sigma_y_mps,
                "spe": self.spe}


def identify_mach(flight, *, knots=None, recovery_bounds=RECOVERY_BOUNDS, attitude=None,
                  spline_error=True):
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
    attitude : dict of ndarray, optional
        `time_s`, `roll_rad`, `pitch_rad`, `heading_rad` (true) and optionally `sideslip_rad`
        (e.g. from `pitotcal.io.mapped_csv.read_attitude`): the airspeed's direction becomes a
        third output, with the misalignment and the time offset as unknowns (module notes).
    spline_error : bool
        Measure the spline's representation error (a second fit, denser knots) and carry it in
        the curve's 2σ.

    Returns
    -------
    MachFitResult
    """
    r_lo, r_hi = checks.recovery_bounds(recovery_bounds)
    data = _data(flight, attitude)
    knots = mach_knots(data["mach_ic"]) if knots is None else _knots(knots)
    k = knots.size
    vector = "u" in data
    start = np.r_[np.full(k, 0.01), _ram_line(data, r_lo, r_hi), np.zeros(2 if vector else 0)]
    x, sol, weights, scale = _solve(data, knots, start, (r_lo, r_hi),
                                    _PRIOR_SIGMAS[:3 if vector else 2], passes=2)
    cov = colored_covariance(sol.jac, sol.fun, window="exponential").covariance \
        * np.outer(scale, scale)
    spline_sigma = (_spline_sigma(data, knots, x, cov, (r_lo, r_hi), weights) if spline_error
                    else np.zeros(k - 1))
    result = MachFitResult(
        success=bool(sol.success), message=str(sol.message), knots=knots,
        dpp_ps_knots=x[:k], wind_n_mps=float(x[k]), wind_e_mps=float(x[k + 1]),
        recovery=float(x[k + 2]), oat_k=float(x[k + 3]), covariance=cov,
        recovery_at_bound=bool(min(x[k + 2] - r_lo, r_hi - x[k + 2]) < 1e-6), spe=[],
        sigma_q_pa=weights[0], sigma_t_k=weights[1], n_fit=int(data["mach_ic"].size),
        mach_ic_max=float(np.max(data["mach_ic"])),
        airspeed_model="vector" if vector else "magnitude",
        misalignment_rad=float(x[k + 4]) if vector else 0.0,
        latency_s=float(x[k + 5]) if vector else 0.0,
        sigma_y_mps=weights[2] if vector else float("nan"), spline_sigma=spline_sigma)
    return dataclasses.replace(result, spe=_table(result, data))


def _solve(data, knots, start, r_bounds, weights, passes, ftol=1e-8):
    """Bounded least squares from `start`; each pass reweights the outputs by the residual RMS
    it leaves. (x, the last solver result, the outputs' RMS at x, the unknowns' scales)."""
    data = {**data, "basis": mach_spline_basis(data["mach_ic"], knots)}
    k = knots.size
    extra = start.size - k - 4
    scale = np.r_[np.full(k, 0.01), _SCALES[:4 + extra]]
    lower = np.r_[np.full(k + 2, -np.inf), r_bounds[0], 150.0, np.full(extra, -np.inf)]
    upper = np.r_[np.full(k + 2, np.inf), max(r_bounds[1], r_bounds[0] + 1e-9), 350.0,
                  np.full(extra, np.inf)]                   # low = high: r fixed
    x = start
    for _ in range(passes):
        sol = least_squares(_residual, x / scale, args=(data, scale, weights),
                            bounds=(lower / scale, upper / scale), method="trf", x_scale=1.0,
                            ftol=ftol)
        x = sol.x * scale
        weights = tuple(float(np.sqrt(np.mean(r ** 2))) for r in _outputs(x, data))
    return x, sol, weights, scale


def _spline_sigma(data, knots, x, cov, r_bounds, weights):
    """1σ of the representation error in each knot interval (module notes): the largest
    difference within it between this spline and the refit with `denser_knots`, less what the
    denser fit's extra noise explains (the variance of a nested fit's difference is the
    difference of the variances)."""
    k = knots.size
    dense = denser_knots(knots, data["mach_ic"])
    if dense.size == k:
        return np.zeros(k - 1)
    start = np.r_[mach_spline_basis(dense, knots) @ x[:k], x[k:]]
    # from the coarse solution; a looser tolerance: the difference is wanted to ~1e-4
    xd, sol, _, scale = _solve(data, dense, start, r_bounds, weights, passes=1, ftol=1e-6)
    kd = dense.size
    cov_d = colored_covariance(sol.jac, sol.fun, window="exponential").covariance[:kd, :kd] \
        * np.outer(scale[:kd], scale[:kd])
    out = np.zeros(k - 1)
    for i, (lo, hi) in enumerate(zip(knots[:-1], knots[1:])):
        m = np.linspace(lo, hi, 21)
        b, bd = mach_spline_basis(m, knots), mach_spline_basis(m, dense)
        extra = (np.einsum("ij,jk,ik->i", bd, cov_d, bd)
                 - np.einsum("ij,jk,ik->i", b, cov[:k, :k], b))
        out[i] = np.sqrt(np.max(np.maximum((bd @ xd[:kd] - b @ x[:k]) ** 2 - extra, 0.0)))
    return out


def _interval(mach_ic, knots):
    """Index of the knot interval holding each M_ic (the end intervals beyond the knots)."""
    return np.clip(np.searchsorted(knots, mach_ic, side="right") - 1, 0, knots.size - 2)


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


def _data(flight, attitude=None):
    """The arrays the fit needs, SI (every sample); with the attitude, `u` the airspeed's
    direction and `omega` the heading's rate."""
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
    out = {"ps_pa": ps, "pt_pa": ps + qci, "tat_k": tat, "mach_ic": mach_ic,
           "dh_m": h - np.median(h), "vg": np.column_stack([flight.gps_vn_mps,
                                                            flight.gps_ve_mps, vd]),
           "oat0_k": float(np.mean(tat / total_temperature_ratio(mach_ic)))}
    if attitude is not None:
        att = aligned_attitude(attitude, np.asarray(flight.time_s, dtype=float))
        if not all(np.all(np.isfinite(v)) for v in att.values()):
            raise PitotcalError("`attitude` has a sample that is not a finite number",
                                param="attitude")
        out["u"] = airspeed_direction(att, out["vg"])
        out["omega"] = heading_rate_rps(att["heading_rad"], flight.time_s)
    return out


def _outputs(x, data):
    """(r_q Pa, r_T K[, r_y m/s]) per sample at the unknowns `x` (module notes)."""
    k = data["basis"].shape[1]
    ps = data["ps_pa"] * (1.0 - data["basis"] @ x[:k])
    oat = x[k + 3] - ISA_LAPSE_KPM * data["dh_m"]
    air = data["vg"] - np.array([x[k], x[k + 1], 0.0])
    tas = np.linalg.norm(air, axis=1)
    mach = np.minimum(tas / np.sqrt(GAMMA * R_AIR_JKGK * oat), 3.0)
    r_t = oat * total_temperature_ratio(mach, x[k + 2]) - data["tat_k"]
    r_q = qc_from_mach_pa(mach, ps) - (data["pt_pa"] - ps)
    if "u" not in data:
        return r_q, r_t
    u = rotated_horizontal(data["u"], x[k + 4] + x[k + 5] * data["omega"])
    return r_q, r_t, u[:, 0] * air[:, 1] - u[:, 1] * air[:, 0]


def _residual(xs, data, scale, weights):
    return np.concatenate([r / w for r, w in zip(_outputs(xs * scale, data), weights)])


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
    spline_2s = 2.0 * result.spline_sigma[_interval(grid, result.knots)]
    dv, dm, dh = position_corrections(grid, g, float(np.median(data["ps_pa"])))
    return [{"mach_ic": float(m), "dpp_ps": float(a), "dpp_ps_2sigma": float(b),
             "dpp_ps_spline_2sigma": float(c), "dv_kt": float(v), "dm": float(d),
             "dh_ft": float(h)}
            for m, a, b, c, v, d, h in zip(grid, g, g2s, spline_2s, dv, dm, dh)]
