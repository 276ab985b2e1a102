"""The classic GPS leg methods, per calibration point: 3-leg closed form and N-leg subset mean.

At one indicated airspeed the aircraft flies legs at a constant true airspeed V on different
tracks; with a constant wind w each leg's ground velocity is g_i = V (cos ψ_i, sin ψ_i) + w, so
the ground velocities lie on a circle of radius V centred on w (Gray 1998; Lewis, NTPS 2003):

    |g_i − w|² = V²   ⇔   2 g_i·w + c = |g_i|²,   c = V² − |w|²        (i = 1, 2, 3)

— linear in (w_N, w_E, c): three legs give the circle through three points exactly. With four
or more legs the classic answer (Horton's NTPS 4-leg spreadsheet) is the mean of the 3-leg
solutions of the subsets (for four legs: legs 123, 234, 341, 412), with their spread.

Bounds, linearised: the implicit-function Jacobian of the solution with respect to each leg's
ground-velocity vector, J = −(∂F/∂x)⁻¹ ∂F/∂g, F_i = |g_i − w|² − V², x = (w_N, w_E, V), with a
per-leg velocity error σ_i per component: Cov x = J diag(σ²) Jᵀ (the tangential part of each
error moves g_i along the circle and drops out). σ_i is the stated `groundspeed_sd_kt` when
every leg of the point has it ("stated", or "samples" when the legs' own GPS samples give it,
`estimation.legs.flight`; bound 2σ); otherwise, with four or more legs, the
scatter of the legs about the circle, s² = Σ r_i² / (N − 3) with r_i = |g_i − w| − V, and the
half-width t₀.₉₇₅(N − 3) s |J_V| (Student t: with four legs one degree of freedom, t = 12.7;
"scatter"). Three legs without a stated accuracy carry no information on their own error
("none": no bound, with a warning).

The observability rule comes from the same Jacobian: |J_V|, the TAS error per knot of leg
velocity error (a dilution of precision: 0.58 for tracks 120° apart, 0.71 for N/E/S, 8 for legs
30° apart, infinite for collinear ground velocities), must stay below `DOP_MAX`.

TAS → CAS is compressible (`pitotcal.core.airdata`) at the leg's pressure altitude and OAT, with
the position error taken as static-source error, p_s = p_s,ind − (q_c − q_ci) (iterated).
ΔV_pc = V_c − V_ic.

Legs flown at different indicated airspeeds (or altitudes, or OATs) fly different TAS: each leg's
circle has its own radius V + δ_i, V the TAS at the point's mean q_ci, altitude and OAT, and δ_i
the leg's TAS less that one at the same pressure-error ratio Δp/q_ci (the position error of
legs a knot or two apart is the same fraction of q_c). Each 3-leg subset is then solved by
Newton's method on |g_i − w|² = (V + δ_i)² from the one-radius circle, and δ_i re-computed with
the ratio the solution gives until the ratio moves less than 1e-9 (six rounds at most). With
δ_i = 0 this is the one-radius circle exactly. A total-temperature column (`LegData.tat_k`)
is converted with each leg's true Mach at that ratio, in the same rounds.
"""

import dataclasses
import itertools
import math
from dataclasses import dataclass

import numpy as np

from pitotcal.core import airdata
from pitotcal.core.errors import ObservabilityError
from pitotcal.core.measurement import TotalPressureAir
from pitotcal.core.units import KT_TO_MPS, wind_polar

__all__ = ["DOP_MAX", "MAX_SUBSETS", "PointSolution", "cas_from_tas_mps", "circle_jacobian", "solve_point",
           "solve_points", "subsets", "three_leg"]

# Largest accepted TAS error per knot of leg velocity error (legs ~55° apart in heading).
DOP_MAX = 10.0
# Most 3-leg subsets averaged at one point: C(N, 3) grows as N³ (C(200, 3) = 1.3 million);
# beyond this many they are sampled: the mean's sampling error is the subsets' spread over
# sqrt(MAX_SUBSETS) (measured at 60 legs, 34,220 subsets: ΔV within 0.01 kt of the all-subset
# mean, bound ±0.063 against ±0.061 kt; docs/measured.md), at ~0.25 ms a subset.
MAX_SUBSETS = 5000
_MAX_NOTES = 10            # subsets named one by one in the warnings; the rest counted
_COLLINEAR = 1e-9          # relative smallest singular value of the circle's linear system
_NEWTON_STEPS = 20         # per-leg radii: Newton from the one-radius circle (3-5 suffice)
_TAS_ROUNDS = 6            # per-leg TAS re-computed with the solution's pressure-error ratio


