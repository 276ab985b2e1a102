"""Auto-throttle: a PI speed loop, its tuning, and a linear check against a plan's schedule.

The paper flew its schedules by hand to +-5 KCAS and recommends an auto-throttle (section V).
Model of the speed loop, per unit mass, around the trim true airspeed V0::

    thrust' = (thrust_cmd - thrust) / tau_e                    (engine lag)
    V'      = thrust - D(V) - u_g'                             (u_g: gust along the path)
    D(V)    = g / (L/D) * (V / V0)^2   ->   dD/dV = X_u = 2 g / ((L/D) V0)   at trim

so the plant from thrust command to airspeed is P(s) = 1 / ((tau_e s + 1)(s + X_u)). The
auto-throttle is thrust_cmd = [D(V_ref) + V_ref'](t + tau_e) + C(s) (V_ref - V) (feed-forward read
one engine lag ahead from the known schedule) with a PI
C(s) = Kp (1 + w_i / s), tuned for a phase margin at the highest crossover a PI can reach with
w_i a fixed fraction of the crossover. The simulator (maneuvers.fly.guidance) flies the same loop,
with the nonlinear drag, thrust limits and anti-windup.

Tuning and check are plain numpy (closed-form crossover, an exact first-order-hold simulation
of the linear loop), so `pitotcal plan` does not import python-control or scipy (1.7 s, most
of the command's time); the tests re-tune and re-simulate with python-control and compare.
`speed_plant` still gives the python-control transfer function for analysis.
"""

import math
from dataclasses import dataclass

import numpy as np

from pitotcal.core.checks import number, positive
from pitotcal.core.dynamics import Limits
from pitotcal.core.linear import expm
from pitotcal.core.speeds import cas_from_tas_mps
from pitotcal.core.units import G0_MPS2, mps_to_kt

__all__ = [
    "AutothrottleCheck",
    "SpeedLoop",
    "autothrottle_report",
    "check_autothrottle",
    "speed_plant",
    "tune_autothrottle",
]

# The plan command's report: the loop in still air and in this light turbulence (paper: light)
REPORT_TURBULENCE_MPS = 0.5


@dataclass(frozen=True)
class SpeedLoop:
    """Speed-loop model and PI gains (SI; thrust and drag per unit mass, m/s^2).

    Attributes
    ----------
    trim_tas_mps : float
        Trim true airspeed V0 where the drag is linearised, m/s.
    engine_lag_s : float
        Engine (thrust) time constant, s.
    lift_to_drag : float
        L/D at trim: the trim drag is g / (L/D).
    kp : float
        Proportional gain, (m/s^2) per (m/s).
    ki : float
        Integral gain, (m/s^2) per m.
    crossover_rad_s, phase_margin_deg, gain_margin_db : float
        The tuned loop's crossover and margins (python-control's `stability_margins` gives
        the same, tests/maneuvers/test_autothrottle.py).
    """

    trim_tas_mps: float
    engine_lag_s: float
    lift_to_drag: float
    kp: float
    ki: float
    crossover_rad_s: float = float("nan")
    phase_margin_deg: float = float("nan")
    gain_margin_db: float = float("inf")

    @property
    def drag_slope_per_s(self):
        """X_u = dD/dV at trim, 1/s."""
        return 2.0 * G0_MPS2 / (self.lift_to_drag * self.trim_tas_mps)

    def drag_mps2(self, tas_mps):
        """Drag per unit mass (parasite, quadratic in airspeed), m/s^2."""
        return G0_MPS2 / self.lift_to_drag * (np.asarray(tas_mps) / self.trim_tas_mps) ** 2


def speed_plant(trim_tas_mps, engine_lag_s=1.5, lift_to_drag=8.0):
    """P(s) = 1 / ((tau_e s + 1)(s + X_u)) from thrust command to airspeed, python-control tf."""
    import control

    x_u = 2.0 * G0_MPS2 / (lift_to_drag * trim_tas_mps)
    return control.tf([1.0], np.polymul([engine_lag_s, 1.0], [1.0, x_u]))


