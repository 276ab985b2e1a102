"""The monitor's sequential tests: two-sided CUSUMs on the whitened residual and on the
q_ci "liveness", with thresholds designed for a stated false-alarm rate, and the slow trackers
(residual scale, liveness level, wind) that let the monitor adapt.

Statistics, each a one-sided CUSUM S = max(0, S + x − κ), alarm at S > h (Page 1954):

* ``low`` / ``high``: x = ∓z, z = w/σ_w the block's innovation, w = e_k − Σ φ_i e_{k−i}, e the
  residual in the noise model's unit (`uncertainty.block_noise`: airspeed, m/s; relative for older
  calibrations); whitening turns the turbulence's colored residual into
  near-white innovations, so a jump shows at once in one innovation and a ramp as a growing
  mean (slow faults: a small κ).
* ``still`` / ``erratic``: x = ∓y, y = (log band variance − μ)/σ the block's liveness: a frozen
  pitot stops following the gusts (variance down to the transducer noise), water makes it
  erratic (variance up).

``low`` and ``high`` also fire on one innovation beyond ±c (a Shewhart limit beside the CUSUM,
Lucas 1982): a jump (leak, blocked port) is flagged in the block it happens in.

``ramp``: the Shiryaev–Roberts test for a ramp of e (`monitor_ramp`).

Design (`design`): RAMP_SHARE of the false-alarm budget (per flight hour) goes to the ramp
test (threshold log of its ARL₀, exact), the rest evenly to the four CUSUMs and the two
Shewhart limits; each CUSUM gets the threshold whose in-control average run
length (ARL₀) by Siegmund's approximation for N(0,1) increments,
ARL₀ ≈ (e^{2κ(h+1.166)} − 2κ(h+1.166) − 1)/(2κ²), is the inverse of its share, and c is the
normal quantile of one block's share. The monitor study measures the rate actually reached.
"""

from collections import deque
from dataclasses import dataclass

import numpy as np

from pitotcal.core.checks import number, positive
from pitotcal.core.information import normal_isf

from .ramp import RampTest, ramp_threshold

__all__ = [
    "STATISTICS",
    "MonitorOptions",
    "SequentialTest",
    "WindTracker",
    "ar_coefficients",
    "cusum_threshold",
    "design",
    "in_velocity",
    "siegmund_arl",
    "variance_ratio",
]

CUSUMS = ("low", "high", "still", "erratic")
STATISTICS = (*CUSUMS, "ramp")
_CLIP_SIGMA = 3.0          # innovations beyond this do not move the scale trackers (robust)
_PRIOR_BLOCKS = 10.0       # weight of the calibration's noise model, in blocks of evidence
_MAX_RHO_Y = 0.9           # the liveness's tracked lag-one correlation is capped here
# Share of the false-alarm budget given to the ramp test (slow faults are the hard ones: a jump
# is seen at once by several statistics); the rest is split evenly over the CUSUMs and the two
# Shewhart limits.
RAMP_SHARE = 0.5


