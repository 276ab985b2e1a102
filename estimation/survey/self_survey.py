"""The self-survey: static position error from GPS height, independent of a pressure-error model.

The principle of the USAF Test Pilot School's online self-survey (Jurado & McGehee, J. Aircraft
56(2), 2019), written here from its description: during a level test point the aircraft
surveys its own atmosphere. The true static pressure along the flight path follows from the
GPS geometric height by the hydrostatic equation, dp/dh = −p g / (R T), with a temperature
profile T(h) = T̄ − L (h − h̄) (T̄ the test point's mean static temperature, L the standard
lapse rate), from one unknown reference pressure p_ref at the median height h̄:

    p(h) = p_ref (T(h) / T̄)^(g / (R L))

With the pitot total pressure p_t taken as exact, p(h) gives the Mach number
M = M(p_t − p, p), the static temperature T_s = T_t / (1 + 0.2 r M²) of a total-temperature
probe of recovery r, and the true airspeed V_t = M √(γ R T_s), which must equal the GPS
velocity relative to the air, |V_g − W|. Least squares over the samples fit p_ref, the wind
W (north, east) and r; every sample then gives its own static position error

    Δp_p / p_s = (p_s − p(h)) / p_s    against    M_ic = M(p_t − p_s, p_s),

with no model of how Δp_p depends on M_ic: the curve is whatever the data say, through the
transonic region. With the attitude and the sideslip vane given, the airspeed is compared as a
vector, V_t u + W = V_g (u its direction, `airspeed_direction`), and the vertical wind is
fitted too. The profile's T̄ is the probe's temperature with r = 1 at M_ic: over the few tens
of metres of a level test point its error moves p(h) by far less than its stated bound. Every
sample enters the fit and the curve, through Mach 1: the Mach numbers come from the pitot
relations of `pitotcal.core.airdata` (Rayleigh above M 1). The recovery factor is bounded
(`recovery_bounds`, default 0.5 to 1: a probe recovers at most the whole stagnation rise);
at a bound `recovery_at_bound` says so and the covariance is the local one there.

Bounds (2σ) of each M_ic bin combine: the fitted unknowns' covariance (colored residuals,
`estimation.uncertainty.covariance`), the scatter of the bin's samples, a GPS height drift
over the test point (`height_drift_m`, 1σ) and the temperature profile (T̄ ± `oat_sigma_k`
and the lapse rate ± `LAPSE_SIGMA_KPM`).
"""

import dataclasses

import numpy as np
from scipy.optimize import least_squares

from pitotcal.core import checks
from pitotcal.core.airdata import GAMMA, QC_OVER_PS_MAX, mach_from_qc
from pitotcal.core.airspeed_direction import airspeed_direction, aligned_attitude
from pitotcal.core.errors import PitotcalError
from pitotcal.core.moist_air import total_temperature_ratio
from pitotcal.core.units import G0_MPS2, ISA_LAPSE_KPM, R_AIR_JKGK

from ..uncertainty.covariance import colored_covariance

__all__ = ["LAPSE_SIGMA_KPM", "RECOVERY_BOUNDS", "SelfSurveyResult", "hydrostatic_pressure_pa",
           "self_survey"]

LAPSE_SIGMA_KPM = 0.003          # a real profile's lapse rate, 1σ about the standard one
# A probe recovers at most the whole stagnation rise (r = 1); an unshielded one about 0.6-0.8.
RECOVERY_BOUNDS = (0.5, 1.0)
# unknowns: (p_ref/p̄_s − 1), W_n, W_e, r, and W_d with the vector airspeed
_SCALE = np.array([1e-2, 1.0, 1.0, 1.0, 1.0])
_NAMES = ("p_ref_pa", "wind_n_mps", "wind_e_mps", "recovery", "wind_d_mps")