def _crossover_rad_s(engine_lag_s, drag_slope_per_s, lag_budget_rad):
    """The w solving atan(tau w) + atan(w / X_u) = budget, 0 < budget < pi, in closed form.

    With a = tau, b = 1 / X_u the tangent addition formula gives T a b w^2 + (a + b) w - T = 0,
    T = tan(budget); its positive root on the right branch is 2 T / ((a + b) + sign(T) sqrt(D)).
    """
    a, b = engine_lag_s, 1.0 / drag_slope_per_s
    if abs(lag_budget_rad - 0.5 * math.pi) < 1e-12:
        return 1.0 / math.sqrt(a * b)
    tan_b = math.tan(lag_budget_rad)
    root = math.sqrt((a + b) ** 2 + 4.0 * tan_b * tan_b * a * b)
    return 2.0 * tan_b / ((a + b) + math.copysign(root, tan_b))


def _gain_margin_db(kp, w_i, engine_lag_s, x_u):
    """20 log10(1 / |L|) where the phase of L = Kp (s + w_i) / (s (tau s + 1)(s + X_u)) is -180°.

    The phase -[atan(w_i/w) + atan(tau w) + atan(w/X_u)] tends to -180° from above unless
    w_i > 1/tau + X_u: then it crosses once, found by bisection in log frequency.
    """
    if w_i <= 1.0 / engine_lag_s + x_u:
        return math.inf

    def excess(w):
        return math.atan(w_i / w) + math.atan(engine_lag_s * w) + math.atan(w / x_u) - math.pi

    lo, hi = 1e-6, 1e6                                     # excess < 0 at lo, > 0 at hi
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if excess(mid) < 0 else (lo, mid)
    w = math.sqrt(lo * hi)
    mag = kp * math.hypot(w, w_i) / (w * math.hypot(1.0, engine_lag_s * w) * math.hypot(w, x_u))
    return -20.0 * math.log10(mag)


def tune_autothrottle(trim_tas_mps, *, engine_lag_s=1.5, lift_to_drag=8.0,
                      phase_margin_deg=60.0, integral_ratio=0.2):
    """Tune the PI auto-throttle on the linearised speed loop.

    Parameters
    ----------
    trim_tas_mps : float
        Trim true airspeed, m/s (> 0).
    engine_lag_s : float
        Engine time constant, s (> 0).
    lift_to_drag : float
        L/D at trim (> 0).
    phase_margin_deg : float
        Required phase margin, degrees (0-90).
    integral_ratio : float
        w_i / w_c: the PI zero as a fraction of the crossover (its phase lag is atan(ratio)).

    Returns
    -------
    SpeedLoop

    Notes
    -----
    The crossover w_c solves atan(tau_e w_c) + atan(w_c / X_u) + atan(ratio) = 180 - PM, the
    highest crossover with that margin (in closed form, `_crossover_rad_s`); then
    Kp = 1 / |C'(j w_c) P(j w_c)| with C' = 1 + w_i/s, i.e.
    Kp = w_c |j tau w_c + 1| |j w_c + X_u| / |j w_c + w_i|. The margins are those of this loop
    (python-control's `stability_margins` agrees, tests/maneuvers/test_autothrottle.py).
    """
    for name, value in (("trim_tas_mps", trim_tas_mps), ("engine_lag_s", engine_lag_s),
                        ("lift_to_drag", lift_to_drag), ("integral_ratio", integral_ratio)):
        positive(name, value)
    number("phase_margin_deg", phase_margin_deg, 0.0, 90.0, lo_open=True, hi_open=True)
    x_u = 2.0 * G0_MPS2 / (lift_to_drag * trim_tas_mps)
    lag_budget = math.radians(180.0 - phase_margin_deg) - math.atan(integral_ratio)
    w_c = _crossover_rad_s(engine_lag_s, x_u, lag_budget)
    w_i = integral_ratio * w_c
    kp = w_c * math.hypot(1.0, engine_lag_s * w_c) * math.hypot(w_c, x_u) / math.hypot(w_c, w_i)
    phase_deg = math.degrees(math.atan(w_c / w_i) - 0.5 * math.pi - math.atan(engine_lag_s * w_c)
                             - math.atan(w_c / x_u))
    return SpeedLoop(float(trim_tas_mps), float(engine_lag_s), float(lift_to_drag), kp,
                     kp * w_i, w_c, 180.0 + phase_deg,
                     _gain_margin_db(kp, w_i, engine_lag_s, x_u))