@dataclass(frozen=True)
class PointSolution:
    """One calibration point solved by a classic method (SI; `_kt` where it says so).

    Attributes
    ----------
    point : str
    method : str
        "3-leg", "4-leg", "N-leg" (mean of the 3-leg subsets).
    legs : ndarray of int
        Indices of the point's legs in the `LegData`.
    ias_kt, pressure_alt_m, oat_k, qci_pa : float
        Mean indicated airspeed, indicated pressure altitude, OAT and q_ci over the legs.
    tas_mps, wind_n_mps, wind_e_mps : float
        TAS at the mean q_ci, altitude and OAT (each leg flies its own, module notes), wind.
    cov : ndarray, shape (3, 3)
        Covariance of (w_N, w_E, V) (NaN when `bound` is "none").
    half_width_factor : float
        Multiplier of the standard deviations for the 95 % half-widths (2, or Student t).
    bound : str
        "stated", "samples" (the sd the legs' own GPS samples give), "scatter" or "none".
    dop : float
        TAS error per unit leg velocity error (`DOP_MAX`).
    tas_subset_sd_mps : float
        Standard deviation of the subsets' TAS (Horton's SD; NaN for three legs).
    qc_pa, vc_kt, dv_kt, dv_half_kt, tas_half_mps : float
        Impact pressure and CAS from the TAS, ΔV_pc = V_c − V_ic and the half-widths.
    naive_tas_mps : float
        The mean of the legs' ground speeds, what a naive average would call TAS (biased by
        about |w|²/(2V) sin² of the wind angle, e.g. +1 kt for 20 kt of wind at 100 kt).
    residuals_mps : ndarray
        r_i = |g_i − w| − (V + δ_i).
    tas_offsets_mps : ndarray
        δ_i, each leg's TAS less V (zero when the legs share q_ci, altitude and OAT).
    """

    point: str
    method: str
    legs: np.ndarray
    ias_kt: float
    pressure_alt_m: float
    oat_k: float
    qci_pa: float
    tas_mps: float
    wind_n_mps: float
    wind_e_mps: float
    cov: np.ndarray
    half_width_factor: float
    bound: str
    dop: float
    tas_subset_sd_mps: float
    qc_pa: float
    vc_kt: float
    dv_kt: float
    dv_half_kt: float
    tas_half_mps: float
    naive_tas_mps: float
    residuals_mps: np.ndarray
    tas_offsets_mps: np.ndarray = None

    @property
    def wind(self):
        """(speed m/s, from deg)."""
        speed, frm = wind_polar(self.wind_n_mps, self.wind_e_mps)
        return float(speed), float(frm)


def three_leg(g_ne, delta=None):
    """TAS and wind from three ground velocities: the circle through three points.

    Parameters
    ----------
    g_ne : array_like, shape (3, 2)
        Ground velocities (north, east), any speed unit.
    delta : array_like, shape (3,), optional
        Each leg's TAS less V, in the unit of `g_ne` (module notes); None: one TAS.

    Returns
    -------
    ndarray, shape (3,)
        (w_N, w_E, V) in the unit of `g_ne`.

    Raises
    ------
    numpy.linalg.LinAlgError
        Collinear points (no circle); `solve_point` checks the conditioning first.

    Example
    -------
    >>> from pitotcal.core.units import wind_polar
    >>> import numpy as np
    >>> t = np.radians([178, 82, 355])      # NTPS GPS PEC sample data, legs 1-3
    >>> wn, we, v = three_leg(np.column_stack([[178, 185, 188] * np.cos(t),
    ...                                        [178, 185, 188] * np.sin(t)]))
    >>> round(float(v), 2)
    183.05
    """
    g = np.asarray(g_ne, dtype=float)
    a = np.column_stack([2.0 * g, np.ones(3)])
    wn, we, c = np.linalg.solve(a, np.sum(g ** 2, axis=1))
    x = np.array([wn, we, np.sqrt(c + wn ** 2 + we ** 2)])
    if delta is None or not np.any(delta):
        return x
    delta = np.asarray(delta, dtype=float)
    for _ in range(_NEWTON_STEPS):
        d = g - x[:2]
        f = np.sum(d ** 2, axis=1) - (x[2] + delta) ** 2
        step = np.linalg.solve(np.column_stack([-2.0 * d, -2.0 * (x[2] + delta)]), -f)
        x = x + step
        if np.max(np.abs(step)) <= 1e-12 * max(1.0, abs(x[2])):
            break
    return x