@dataclasses.dataclass(frozen=True)
class SelfSurveyResult:
    """What `self_survey` found.

    Attributes
    ----------
    success, message : bool, str
        The least-squares solver's outcome.
    wind_n_mps, wind_e_mps, recovery, p_ref_pa : float
        The fitted wind (the air mass's velocity, north and east), the probe's recovery
        factor and the true static pressure at the median GPS height `h_ref_m`.
    covariance : ndarray (4, 4) or (5, 5)
        Of (p_ref_pa, wind_n_mps, wind_e_mps, recovery[, wind_d_mps]).
    airspeed_model : str
        "magnitude" (|V_g − W| = V_t) or "vector" (attitude and vanes point V_t; `wind_d_mps`
        fitted).
    oat_k, oat_2sigma_k : float
        The test point's mean static temperature and its 2σ.
    mach_ic, dpp_ps : ndarray
        Per sample: M_ic and Δp_p/p_s (every sample, through Mach 1).
    spe : list of dict
        The curve by M_ic bin: {"mach_ic", "dpp_ps", "dpp_ps_2sigma", "n"}.
    n_fit, n_excluded_supersonic : int
        Samples fitted; samples beyond the pitot relations' Mach range (none in a real flight).
    recovery_at_bound : bool
        The fitted recovery factor sits on a bound of `recovery_bounds`.
    """

    success: bool
    message: str
    wind_n_mps: float
    wind_e_mps: float
    recovery: float
    p_ref_pa: float
    h_ref_m: float
    covariance: np.ndarray
    oat_k: float
    oat_2sigma_k: float
    mach_ic: np.ndarray
    dpp_ps: np.ndarray
    spe: list
    n_fit: int
    n_excluded_supersonic: int
    airspeed_model: str = "magnitude"
    wind_d_mps: float = 0.0
    recovery_at_bound: bool = False

    def std(self, name):
        """1σ of "p_ref_pa", "wind_n_mps", "wind_e_mps", "recovery" or "wind_d_mps"."""
        i = _NAMES.index(name)
        return float(np.sqrt(self.covariance[i, i])) if i < len(self.covariance) else 0.0

    def to_dict(self):
        """The JSON-ready summary (no per-sample arrays)."""
        return {"method": "self_survey", "success": self.success, "message": self.message,
                "airspeed_model": self.airspeed_model,
                "wind_n_mps": self.wind_n_mps, "wind_e_mps": self.wind_e_mps,
                "wind_d_mps": self.wind_d_mps,
                "wind_2sigma_mps": 2.0 * max(self.std("wind_n_mps"), self.std("wind_e_mps")),
                "recovery": self.recovery, "recovery_2sigma": 2.0 * self.std("recovery"),
                "recovery_at_bound": self.recovery_at_bound,
                "p_ref_pa": self.p_ref_pa, "h_ref_m": self.h_ref_m, "oat_k": self.oat_k,
                "oat_2sigma_k": self.oat_2sigma_k, "n_fit": self.n_fit,
                "n_excluded_supersonic": self.n_excluded_supersonic, "spe": self.spe}


def self_survey(flight, *, attitude=None, bin_width=0.025, height_drift_m=1.0,
                oat_sigma_k=2.0, recovery_bounds=RECOVERY_BOUNDS):
    """Static position error Δp_p/p_s against M_ic by the self-survey (module notes).

    Parameters
    ----------
    flight : Flight
        With `ps_pa` (the static port), `alt_m` (GPS geometric height, m) and `tat_k` (a
        total-temperature probe); `qci_pa` the measured p_t − p_s.
    attitude : dict of ndarray, optional
        `time_s`, `roll_rad`, `pitch_rad`, `heading_rad` (true) and optionally `sideslip_rad`
        (the vane), e.g. from `pitotcal.io.mapped_csv.read_attitude`: the airspeed is then
        compared with GPS as a vector (`airspeed_direction`), and the vertical wind fitted.
        Without it, as a magnitude.
    bin_width : float
        Width of the M_ic bins of the curve.
    height_drift_m : float
        1σ drift of the GPS height over the test point, m (it moves p(h) by g/(R T) per m).
    oat_sigma_k : float
        1σ of the hydrostatic profile's mean temperature, K.
    recovery_bounds : (float, float)
        Lowest and highest recovery factor of the probe (module notes).

    Returns
    -------
    SelfSurveyResult
    """
    bin_width = checks.number("bin_width", bin_width, 1e-3, 0.5)
    height_drift_m = checks.number("height_drift_m", height_drift_m, 0.0, 100.0)
    oat_sigma_k = checks.number("oat_sigma_k", oat_sigma_k, 0.0, 50.0)
    r_lo, r_hi = checks.recovery_bounds(recovery_bounds)
    data = _data(flight, attitude)
    fit = np.ones(data["ratio"].size, dtype=bool)
    profile = (data["oat0_k"], ISA_LAPSE_KPM)
    scale = _SCALE[:5 if "u" in data else 4]
    start = np.array([0.0, 0.0, 0.0, min(max(0.98, r_lo), r_hi), 0.0])[:scale.size]
    lower = np.full(scale.size, -np.inf)
    upper = np.full(scale.size, np.inf)
    lower[3], upper[3] = r_lo, max(r_hi, r_lo + 1e-9)         # low = high: r fixed
    sol = least_squares(_residual, start / scale, x_scale=1.0, args=(data, fit, profile),
                        method="trf", bounds=(lower / scale, upper / scale))
    x = sol.x * scale
    cov_x = colored_covariance(sol.jac, sol.fun, window="exponential").covariance \
        * np.outer(scale, scale)
    p_ref = data["ps_mean_pa"] * (1.0 + x[0])
    to_pa = np.diag([data["ps_mean_pa"], *np.ones(scale.size - 1)])
    cov = to_pa @ cov_x @ to_pa
    oat = _static_temperature(data, _static_pa(data, x, profile), x[3])
    dpp = _dpp_ps(data, x, profile)
    spread = _term_spreads(data, x, cov_x, profile, height_drift_m, oat_sigma_k)
    oat_2s = 2.0 * np.sqrt(_oat_var(data, x, cov_x, profile))
    return SelfSurveyResult(
        success=bool(sol.success), message=str(sol.message), wind_n_mps=float(x[1]),
        wind_e_mps=float(x[2]), recovery=float(x[3]), p_ref_pa=float(p_ref),
        h_ref_m=float(data["h_ref_m"]), covariance=cov, oat_k=float(np.mean(oat)),
        oat_2sigma_k=float(oat_2s), mach_ic=data["mach_ic"], dpp_ps=dpp,
        spe=_binned(data["mach_ic"], dpp, spread, bin_width, data["time_s"]),
        n_fit=int(np.count_nonzero(fit)), n_excluded_supersonic=data["n_super"],
        airspeed_model="vector" if "u" in data else "magnitude",
        wind_d_mps=float(x[4]) if x.size > 4 else 0.0,
        recovery_at_bound=bool(min(x[3] - r_lo, r_hi - x[3]) < 1e-6))