@dataclass(frozen=True)
class AutothrottleCheck:
    """The linear auto-throttle flown against a plan's CAS schedule.

    Attributes
    ----------
    time_s, cas_cmd_mps, cas_mps : ndarray (N,)
        Schedule and response (calibrated airspeed, m/s).
    error_kt : ndarray (N,)
        cas - cas_cmd, knots.
    max_error_kt, rms_error_kt : float
        Peak and RMS tracking error, knots.
    tolerance_kt : float
        The criterion (paper: +-5 KCAS).
    success : bool
        max_error_kt <= tolerance_kt.
    max_thrust_cmd_mps2 : float
        Peak commanded thrust per unit mass, to compare with the engine's capability.
    loop : SpeedLoop
    """

    time_s: np.ndarray
    cas_cmd_mps: np.ndarray
    cas_mps: np.ndarray
    error_kt: np.ndarray
    max_error_kt: float
    rms_error_kt: float
    tolerance_kt: float
    success: bool
    max_thrust_cmd_mps2: float
    loop: SpeedLoop

    def summary(self):
        lp = self.loop
        return (f"auto-throttle: Kp {lp.kp:.3g} 1/s, Ki {lp.ki:.3g} 1/s^2, crossover "
                f"{lp.crossover_rad_s:.3g} rad/s, phase margin {lp.phase_margin_deg:.0f} deg; "
                f"CAS error max {self.max_error_kt:.2f} kt, rms {self.rms_error_kt:.2f} kt "
                f"({'within' if self.success else 'OUTSIDE'} +-{self.tolerance_kt:g} KCAS)")


def _lsim_foh(a, b, c, d, dt_s, u):
    """Response from rest of x' = a x + b u, y = c x + d u to the inputs `u` (N, m) sampled
    every `dt_s` and linear in between: exact (python-control's `forced_response`)."""
    n, m = a.shape[0], b.shape[1]
    block = np.zeros((n + 2 * m, n + 2 * m))
    block[:n, :n], block[:n, n:n + m] = a * dt_s, b * dt_s
    block[n:n + m, n + m:] = np.eye(m)
    e = expm(block)
    ad, bd1 = e[:n, :n], e[:n, n + m:]
    drive = u[:-1] @ (e[:n, n:n + m] - bd1).T + u[1:] @ bd1.T
    x = np.zeros((u.shape[0], n))
    for k in range(u.shape[0] - 1):
        x[k + 1] = ad @ x[k] + drive[k]
    return x @ c.T + u @ d.T


def _closed_loop(loop):
    """The linear speed loop as (a, b, c, d): states thrust, V - V0 + u_g, the PI integral;
    inputs the reference and the feed-forward (both relative to their first values) and the
    gust u_g; outputs V - V0 and the thrust command relative to its first value.

    With y = dV + u_g the gust needs no derivative: y' = thrust - X_u y + X_u u_g.
    """
    kp, ki, tau, x_u = loop.kp, loop.ki, loop.engine_lag_s, loop.drag_slope_per_s
    a = np.array([[-1.0 / tau, -kp / tau, ki / tau], [1.0, -x_u, 0.0], [0.0, -1.0, 0.0]])
    b = np.array([[kp / tau, 1.0 / tau, kp / tau], [0.0, 0.0, x_u], [1.0, 0.0, 1.0]])
    c = np.array([[0.0, 1.0, 0.0], [0.0, -kp, ki]])
    d = np.array([[0.0, 0.0, -1.0], [kp, 1.0, kp]])
    return a, b, c, d