@dataclass(frozen=True)
class MonitorOptions:
    """Settings of the monitor (defaults used in the measurements of docs/measured.md).

    Attributes
    ----------
    false_alarms_per_hour : float
        Designed false-alarm rate of all four statistics together, per flight hour.
    kappa, kappa_band : float
        CUSUM reference values, in σ of the innovation and of the liveness.
    warmup_s : float
        Start of the record where the trackers learn the flight's turbulence and wind (no alarm).
    variance_tau_s : float
        Time constant of the residual-scale tracker after the warm-up, s.
    band_tau_s : float
        Time constant of the liveness tracker after the warm-up, s: short, because the q_ci
        fluctuation relative to q_ci changes with the airspeed (a frozen pitot is seen in a
        second or two, well inside it).
    wind_tau_s, warmup_wind_tau_s : float
        Time constant of the wind tracker after / during the warm-up, s. 60 s follows a wind
        drifting 0.35 m/s per minute (the monitor study's) closely enough that the ramp test
        does not take it for a fault, and a circling aircraft's heading keeps a drift of the
        airspeed itself from being learned as wind (measured: 2 kt/min icing found as soon as
        with 180 s).
    drift_kt_per_min : float
        The drift of the indicated airspeed the ramp test is tuned to (its slope prior's
        standard deviation), kt/min.
    """

    false_alarms_per_hour: float = 0.02
    kappa: float = 0.25
    kappa_band: float = 1.0
    warmup_s: float = 30.0
    variance_tau_s: float = 120.0
    band_tau_s: float = 20.0
    wind_tau_s: float = 60.0
    warmup_wind_tau_s: float = 10.0
    drift_kt_per_min: float = 2.0

    def checked(self):
        number("false_alarms_per_hour", self.false_alarms_per_hour, 0.0, lo_open=True)
        for name in ("kappa", "kappa_band", "variance_tau_s", "band_tau_s", "wind_tau_s",
                     "warmup_wind_tau_s", "drift_kt_per_min"):
            positive(name, getattr(self, name))
        number("warmup_s", self.warmup_s, 0.0)
        return self


def in_velocity(noise):
    """Whether the noise model describes the residual in airspeed (m/s, ``"ar_mps"``) rather
    than relative to q_ci (calibrations written before it was added)."""
    return "innovation_std_mps" in noise


def ar_coefficients(noise):
    """The AR coefficients φ_1..φ_p of the residual the monitor tests: ``"ar_mps"`` (airspeed),
    else ``"ar"`` (relative; older calibrations: [``"ar1"``])."""
    if in_velocity(noise):
        return np.atleast_1d(np.asarray(noise["ar_mps"], float))
    return np.atleast_1d(np.asarray(noise.get("ar") or [noise["ar1"]], float))


def variance_ratio(phi, n_terms=4000):
    """var(e)/var(w) of the AR process e_k = Σ φ_i e_{k−i} + w_k: Σ ψ_k², ψ its impulse
    response."""
    psi = np.zeros(n_terms)
    psi[0] = 1.0
    for k in range(1, n_terms):
        m = min(k, phi.size)
        psi[k] = phi[:m] @ psi[k - m:k][::-1]
    return float(min(psi @ psi, 1e3))


def siegmund_arl(h, kappa):
    """In-control ARL of a one-sided CUSUM with N(0,1) increments (Siegmund), in samples."""
    b = 2.0 * kappa * (h + 1.166)
    return (np.expm1(b) - b) / (2.0 * kappa ** 2)


def cusum_threshold(arl_samples, kappa):
    """The h with `siegmund_arl(h, kappa)` = `arl_samples` (bisection)."""
    lo, hi = 0.0, 1.0
    while siegmund_arl(hi, kappa) < arl_samples:
        hi *= 2.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if siegmund_arl(mid, kappa) < arl_samples else (lo, mid)
    return 0.5 * (lo + hi)


def design(opts, block_s):
    """Thresholds for `opts` on blocks of `block_s`: {h: {stat: h}, kappa: {stat: κ},
    arl_hours_each, false_alarms_per_hour}."""
    share = opts.false_alarms_per_hour * (1.0 - RAMP_SHARE) / (len(CUSUMS) + 2)
    arl_blocks = 3600.0 / block_s / share
    kappas = {"low": opts.kappa, "high": opts.kappa, "still": opts.kappa_band,
              "erratic": opts.kappa_band}
    h = {s: cusum_threshold(arl_blocks, k) for s, k in kappas.items()}
    h["ramp"] = ramp_threshold(3600.0 / block_s / (opts.false_alarms_per_hour * RAMP_SHARE))
    return {"h": h,
            "kappa": kappas, "jump_sigma": float(normal_isf(1.0 / arl_blocks)),
            "arl_hours_each": 1.0 / share,
            "arl_hours_ramp": 1.0 / (opts.false_alarms_per_hour * RAMP_SHARE),
            "false_alarms_per_hour": opts.false_alarms_per_hour, "block_s": block_s}