def _data(flight, attitude=None):
    """The arrays the survey needs, SI, every sample in the pitot relations' range; `u` the
    airspeed's direction when the attitude is given."""
    for name in ("ps_pa", "alt_m", "tat_k"):
        if getattr(flight, name) is None:
            raise PitotcalError(f"`flight` has no {name}: the self-survey needs the static "
                                "port, the GPS height and a total-temperature probe",
                                param="flight")
    ps = np.asarray(flight.ps_pa, dtype=float)
    ratio = np.asarray(flight.qci_pa, dtype=float) / ps
    keep = (np.abs(ratio) <= QC_OVER_PS_MAX) & np.isfinite(flight.alt_m)
    vd = flight.gps_vd_mps if flight.gps_vd_mps is not None else np.zeros(ps.size)
    h = np.asarray(flight.alt_m, dtype=float)[keep]
    oat0 = np.asarray(flight.tat_k)[keep] / total_temperature_ratio(mach_from_qc(ratio[keep], 1.0))
    vg = np.column_stack([flight.gps_vn_mps, flight.gps_ve_mps, vd])[keep]
    extra = {}
    if attitude is not None:
        att = aligned_attitude(attitude, np.asarray(flight.time_s)[keep])
        extra["u"] = airspeed_direction(att, vg)
    return {**extra, "time_s": np.asarray(flight.time_s)[keep], "ps_pa": ps[keep],
            "pt_pa": ps[keep] + np.asarray(flight.qci_pa)[keep], "tat_k": flight.tat_k[keep],
            "h_m": h, "h_ref_m": float(np.median(h)), "ratio": ratio[keep],
            "mach_ic": mach_from_qc(ratio[keep], 1.0), "ps_mean_pa": float(np.mean(ps[keep])),
            "oat0_k": float(np.mean(oat0)),
            "vg": vg,
            "n_super": int(np.count_nonzero(np.abs(ratio) > QC_OVER_PS_MAX))}


def hydrostatic_pressure_pa(h_m, h_ref_m, p_ref_pa, t_ref_k, lapse_kpm=ISA_LAPSE_KPM):
    """Static pressure at geometric height `h_m` by the hydrostatic equation, Pa.

    Notes
    -----
    With T(h) = T_ref − L (h − h_ref) and constant gravity g₀,
    p(h) = p_ref (T(h) / T_ref)^(g₀ / (R L)); L = 0 is the isothermal
    p_ref exp(−g₀ (h − h_ref) / (R T_ref)).
    """
    dh = np.asarray(h_m, dtype=float) - h_ref_m
    if lapse_kpm == 0.0:
        return p_ref_pa * np.exp(-G0_MPS2 * dh / (R_AIR_JKGK * t_ref_k))
    t_h = t_ref_k - lapse_kpm * dh
    return p_ref_pa * (t_h / t_ref_k) ** (G0_MPS2 / (R_AIR_JKGK * lapse_kpm))