def circle_jacobian(g_ne, x, delta=None):
    """d(w_N, w_E, V)/d(g_1N, g_1E, g_2N, ...), shape (3, 6), of the 3-leg solution `x`
    (`delta`: each leg's TAS less V, as `three_leg`)."""
    g = np.asarray(g_ne, dtype=float)
    d = g - x[:2]
    radius = x[2] if delta is None else x[2] + np.asarray(delta, dtype=float)
    dfdx = np.column_stack([-2.0 * d, -2.0 * radius * np.ones(3)])
    dfdg = np.zeros((3, 6))
    for i in range(3):
        dfdg[i, 2 * i:2 * i + 2] = 2.0 * d[i]
    return -np.linalg.solve(dfdx, dfdg)


def subsets(n):
    """The 3-leg subsets of n legs: three legs alone; for four, Horton's cyclic order
    (123, 234, 341, 412); beyond, every combination, or `MAX_SUBSETS` of them drawn without
    repetition (seeded by n, so the same legs give the same answer) when there are more."""
    if n == 3:
        return [(0, 1, 2)]
    if n == 4:
        return [tuple((i + k) % 4 for k in range(3)) for i in range(4)]
    if math.comb(n, 3) <= MAX_SUBSETS:
        return list(itertools.combinations(range(n), 3))
    rng = np.random.default_rng(n)
    drawn = set()
    while len(drawn) < MAX_SUBSETS:
        drawn.update(tuple(sorted(rng.choice(n, 3, replace=False)))
                     for _ in range(MAX_SUBSETS - len(drawn)))
    return sorted(drawn)


def _conditioning(g):
    """(relative smallest singular value of the circle system, TAS DOP or inf)."""
    centred = g - g.mean(axis=0)
    scale = max(float(np.max(np.abs(centred))), 1e-12)
    a = np.column_stack([2.0 * centred / scale, np.ones(3)])
    s = np.linalg.svd(a, compute_uv=False)
    if s[-1] / s[0] < _COLLINEAR:
        return 0.0, np.inf
    jv = circle_jacobian(g, three_leg(g))[2]
    return s[-1] / s[0], float(np.sqrt(jv @ jv))


def _describe(legs, idx):
    tracks = ", ".join(f"{legs.track_deg[i]:.0f}°" for i in idx)
    return f"point {legs.point[idx[0]]} (tracks {tracks})"


def _subset_solutions(legs, idx, g, delta):
    """Solutions and leg-space Jacobians (3, 2N) of the well-conditioned subsets; the DOP."""
    sols, dops, refused = [], [], []
    jac = np.zeros((3, 2 * len(idx)))          # summed: one (3, 2N) matrix whatever N
    delta = delta if np.any(delta) else None   # one radius: the closed form, no copies
    for sub in subsets(len(idx)):
        gs = g[list(sub)]
        _, dop = _conditioning(gs)
        if not dop <= DOP_MAX:
            refused.append((sub, dop))
            continue
        ds = None if delta is None else delta[list(sub)]
        x = three_leg(gs, ds)
        dx = circle_jacobian(gs, x, ds)
        for k, leg in enumerate(sub):
            jac[:, 2 * leg:2 * leg + 2] += dx[:, 2 * k:2 * k + 2]
        sols.append(x)
        dops.append(dop)
    if not sols:
        sub, dop = refused[0]
        why = ("lie on one line in the velocity plane: no circle passes through them"
               if not np.isfinite(dop) else
               f"are nearly collinear: 1 kt of ground-velocity error would move the TAS by "
               f"{dop:.0f} kt (limit {DOP_MAX:g})")
        raise ObservabilityError(
            f"{legs.source}: {_describe(legs, idx[list(sub)])}: the legs' ground velocities "
            f"{why}; fly tracks farther apart (90-120° between legs)")
    return np.array(sols), jac / len(sols), refused, float(np.mean(dops))