class WindTracker:
    """A random-walk Kalman filter of the air-mass velocity (north, east) on the residual.

    The innovation r = q_ci − predicted (Pa), with gradient g = ∂q_ci/∂W (Pa per m/s), and a
    residual variance R; the random walk's variance per block is R (Δt/τ)²/|g|², which makes
    the steady gain ≈ Δt/τ: the wind follows the data with time constant τ. `settle` caps the
    covariance at that steady state (R/|g|² Δt/τ), so a change of τ takes effect at once.
    """

    def __init__(self, wind_ne, prior_std_mps=3.0):
        self.wind = np.array(wind_ne, dtype=float)
        self.p = np.eye(2) * prior_std_mps ** 2

    def settle(self, grad, r_var, dt_s, tau_s):
        """Cap the covariance at the steady state of `tau_s` (at the end of the warm-up: the
        filter must not keep its fast gain, or it would learn a slow fault as wind)."""
        gg = float(grad @ grad)
        p_steady = r_var / gg * dt_s / tau_s if gg > 0 else 0.0
        if 0.0 < 2.0 * p_steady < np.trace(self.p):
            self.p *= 2.0 * p_steady / np.trace(self.p)

    def update(self, r_pa, grad, r_var, dt_s, tau_s):
        gg = float(grad @ grad)
        if gg <= 0.0 or not np.isfinite(r_pa):
            return
        self.p = self.p + np.eye(2) * r_var * (dt_s / tau_s) ** 2 / gg
        s = float(grad @ self.p @ grad) + r_var
        gain = self.p @ grad / s
        self.wind = self.wind + gain * r_pa
        self.p = self.p - np.outer(gain, grad @ self.p)