def _static_pa(data, x, profile):
    """True static pressure along the path from the unknowns `x`, Pa."""
    return hydrostatic_pressure_pa(data["h_m"], data["h_ref_m"],
                                   data["ps_mean_pa"] * (1.0 + x[0]), *profile)


def _true_mach(data, p):
    ratio = np.clip((data["pt_pa"] - p) / p, 0.0, QC_OVER_PS_MAX)
    return mach_from_qc(ratio, 1.0)


def _static_temperature(data, p, recovery):
    return data["tat_k"] / total_temperature_ratio(_true_mach(data, p), recovery)


def _residual(xs, data, fit, profile):
    """V_t from the pressures minus |V_g − W| (magnitude), or V_t u + W − V_g stacked north,
    east, down (vector), m/s, on the fitted samples."""
    x = xs * _SCALE[:xs.size]
    p = _static_pa(data, x, profile)
    tas = _true_mach(data, p) * np.sqrt(GAMMA * R_AIR_JKGK * _static_temperature(data, p, x[3]))
    if "u" in data:
        air = tas[:, None] * data["u"] + np.array([x[1], x[2], x[4]]) - data["vg"]
        return air[fit].ravel(order="F")
    air = data["vg"] - np.array([x[1], x[2], 0.0])
    return (tas - np.linalg.norm(air, axis=1))[fit]


def _dpp_ps(data, x, profile):
    return (data["ps_pa"] - _static_pa(data, x, profile)) / data["ps_pa"]


def _term_spreads(data, x, cov_x, profile, drift_m, oat_sigma_k):
    """Per-sample 1σ of Δp_p/p_s from the unknowns, the height drift and the profile."""
    steps = np.diag(_SCALE[:x.size] * 1e-3)
    jac = np.column_stack([(_dpp_ps(data, x + d, profile) - _dpp_ps(data, x - d, profile))
                           / (2.0 * d[i]) for i, d in enumerate(steps)])
    var = np.einsum("ij,jk,ik->i", jac, cov_x, jac)
    t_mean, lapse = profile
    var += (drift_m * G0_MPS2 / (R_AIR_JKGK * t_mean)) ** 2
    for other in ((t_mean + oat_sigma_k, lapse), (t_mean, lapse + LAPSE_SIGMA_KPM)):
        var += (_dpp_ps(data, x, other) - _dpp_ps(data, x, profile)) ** 2
    return np.sqrt(var)


def _oat_var(data, x, cov_x, profile):
    """Variance of the mean static temperature from the unknowns' covariance."""
    def mean_oat(xx):
        return np.mean(_static_temperature(data, _static_pa(data, xx, profile), xx[3]))
    grad = np.array([(mean_oat(x + d) - mean_oat(x - d)) / (2.0 * d[i])
                     for i, d in enumerate(np.diag(_SCALE[:x.size] * 1e-3))])
    return float(grad @ cov_x @ grad)


def _binned(mach_ic, dpp, spread, width, time_s):
    """The curve by M_ic bin: mean Δp_p/p_s and its 2σ (the terms' spread plus the bin's
    scatter over its independent stretches, counted as the bin's seconds of data)."""
    edges = np.arange(np.floor(mach_ic.min() / width) * width, mach_ic.max() + width, width)
    dt = float(np.median(np.diff(time_s))) if time_s.size > 1 else 1.0
    out = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        inside = (mach_ic >= lo) & (mach_ic < hi)
        n = int(np.count_nonzero(inside))
        if n < 3:
            continue
        independent = max(1.0, n * dt)       # one independent stretch per second of data
        scatter = np.std(dpp[inside], ddof=1) / np.sqrt(independent)
        sigma = np.sqrt(np.mean(spread[inside] ** 2) + scatter ** 2)
        out.append({"mach_ic": float(np.mean(mach_ic[inside])),
                    "dpp_ps": float(np.mean(dpp[inside])), "dpp_ps_2sigma": float(2.0 * sigma),
                    "n": n})
    return out