def cas_from_tas_mps(tas_mps, qci_pa, ps_ind_pa, oat_k):
    """(V_c m/s, q_c Pa) of a true airspeed, the static-source error corrected.

    q_c = q_c(V_t, p_s, T_s) isentropic, with p_s = p_s,ind − (q_c − q_ci): the static port
    reads p_s,ind, and with all the position error in the static source Δp_p = q_c − q_ci, so
    the total pressure p_s,ind + q_ci is exact and q_c follows from it in closed form
    (`pitotcal.core.measurement.TotalPressureAir`).
    """
    qci_pa = np.asarray(qci_pa, dtype=float)
    air = TotalPressureAir(np.asarray(ps_ind_pa, dtype=float) + qci_pa,
                           np.asarray(oat_k, dtype=float))
    qc = air.qc_pa(np.asarray(tas_mps, dtype=float) ** 2)
    return airdata.cas_from_qc_mps(qc), qc


def solve_point(legs, label):
    """The classic solution of calibration point `label` (module docstring).

    Returns
    -------
    (PointSolution, list of str)
        The solution and its warnings.

    Raises
    ------
    ObservabilityError
        Fewer than three legs, or no 3-leg subset well conditioned (`DOP_MAX`).
    """
    from scipy.stats import t as student_t

    idx = legs.indices(label)
    n = idx.size
    if n < 3:
        raise ObservabilityError(
            f"{legs.source}: point {label} has {n} leg{'s' * (n != 1)}: three legs on "
            f"different tracks are needed to solve for TAS and wind")
    g = legs.velocity_ne_mps()[idx]
    x, sols, jac, refused, dop, delta, ratio = _per_leg_solution(legs, idx, g)
    notes = [f"{_describe(legs, idx[list(s)])}: subset left out, ground velocities nearly "
             f"collinear (TAS DOP {d:.0f} > {DOP_MAX:g})" for s, d in refused[:_MAX_NOTES]]
    if len(refused) > _MAX_NOTES:
        notes.append(f"point {label}: {len(refused) - _MAX_NOTES} more 3-leg subsets left "
                     "out, ground velocities nearly collinear")
    if math.comb(n, 3) > MAX_SUBSETS:
        notes.append(f"point {label}: {n} legs, {math.comb(n, 3)} 3-leg subsets: the mean of "
                     f"{MAX_SUBSETS} of them drawn at random (seeded, so reproducible; its "
                     "sampling error is a small part of the bound)")
    resid = np.hypot(*(g - x[:2]).T) - (x[2] + delta)
    sd = legs.groundspeed_sd_mps[idx]
    if np.all(np.isfinite(sd) & (sd > 0)):
        bound, factor, sigma = legs.sd_from, 2.0, np.repeat(sd, 2)
    elif n > 3:
        s = float(np.sqrt(np.sum(resid ** 2) / (n - 3)))
        bound, factor, sigma = "scatter", float(student_t.ppf(0.975, n - 3)), np.full(2 * n, s)
    else:
        bound, factor, sigma = "none", np.nan, np.full(2 * n, np.nan)
        notes.append(f"point {label}: three legs and no groundspeed_sd_kt: no bound (fly a "
                     f"fourth leg, or state the GPS accuracy)")
    cov = (jac * sigma ** 2) @ jac.T
    return dataclasses.replace(_finish(legs, label, idx, x, sols, cov, factor, bound, dop, g,
                                       resid, ratio), tas_offsets_mps=delta), notes


def _reference(legs, idx, ratio=0.0):
    """The point's (mean q_ci, indicated static pressure at the mean altitude, mean OAT); the
    OAT of a total-temperature column at the pressure-error ratio's true Mach."""
    qc = legs.qci_pa[idx] * (1.0 + ratio)
    return (float(np.mean(legs.qci_pa[idx])),
            float(airdata.static_pressure_pa(float(np.mean(legs.pressure_alt_m[idx])))),
            float(np.mean(legs.static_oat_k(qc, idx))))