def check_autothrottle(plan, loop=None, *, turbulence_mps=0.0, turbulence_length_m=None,
                       seed=0, rate_hz=10.0, limits=None):
    """Simulate the linear auto-throttle loop against `plan`'s CAS schedule.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
    loop : SpeedLoop, optional
        Default: `tune_autothrottle` at the plan's mid-range true airspeed.
    turbulence_mps : float
        RMS of the along-path Dryden gust (MIL-F-8785C at the plan's altitude), m/s.
    turbulence_length_m : float, optional
        Gust scale length override, m.
    seed : int
        Seed of the gust noise.
    rate_hz : float
        Simulation rate, Hz.
    limits : Limits, optional
        For the tolerance (default Limits().cas_tolerance_kt: the paper's 5 KCAS).

    Returns
    -------
    AutothrottleCheck

    Notes
    -----
    The loop of `_closed_loop`, from rest, driven by the reference (through T = CP/(1+CP)),
    the feed-forward D(V_ref) + V_ref' (through P/(1+CP)) and the gust (through
    -s/(s+X_u)/(1+CP)), each linear between the samples. CAS follows TAS by the standard law
    at the plan's altitude (`pitotcal.core.speeds`).
    """
    from ..turbulence import along_path_gust, dryden_scales

    limits = limits or Limits()
    rate_hz = positive("rate_hz", rate_hz)
    t = np.arange(plan.time_s[0], plan.time_s[-1] + 0.5 / rate_hz, 1.0 / rate_hz)
    tas_ref = np.interp(t, plan.time_s, plan.tas_mps)
    if loop is None:
        loop = tune_autothrottle(0.5 * (tas_ref.min() + tas_ref.max()))
    v0 = loop.trim_tas_mps
    # Feed-forward relative to the trim thrust D(V0), with the linearised drag so that the
    # loop starts in equilibrium at the schedule's first speed (zero state, inputs - inputs[0]).
    ff = loop.drag_slope_per_s * (tas_ref - v0) + np.gradient(tas_ref, t)
    # read one engine lag ahead, as the simulator's auto-throttle does (the schedule is known)
    ff = ff[np.minimum(np.arange(t.size) + round(loop.engine_lag_s * rate_hz), t.size - 1)]
    gust = np.zeros(t.size)
    if turbulence_mps > 0:
        scales = dryden_scales(max(float(np.mean(plan.alt_m)), 0.0), turbulence_mps,
                               turbulence_length_m)
        gust = along_path_gust(t.size, 1.0 / rate_hz, scales, float(np.mean(tas_ref)),
                               np.random.default_rng(seed))
    ref = tas_ref - v0
    out = _lsim_foh(*_closed_loop(loop), (t[-1] - t[0]) / (t.size - 1),
                    np.column_stack([ref - ref[0], ff - ff[0], gust]))
    tas = v0 + ref[0] + out[:, 0]
    thrust_cmd = loop.drag_mps2(v0) + ff[0] + out[:, 1]
    alt_m = np.interp(t, plan.time_s, plan.alt_m)
    cas_cmd, cas = cas_from_tas_mps(tas_ref, alt_m), cas_from_tas_mps(tas, alt_m)
    err_kt = mps_to_kt(cas - cas_cmd)
    max_err = float(np.max(np.abs(err_kt)))
    return AutothrottleCheck(t, cas_cmd, cas, err_kt, max_err,
                             float(np.sqrt(np.mean(err_kt ** 2))), limits.cas_tolerance_kt,
                             bool(max_err <= limits.cas_tolerance_kt),
                             float(np.max(thrust_cmd)), loop)


def autothrottle_report(plan):
    """One line for the plan command: the tuned loop and its CAS error in still air and in
    light turbulence (REPORT_TURBULENCE_MPS), against the paper's ±5 KCAS."""
    calm = check_autothrottle(plan)
    rough = check_autothrottle(plan, turbulence_mps=REPORT_TURBULENCE_MPS)
    ok = calm.success and rough.success
    return (f"auto-throttle check (PI, Kp {calm.loop.kp:.3g} 1/s, Ki {calm.loop.ki:.3g} 1/s², "
            f"{calm.loop.phase_margin_deg:.0f}° phase margin): CAS error max "
            f"{calm.max_error_kt:.1f} kt in still air, {rough.max_error_kt:.1f} kt in "
            f"{REPORT_TURBULENCE_MPS:g} m/s turbulence: {'within' if ok else 'OUTSIDE'} "
            f"±{calm.tolerance_kt:g} KCAS")