class SequentialTest:
    """The four CUSUMs and the scale trackers, one block at a time (usable live).

    `step(t_s, e, log_band, learning)` returns the statistics that crossed their threshold at
    this block (empty tuple for none); `values` holds the statistics, `open` the ones in alarm.
    """

    def __init__(self, noise, plan, opts):
        self.plan, self.opts, self.block_s = plan, opts, plan["block_s"]
        self.phi = ar_coefficients(noise)
        self.velocity = in_velocity(noise)
        self.sw2 = float(noise["innovation_std_mps" if self.velocity
                               else "innovation_rel_std"]) ** 2
        self.e_var_ratio = variance_ratio(self.phi)
        self.mu_l = noise.get("band_log_mean")
        sl = noise.get("band_log_std")
        self.sl2 = None if sl is None else float(sl) ** 2
        self.n_seen = _PRIOR_BLOCKS if self.mu_l is not None else 0.0
        self.n_seen_w = _PRIOR_BLOCKS
        self.rho_y, self.y_prev = 0.0, None
        self.e_past = deque(maxlen=self.phi.size)     # e_{k-1}, e_{k-2}, ...
        self.ramp = RampTest(self.phi, self.block_s)
        # below these each statistic is calm: the trackers may learn, an alarm ends
        self.calm = {s: 0.5 * plan["h"][s] for s in CUSUMS}
        self.calm["ramp"] = self.ramp.calm_level(plan["h"]["ramp"])
        self.values = dict.fromkeys(STATISTICS, 0.0)
        self.zero_s = dict.fromkeys(STATISTICS, None)
        self.open = set()

    def quiet(self, stats=STATISTICS):
        """No statistic (of `stats`) above its calm level (half its threshold; the ramp
        test's: `RampTest.calm_level`): the data may teach the trackers."""
        return all(self.values[s] < self.calm[s] for s in stats)

    def step(self, t_s, e, log_band, learning, drift=0.0):
        """One block: `e` its residual (in the noise model's unit), `drift` the ramp test's
        slope prior (standard deviation, same unit per block)."""
        past = self.e_past
        z = 0.0 if len(past) < past.maxlen else \
            (e - float(self.phi @ np.fromiter(past, float))) / np.sqrt(self.sw2)
        past.appendleft(e)
        if self.mu_l is None:          # no liveness prior: the first block is the level
            self.mu_l, self.sl2, self.n_seen = log_band, 0.5 ** 2, 1.0
        y = (log_band - self.mu_l) / np.sqrt(self.sl2)
        # `still` tests the liveness whitened with its tracked lag-one correlation (~0 in
        # turbulence; in calm air the speed schedule moves the relative noise floor slowly:
        # 0.66, and the CUSUM of correlated increments ran 8x its designed false-alarm rate).
        # `erratic` keeps y: whitened, water in 1 m/s turbulence was missed in 3 of 10 flights
        y_w = y if self.y_prev is None else \
            (y - self.rho_y * self.y_prev) / np.sqrt(1.0 - self.rho_y ** 2)
        if learning or self.quiet(("low", "high", "ramp")):
            self._learn_scale(z)
        if learning or self.quiet(("still", "erratic")):
            self._learn_band(y)
        self.y_prev = y
        x = {"low": -z, "high": z, "still": -y_w, "erratic": y}
        fired = self._ramp(t_s, z, learning, drift * drift / self.sw2)
        for s in CUSUMS:
            h, k = self.plan["h"][s], self.plan["kappa"][s]
            v = max(0.0, self.values[s] + x[s] - k)
            if learning:
                v = min(v, 0.5 * h)       # warm-up: no alarm, and no debt carried out of it
            if v == 0.0 or self.zero_s[s] is None:
                self.zero_s[s] = t_s
            jump = s in ("low", "high") and x[s] > self.plan["jump_sigma"] and not learning
            if (v > h or jump) and s not in self.open:
                self.open.add(s)
                fired.append(s)
                v = max(v, h)                  # held in alarm until the evidence is gone
            self.values[s] = min(v, 1.5 * h)   # capped so that an alarm can end
            if s in self.open and self.values[s] < 0.5 * h:
                self.open.discard(s)
        return tuple(fired), z, y

    def _ramp(self, t_s, z, learning, v):
        """The ramp test: fires at log R > h, ends below its calm level; onset the likeliest τ."""
        g, m, _ = self.ramp.update(z, v)
        h = self.plan["h"]["ramp"]
        self.values["ramp"] = min(g, self.calm["ramp"]) if learning else g
        if learning:
            return []
        fired = []
        if g > h and "ramp" not in self.open:
            self.open.add("ramp")
            self.zero_s["ramp"] = t_s - m * self.block_s
            fired.append("ramp")
        elif "ramp" in self.open and g < self.calm["ramp"]:
            self.open.discard("ramp")
        return fired

    # Robust running means, fast at first (1/n), then with their time constants.
    def _learn_scale(self, z):
        self.n_seen_w += 1.0
        wz = max(1.0 / self.n_seen_w, self.block_s / self.opts.variance_tau_s)
        self.sw2 *= 1.0 + wz * (min(z * z, _CLIP_SIGMA ** 2) - 1.0)

    def _learn_band(self, y):
        self.n_seen += 1.0
        wy = max(1.0 / self.n_seen, self.block_s / self.opts.band_tau_s)
        yc = float(np.clip(y, -_CLIP_SIGMA, _CLIP_SIGMA))
        if self.y_prev is not None:
            yp = float(np.clip(self.y_prev, -_CLIP_SIGMA, _CLIP_SIGMA))
            self.rho_y = float(np.clip(self.rho_y + wy * (yc * yp - self.rho_y), 0.0, _MAX_RHO_Y))
        self.mu_l += wy * yc * np.sqrt(self.sl2)
        self.sl2 *= 1.0 + wy * (yc * yc - 1.0)