def _tas_at_ratio(qci_pa, ps_ind_pa, oat_k, ratio):
    """TAS, m/s, of a leg whose impact pressure is q_ci (1 + ratio), the error in the static
    source: p_s = p_s,ind − q_ci ratio (module notes)."""
    qc = np.asarray(qci_pa, dtype=float) * (1.0 + ratio)
    ps = np.asarray(ps_ind_pa, dtype=float) - np.asarray(qci_pa, dtype=float) * ratio
    return airdata.mach_from_qc(qc, ps) * airdata.speed_of_sound_mps(oat_k)


def _tas_offsets(legs, idx, ratio):
    """δ_i: each leg's TAS less the point's reference TAS at the same pressure-error ratio."""
    ps_ind = airdata.static_pressure_pa(legs.pressure_alt_m[idx])
    ref = _tas_at_ratio(*_reference(legs, idx, ratio), ratio)
    oat = legs.static_oat_k(legs.qci_pa[idx] * (1.0 + ratio), idx)
    return _tas_at_ratio(legs.qci_pa[idx], ps_ind, oat, ratio) - ref


def _per_leg_solution(legs, idx, g):
    """(x, subset solutions, Jacobian, refused subsets, DOP, δ, pressure-error ratio) with each
    leg's own TAS: δ at the indicated values first, then at the ratio of the solution's TAS
    (which also sets a total-temperature column's true Mach)."""
    ratio = 0.0
    delta = _tas_offsets(legs, idx, ratio)
    sols, jac, refused, dop = _subset_solutions(legs, idx, g, delta)
    x = sols.mean(axis=0)
    if not np.any(delta) and legs.tat_k is None:
        return x, sols, jac, refused, dop, delta, ratio
    for _ in range(_TAS_ROUNDS):
        qci, ps_ind, oat = _reference(legs, idx, ratio)
        new = float(cas_from_tas_mps(x[2], qci, ps_ind, oat)[1]) / qci - 1.0
        delta, moved, ratio = _tas_offsets(legs, idx, new), abs(new - ratio), new
        if np.any(delta):
            sols, jac, refused, dop = _subset_solutions(legs, idx, g, delta)
            x = sols.mean(axis=0)
        if moved < 1e-9:
            break
    return x, sols, jac, refused, dop, delta, ratio


def _finish(legs, label, idx, x, sols, cov, factor, bound, dop, g, resid, ratio=0.0):
    """TAS → CAS and ΔV with their half-widths (dV_c/dV_t by central difference)."""
    qci, ps_ind, oat = _reference(legs, idx, ratio)
    alt = float(np.mean(legs.pressure_alt_m[idx]))
    ias_mps = float(airdata.cas_from_qc_mps(qci))
    vc, qc = cas_from_tas_mps(x[2], qci, ps_ind, oat)
    h = 1e-3
    slope = (cas_from_tas_mps(x[2] + h, qci, ps_ind, oat)[0]
             - cas_from_tas_mps(x[2] - h, qci, ps_ind, oat)[0]) / (2 * h)
    tas_half = factor * float(np.sqrt(cov[2, 2]))
    n = idx.size
    method = {3: "3-leg", 4: "4-leg"}.get(n, f"{n}-leg")
    return PointSolution(
        point=label, method=method, legs=idx, ias_kt=ias_mps / KT_TO_MPS,
        pressure_alt_m=alt, oat_k=oat, qci_pa=qci, tas_mps=float(x[2]),
        wind_n_mps=float(x[0]), wind_e_mps=float(x[1]), cov=cov, half_width_factor=factor,
        bound=bound, dop=dop,
        tas_subset_sd_mps=float(np.std(sols[:, 2], ddof=1)) if len(sols) > 1 else np.nan,
        qc_pa=float(qc), vc_kt=float(vc) / KT_TO_MPS, dv_kt=(float(vc) - ias_mps) / KT_TO_MPS,
        dv_half_kt=slope * tas_half / KT_TO_MPS, tas_half_mps=tas_half,
        naive_tas_mps=float(np.mean(np.hypot(*g.T))), residuals_mps=resid)


def solve_points(legs):
    """Every point of a `LegData`, in file order: (list of PointSolution, warnings)."""
    out, notes = [], []
    for label in legs.points():
        sol, w = solve_point(legs, label)
        out.append(sol)
        notes += w
    return out, notes
