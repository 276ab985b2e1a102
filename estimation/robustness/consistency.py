"""Consistency of the calibration over the flight: a step-change test.

One calibration for the whole record is the model; a leak, an iced or blocked port or a
drift that starts mid-flight breaks it while the global fit stays tight, because the
coefficients bend to absorb it. At the global optimum the residual is close to linear in the
unknowns, so the test adds one regressor, a change of scale from t0 on, dr/ds = q_ci 1[t >=
t0], to the output sensitivities and refits by one linear step: its coefficient s is the
fraction by which q_ci changed at t0, and s / sigma_s, with sigma_s from the colored-residual
covariance of the augmented fit, is close to standard normal when the calibration is one.
Beside the step, a ramp q_ci (t - t0)+ / (t_end - t0) takes a gradual change (a blockage
draining, ice growing). t0 is scanned over `ONSETS`, the whole record; the threshold is
Bonferroni over both kinds of the scan plus `MARGIN` for the noise model's heavier tails, or
Student's t at the noise model's degrees of freedom where that is larger (`t_bound`: a record
only a few turbulence correlation times long), so a clean flight is flagged at about the rate
`ALPHA` or less (measured: docs/measured.md). A q_ci that ends low against the GPS, beyond
the record's own wander, is named too (`tail_warning`). A large fall from an onset in the
second half is a collapse (`collapse_onset_s`): the identification removes that tail and says
so.

The same covariance says what the test cannot see: a step smaller than
(bound + z_POWER) sigma_s is missed more often than 1 - `POWER`, and the fit absorbs it
by moving the coefficients. When that move shifts ΔV beyond the reported 2-sigma band
somewhere in the flown range, the maneuver cannot tell such a change from the calibration
(on a one-way speed sweep a scale step from mid-flight is nearly a change of the speed
dependence), and the result says so.
"""

import numpy as np

from pitotcal.core import checks
from pitotcal.core.information import normal_isf
from pitotcal.core.measurement import flight_channels, sensitivities
from pitotcal.core.models import delta_v_kt, delta_v_kt_where_defined, get_model
from pitotcal.core.scenario import HIDES_THRESHOLD_KT

from ..uncertainty.covariance import colored_covariance
from ..uncertainty.residual_noise import block_means

__all__ = ["ALPHA", "COLLAPSE_FRACTION", "HIDDEN_RATIO", "HIDES", "HIDES_THRESHOLD_KT",
           "HIDES_THRESHOLD_MAX_KT", "KINDS", "MARGIN", "MIN_SHIFT_KT", "ONSETS", "POWER",
           "TAIL_SIGMAS", "TAIL_WINDOW_S", "check", "collapse_onset_s", "hidden_bound",
           "hidden_warning", "hides", "hides_threshold", "step_test", "tail_warning",
           "with_hides_threshold"]

# Onsets scanned, as fractions of the record, every 3 % (finer costs threshold: the Bonferroni
# bound grows with the number of alternatives): from a fifth of the record, as a change before
# it leaves too few samples to be told from the start's own transients (in 3 m/s turbulence a
# step from 2 % of the record flags every clean simulated flight), to its last 2 % (a
# blockage in the last minute of a four-minute flight is the late fault to catch).
ONSETS = np.linspace(0.2, 0.98, 27)
# The alternatives tested at each onset: a step of q_ci's scale, and a ramp (q_ci falling or
# rising steadily from the onset on, as a draining blockage or icing does).
KINDS = ("step", "ramp")
# The onsets whose missed step is stated (`hidden_warning`): up to 80 % of the record. A change
# later than that leaves one calibration for most of the record; its smallest detected size,
# from a few samples, is large and says nothing about the maneuver.
HIDDEN_LAST_ONSET = 0.8
# The false-flag rate aimed at on a consistent flight.
ALPHA = 0.01
# Standard deviations added to the Gaussian Bonferroni bound: the step's colored sigma comes
# from a one-exponential noise model fitted to a record only some 10-20 turbulence correlation
# times long, so z has heavier tails than the normal (200 clean return-sweep flights in
# 0.5 m/s turbulence: 7 beyond the bound 3.74, 3.5 %; 2 beyond 4.24, 1 %: docs/measured.md).
MARGIN = 0.5
# The detection probability at which the smallest detected step is stated.
POWER = 0.95
# Hidden when the step detected at POWER moves ΔV by more than this many times its 2-sigma
# band: a step at mid-flight of a maneuver flown as two passes over the same speeds is
# detected at (threshold + z_POWER) sigma_s = 5.0 sigma_s and leaves the fit halfway, at about
# 2.5 bands; a one-way sweep hides it at 4-6 (docs/measured.md).
HIDDEN_RATIO = 3.0
# A flagged fall of q_ci at least this large by the end of the record, from an onset in its
# second half, is a collapse (a blocked pitot draining, ice closing the inlet): q_ci 20 % low
# is V_i 11 % low, far beyond any calibration, and the record's tail is removed.
COLLAPSE_FRACTION = 0.2
# ... and so is a record whose q_ci ends, over its last `COLLAPSE_WINDOW_S`, below this
# fraction of the impact pressure the GPS and the fitted wind give (against its median over
# the record), whatever the scan's z: V_i 29 % low, a gust of 10 m/s held for seconds at 70 kt,
# four sigma of 3 m/s turbulence; a draining blockage reaches it in a drain time or so.
COLLAPSE_RATIO = 0.5
COLLAPSE_WINDOW_S = 5.0
# ... provided the fall is this many times the smoothed ratio's own spread over the record
# (robust std): on a slow aircraft in strong turbulence the smoothed ratio of a clean flight
# wanders to 0.5 (30-45 kt in 3 m/s gusts), on the T-2 maneuver its spread is ~0.02.
COLLAPSE_SIGMAS = 6.0
# A record whose q_ci ends low, over its last `TAIL_WINDOW_S`, by more than `TAIL_SIGMAS` of
# the spread of that window's running mean over the record and by more than `TAIL_MIN_FALL`
# is named (`tail_warning`): a late icing ramp of 5-7 kt/min over the last 20 % of a return
# sweep in 0.5 m/s turbulence has colored step z of -1 to -2.5 and pulls the table's low end
# 3-4 sigma, while its tail stands 2-6 spreads low; 180 clean flights: at most 2.5
# (docs/measured.md).
TAIL_WINDOW_S = 10.0
TAIL_SIGMAS = 4.0
TAIL_MIN_FALL = 0.02
# A hidden step (`HIDDEN_RATIO`) also moves ΔV by more than this, kt: below it no airspeed
# indicator shows it.
MIN_SHIFT_KT = 0.1
# The largest `hides_threshold_kt` taken, kt.
HIDES_THRESHOLD_MAX_KT = 100.0
# The words that mark the statement among a result's warnings.
HIDES = "hides in the calibration"
# The noise model of the step's variance: the identification's own (several time scales).
_WINDOW = "exponential"
# Blocks the colored variance is computed on (at most).
_BLOCKS = 1000


def check(flight, result, air_data):
    """(warnings, details): every consistency test on a converged fit.

    The change of scale (`step_test`), the abrupt jump (`estimation.robustness.jumps.jump_test`, its
    details under ``jump``) and, when neither flags the flight, whether the maneuver hides a
    change of scale from the calibration (`hidden_warning`). `details` is the result's
    `consistency` (JSON ``consistency``, docs/interfaces.md §20).
    """
    from .jumps import jump_test

    jump_note, jump = jump_test(flight)
    step_note, details = step_test(flight, result, air_data,
                                   detectable_jump_pa=jump.get("detectable_pa"))
    details["jump"] = jump
    hidden = None if jump_note else hidden_warning(flight.source, details)
    raw, width = _ratio(flight, result, air_data)
    ratio = _running(raw, width(COLLAPSE_WINDOW_S), median=True)
    healthy = np.flatnonzero(ratio >= 0.95)
    details.update(end_ratio=float(ratio[-1]), ratio_spread=_robust_std(ratio),
                   healthy_until_s=float(flight.time_s[healthy[-1]] if healthy.size
                                         else flight.time_s[0]))
    details["tail_drift"] = _tail_drift(raw, width(TAIL_WINDOW_S))
    drift = None if step_note or jump_note else tail_warning(flight.source, details,
                                                             flight.time_s[-1])
    return tuple(w for w in (step_note, jump_note, hidden, drift) if w), details


def _robust_std(x):
    return 1.4826 * float(np.median(np.abs(x - np.median(x))))


def _running(x, width, median=False):
    """A running median or mean of `width` samples (centred, the ends held)."""
    from .running import running_mean, running_median

    return running_median(x, width) if median else running_mean(x, width)


def _tail_drift(raw, width):
    """The q_ci ratio's mean over the record's last `width` samples against the spread of its
    running mean over the whole record (`TAIL_WINDOW_S`): a late fall the scan's colored sigma
    does not resolve, measured against the record's own wander at that scale."""
    end = float(np.mean(raw[-width:]))
    spread = max(_robust_std(_running(raw, width)), 1e-12)
    sigmas = (1.0 - end) / spread
    return {"window_s": TAIL_WINDOW_S, "end_ratio": end, "sigmas": float(sigmas),
            "flagged": bool(sigmas > TAIL_SIGMAS and 1.0 - end > TAIL_MIN_FALL)}


def tail_warning(source, details, end_s):
    """The warning of a record whose q_ci ends low against the GPS (`_tail_drift`), or None."""
    drift = details.get("tail_drift") or {}
    if not drift.get("flagged"):
        return None
    return (f"{source}: q_ci drifts low at the end of the record: over its last "
            f"{drift['window_s']:.0f} s (to {end_s:.0f} s) it reads "
            f"{100 * drift['end_ratio']:.1f}% of the impact pressure the GPS and the fitted "
            f"wind give (median over the record: 100%), {drift['sigmas']:.1f} times that "
            "ratio's own spread over the record: icing, a draining blockage or a leak late "
            "in the flight? The calibration may be pulled by the tail; fit the record "
            "without it (`end_s`) and compare")


def _ratio(flight, result, air_data):
    """(the ratio of q_ci to the impact pressure of GPS and fitted wind, against its median
    over the record, at each sample; the number of samples in a window of so many seconds)."""
    from pitotcal.core.measurement import as_air, tas_squared

    ch = flight_channels(flight, result.gps_noise_std_mps, air_data)
    wind_n, wind_e = result.internal_params[-2], result.internal_params[-1]
    qc = as_air(ch.air).qc_pa(tas_squared(ch.vn, ch.ve, wind_n, wind_e, ch.vd2))
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.asarray(ch.qci, float) / np.asarray(qc, float)
    ratio = np.where(np.isfinite(ratio), ratio, 1.0)
    dt = float(np.median(np.diff(flight.time_s))) if flight.n > 1 else 1.0

    def width(seconds):
        return int(np.clip(round(seconds / max(dt, 1e-9)), 1, flight.n))

    return ratio / max(float(np.median(ratio)), 1e-12), width


def step_test(flight, result, air_data, *, detectable_jump_pa=None,
              hides_threshold_kt=HIDES_THRESHOLD_KT):
    """(warning or None, details): a change of q_ci's scale during the flight.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
        The samples `result` was fitted on.
    result : IdentificationResult
    air_data : str
        As `pitotcal.core.measurement.flight_channels` takes it.
    detectable_jump_pa : float, optional
        The smallest lasting jump of q_ci the abrupt-jump test catches at its power
        (`jumps.detectable_jump_pa`, Pa); None: a sudden change is judged by this test alone.
    hides_threshold_kt : float
        The ΔV shift, kt, that a missed sudden change must exceed to be stated as hidden
        (`HIDES_THRESHOLD_KT` by default).

    Returns
    -------
    warning : str or None
        Names the onset and the size when |z| exceeds the threshold (`hidden_warning` says
        when a step the test would miss moves ΔV by several bands).
    details : dict
        ``onset_s``, ``kind``, ``step`` (fraction, q_ci low when positive), ``z``,
        ``threshold`` (`t_bound` at ``dof`` when larger than the normal bound plus `MARGIN`),
        ``dof``, ``alpha``, ``flagged``; ``undetected`` (the onset where a missed step matters most:
        ``onset_s``, ``step`` the smallest step detected at ``power``, ``dv_shift_kt`` the
        largest ΔV shift it causes, at ``vi_kt``, against ``dv_2sigma_kt`` there,
        ``k_shift_sigma`` the coefficients' shift in their own covariance) and ``hidden``
        (that shift exceeds `HIDDEN_RATIO` bands and `MIN_SHIFT_KT`).
    """
    model = get_model(result.model)
    ch = flight_channels(flight, result.gps_noise_std_mps, air_data)
    jac = sensitivities(model, result.internal_params, *ch.args)
    r = result.residuals_pa
    t = flight.time_s
    # each onset at the first sample from its fraction of the record on (never inside a gap)
    onsets = t[np.searchsorted(t, t[0] + ONSETS * (t[-1] - t[0]))]
    first = np.r_[0, np.searchsorted(t, onsets)]   # the first: the whole record
    bound = float(normal_isf(ALPHA / (2.0 * len(KINDS) * ONSETS.size)))
    scan = _scan(jac, r, _Alternatives(np.asarray(ch.qci, float), t, first), bound + MARGIN)
    threshold = max(bound + MARGIN, t_bound(ALPHA / (2.0 * len(KINDS) * ONSETS.size),
                                            scan["dof"]))
    z = scan["beta"] / scan["sigma"]
    best = scan["best"]
    kind, at = KINDS[best // ONSETS.size], best % ONSETS.size
    details = {"onset_s": float(onsets[at]), "kind": kind, "step": float(-scan["beta"][best]),
               "z": float(z[best]), "threshold": threshold, "alpha": ALPHA, "dof": scan["dof"],
               "flagged": bool(abs(z[best]) > threshold)}
    # the maneuver's geometry: the Gaussian bound of a scan of the steps it states alone
    # (`hidden_bound`), as the margin is for the noise model's tails
    n_mid = int(np.sum(ONSETS <= HIDDEN_LAST_ONSET + 1e-9))
    z_detect = hidden_bound(n_mid) + float(normal_isf(1 - POWER))
    hidden, sudden = _undetected(result, model, onsets[:n_mid], scan, z_detect,
                                 _jump_steps(np.asarray(ch.qci, float), first[1:n_mid + 1],
                                             detectable_jump_pa))
    details.update(undetected=hidden, undetected_sudden=sudden)
    details.update(hides(details, hides_threshold_kt))
    if details["flagged"]:
        return _change_warning(flight.source, details, t[-1]), details
    return None, details


def hides(details, threshold_kt=HIDES_THRESHOLD_KT):
    """{"hidden", "hides_threshold_kt"}: whether the maneuver hides a change of scale
    (`step_test`'s `details`) at the user's threshold.

    Hidden when both hold: the maneuver cannot tell a change of scale from the calibration
    (the change the scan misses moves ΔV by more than `HIDDEN_RATIO` of its band and
    `MIN_SHIFT_KT`: its geometry), and a sudden change (a leak) that neither the scan nor the
    abrupt-jump test catches moves ΔV by more than `threshold_kt` (what matters to the user).
    """
    kt = hides_threshold(threshold_kt)
    step, sudden = details["undetected"], details.get("undetected_sudden") \
        or details["undetected"]
    geometry = step["dv_shift_kt"] > max(HIDDEN_RATIO * step["dv_2sigma_kt"], MIN_SHIFT_KT)
    return {"hidden": bool(geometry and sudden["dv_shift_kt"] > kt), "hides_threshold_kt": kt}


def hides_threshold(value):
    """`hides_threshold_kt` checked: a ΔV shift in kt, > 0 and at most `HIDES_THRESHOLD_MAX_KT`
    (beyond any airspeed error a calibration is flown for: say "never" with it)."""
    return checks.number("hides_threshold_kt", value, 0.0, HIDES_THRESHOLD_MAX_KT, lo_open=True)


def _jump_steps(qci, first, detectable_pa):
    """The smallest sudden change of scale the abrupt-jump test catches from each onset (the
    first sample `first` of each), as a fraction of q_ci there (at least `jumps.MIN_STEP`,
    below which it names none); None when the test did not run."""
    from .jumps import MIN_STEP, SPAN

    if detectable_pa is None or not np.isfinite(detectable_pa):
        return None
    local = np.array([np.median(qci[max(f - 10 * SPAN, 0):f + 10 * SPAN]) for f in first])
    return np.maximum(detectable_pa / np.maximum(local, 1e-9), MIN_STEP)


def t_bound(tail, dof):
    """The |z| bound of two-sided probability 2 `tail` when the sigma comes from a noise model
    fitted with `dof` degrees of freedom (`ColoredCovariance.dof`: one per few correlation
    times of the residuals): Student's t quantile, over the t widening at 2 sigma that the
    colored covariance already carries; the normal one for infinite `dof`.

    A record only a few turbulence correlation times long (a slow aircraft in strong
    turbulence: 30-45 kt in 3 m/s gusts, correlation times of 20-30 s in a 240 s record)
    leaves the noise model's variance uncertain, and z = coefficient / sigma then has the
    t's heavy tails, not the normal's (docs/measured.md).
    """
    from pitotcal.core.information import student_t_widening
    from pitotcal.core.student_t import student_t_isf

    if not np.isfinite(dof):
        return float(normal_isf(tail))
    v = max(float(dof), 3.0)        # as the covariance's own widening takes it
    return student_t_isf(tail, v) / student_t_widening(v)


def hidden_bound(n_onsets):
    """The |z| bound of the hidden-step statement: Bonferroni over a scan of steps alone at
    `n_onsets` onsets.

    The statement is about the maneuver, whether it can tell a change of scale from
    mid-flight (a leak) from the calibration; the ramps and the onsets after
    `HIDDEN_LAST_ONSET`, scanned for late and gradual faults, raise the detection test's bound
    (from 3.49 to 3.74 sigma) but not what the maneuver can tell: at 3.74 a return sweep in
    1 m/s turbulence, which tells a mid-flight step from the calibration, would be said to
    hide one on 7 of 50 clean flights, at 3.49 on 1 of 50 (docs/measured.md).
    """
    return float(normal_isf(ALPHA / (2.0 * max(int(n_onsets), 1))))


def _change_warning(source, details, end_s):
    """The warning of a flagged change (`step_test`'s details)."""
    beta = -details["step"]
    side = "low" if beta < 0 else "high"
    if details["kind"] == "ramp":
        how = (f"from about t = {details['onset_s']:.0f} s on q_ci drifts steadily "
               f"{'down' if beta < 0 else 'up'}, {100 * abs(beta):.1f}% {side} by the end "
               f"({end_s:.0f} s)")
        cause = "gradual blockage, icing or a drift?"
    else:
        how = (f"from about t = {details['onset_s']:.0f} s to the end ({end_s:.0f} s) q_ci "
               f"reads {100 * abs(beta):.1f}% {side} against before")
        cause = "a leak, icing, blockage or drift?"
    return (f"{source}: the calibration changes during the flight: {how} "
            f"(z = {details['z']:+.1f}, beyond {details['threshold']:.1f}): {cause} One "
            "calibration for the whole record does not hold, and its bounds are not honest")


def collapse_onset_s(details, time_s):
    """Where a collapsed tail of q_ci starts (`check`'s details of the record `time_s`), or
    None.

    A collapse: a flagged fall of at least `COLLAPSE_FRACTION` from an onset in the second
    half of the record, or a record whose smoothed q_ci ends below `COLLAPSE_RATIO` of what
    the GPS gives (``end_ratio``), by more than `COLLAPSE_SIGMAS` of the smoothed ratio's
    spread (``ratio_spread``), from where it last stood at 0.95 of it (``healthy_until_s``). The cut is one
    onset of the scan earlier: the scan places an onset only to its grid, and the samples
    lost before it were healthy."""
    t0, t1 = float(time_s[0]), float(time_s[-1])
    onsets = []
    if details.get("flagged") and details["step"] >= COLLAPSE_FRACTION \
            and details["onset_s"] >= t0 + 0.5 * (t1 - t0):
        onsets.append(details["onset_s"])
    fall = 1.0 - details.get("end_ratio", 1.0)
    if fall > 1.0 - COLLAPSE_RATIO and fall > COLLAPSE_SIGMAS * details.get("ratio_spread", 0.0):
        onsets.append(details["healthy_until_s"])
    if not onsets:
        return None
    return min(onsets) - (ONSETS[1] - ONSETS[0]) * (t1 - t0)


def hidden_warning(source, details):
    """The warning of a result whose maneuver hides a step (`details` from `step_test`), or
    None: flagged, or hidden within `HIDDEN_RATIO` bands."""
    if details["flagged"] or not details["hidden"]:
        return None
    hidden = details["undetected"]
    return (f"{source}: on this maneuver a change of q_ci's scale during the flight (a leak, "
            f"icing, drift) {HIDES}: one from about t = "
            f"{hidden['onset_s']:.0f} s on is caught in {100 * POWER:.0f}% of flights only from "
            f"{100 * hidden['step']:.1f}% up, and one of that size moves dV by "
            f"{hidden['dv_shift_kt']:.2f} kt at {hidden['vi_kt']:.0f} kt{_first_order(hidden)}, "
            f"{hidden['dv_shift_kt'] / hidden['dv_2sigma_reported_kt']:.1f} times the 2-sigma "
            f"band the result reports there{_sudden(details)}; fly "
            "the speeds twice (plan a return sweep: up and back down the speed range) to tell "
            "the two apart")


def _sudden(details):
    """The warning's clause on the sudden change (a leak) both tests miss."""
    sudden = details.get("undetected_sudden")
    if not sudden:
        return ""
    return (f"; a sudden one (a leak) is caught only from {100 * sudden['step']:.1f}% up and "
            f"moves dV by {sudden['dv_shift_kt']:.2f} kt at {sudden['vi_kt']:.0f} kt, more "
            f"than the {details['hides_threshold_kt']:g} kt asked (`hides_threshold_kt`)")


def with_hides_threshold(result, threshold_kt):
    """`result` with its hidden-change statement (`hides`, `hidden_warning`) made again at
    `threshold_kt`: the consistency details carry every number it needs, so nothing is
    refitted."""
    import dataclasses

    found = result.consistency
    if not found or "undetected" not in found:
        hides_threshold(threshold_kt)
        return result
    found = {**found, **hides(found, threshold_kt)}
    jumped = bool((found.get("jump") or {}).get("flagged"))
    note = None if jumped else hidden_warning(result.source, found)
    old = [i for i, w in enumerate(result.warnings) if HIDES in w]
    warnings = [w for w in result.warnings if HIDES not in w]
    if note:            # where the statement stood, or last
        warnings.insert(old[0] if old else len(warnings), note)
    return dataclasses.replace(result, consistency=found, warnings=tuple(warnings))


def _first_order(hidden):
    """The warning's note when the shifted calibration has no V_c at some flown speeds."""
    speeds = hidden.get("first_order_vi_kt") or []
    if not speeds:
        return ""
    return (f" (to first order at {len(speeds)} of the table's speeds, "
            f"{min(speeds):.0f}-{max(speeds):.0f} kt, where it puts q_c beyond the "
            "Mach range of the pitot relations)")


class _Alternatives:
    """The alternatives' columns, never all formed: a change of scale over the whole record
    (index 0), a step g_k = q_ci 1[i >= first_k] and a ramp q_ci (t - t_k)+ / (t_end - t_k)
    at each onset k (a gradual blockage or icing, q_ci falling from t_k on; scaled so its
    coefficient is the fraction changed by the end of the record).

    Their products with the data and with each other are tail sums (from the later onset of
    the two on), so memory stays that of a few columns whatever the number of onsets."""

    def __init__(self, qci, t, first):
        self.qci, self.first, self.n = qci, first, qci.size
        self.t = t - t[0]                          # relative: the tail sums keep their digits
        self.tk = self.t[first]
        self.tk[0] = 0.0
        span = max(float(self.t[-1]), 1e-12)
        self.scale = np.r_[np.ones(first.size),
                           1.0 / np.maximum(self.t[-1] - self.tk[1:], 1e-3 * span)]
        self.on = np.r_[first, first[1:]]          # each column's first sample
        self.ramp = np.r_[np.zeros(first.size, bool), np.ones(first.size - 1, bool)]

    def column(self, j):
        g = np.where(np.arange(self.n) >= self.on[j], self.qci, 0.0)
        if self.ramp[j]:
            g = g * (self.t - self.tk[self._onset(j)]) * self.scale[j]
        return g

    def _onset(self, j):
        return j if j < self.first.size else j - self.first.size + 1

    def dot(self, x):
        """x.T @ G for x of shape (n,) or (n, p): (m,) or (m, p)."""
        x = x.reshape(self.n, -1)
        q0 = _tail(x * self.qci[:, None])[self.on]
        q1 = _tail(x * (self.qci * self.t)[:, None])[self.on]
        tk = np.array([self.tk[self._onset(j)] for j in range(self.on.size)])[:, None]
        out = np.where(self.ramp[:, None], (q1 - tk * q0) * self.scale[:, None], q0)
        return out if out.shape[1] > 1 else out[:, 0]

    def gram(self):
        """G.T @ G."""
        q2 = self.qci * self.qci
        s0, s1, s2 = (_tail(q2 * self.t ** e)[self.on] for e in range(3))
        m = self.on.size
        later = np.where(self.on[:, None] >= self.on[None, :], np.arange(m)[:, None],
                         np.arange(m)[None, :])
        tk = np.array([self.tk[self._onset(j)] for j in range(m)])
        a0, a1, a2 = s0[later], s1[later], s2[later]
        ri, rj = self.ramp[:, None], self.ramp[None, :]
        ti, tj = tk[:, None], tk[None, :]
        g = np.where(ri & rj, a2 - (ti + tj) * a1 + ti * tj * a0,
                     np.where(ri, a1 - ti * a0, np.where(rj, a1 - tj * a0, a0)))
        return g * np.outer(self.scale, self.scale)


def _tail(x):
    """Sums from each row to the end (along the first axis)."""
    return np.cumsum(x[::-1], axis=0)[::-1]


def _scan(jac, r, g, threshold):
    """The augmented fit [S, g_k] of every alternative column g_k of `g` (`_Alternatives`, the
    first a change of scale over the whole record): their coefficients, sigmas, and the
    parameter shift per unit coefficient of the plain fit that absorbs g_k.

    The white-noise sigmas come first: a step or a ramp is a low-frequency regressor, so
    under the positively correlated residuals of flight its colored sigma is larger, and
    where no white-noise |z| exceeds the threshold no colored one does. The noise-model fit,
    the test's main cost, is spent only on the alternative of the largest white-noise |z|
    when it is over the threshold: fitted to the residuals of the augmented fit there (on
    the plain fit's residuals a real step would count as noise and hide itself), the
    white-noise variance a floor.
    """
    n, p = jac.shape
    m = g.on.size
    gram = np.empty((p + m, p + m))
    gram[:p, :p] = jac.T @ jac
    gram[p:, :p] = g.dot(jac)
    gram[:p, p:] = gram[p:, :p].T
    gram[p:, p:] = g.gram()
    xr, rr = np.r_[jac.T @ r, g.dot(r)], float(r @ r)
    cols = [np.r_[np.arange(p), p + k] for k in range(m)]
    inv_k = [np.linalg.inv(gram[np.ix_(idx, idx)]) for idx in cols]
    coef = [mk @ xr[idx] for mk, idx in zip(inv_k, cols)]
    beta = np.array([c[-1] for c in coef])
    # residual sum of squares of each augmented fit by the normal equations
    s2 = np.array([max(rr - c @ xr[idx], 0.0) for c, idx in zip(coef, cols)]) / max(n - p - 1, 1)
    # rounding can make a variance of noise-free data a hair negative: zero, and no test
    sigma = np.sqrt(s2 * np.clip([mk[-1, -1] for mk in inv_k], 0.0, None))
    plain = sigma.copy()
    dof = float("inf")
    z = np.divide(np.abs(beta[1:]), sigma[1:], out=np.zeros(m - 1), where=sigma[1:] > 0)
    best = int(np.argmax(z)) + 1
    if abs(beta[best]) > threshold * sigma[best]:
        x = np.column_stack([jac, g.column(best)])
        # on block means of `b` samples: the regressors are smooth over a block (the step is
        # one jump in ~N / b blocks) and the noise model is fitted to what the blocks keep, at
        # a cost independent of N
        b = max(1, int(np.ceil(n / _BLOCKS)))
        xb = block_means(x, b)
        eb = block_means(r - x @ coef[best], b)
        colored = colored_covariance(xb, eb, window=_WINDOW, velocity=xb[:, p - 2:p])
        white, var = sigma[best] ** 2, float(colored.covariance[-1, -1])
        sigma[best] = np.sqrt(max(var, white))
        # Welch-Satterthwaite: only the part beyond the white noise's is uncertain
        if var > white:
            dof = float(colored.dof) * (var / (var - white)) ** 2
    m_inv = np.linalg.inv(gram[:p, :p])
    # how far the plain fit moves per unit of q_ci low (s = -beta): r is q_ci - predicted
    shift = (m_inv @ gram[:p, p:]).T
    return {"best": best - 1, "beta": beta[1:], "sigma": sigma[1:], "plain": plain[1:], "dof": dof,
            "shift": shift[1:],
            "shift_all": shift[0], "cov_plain": float(np.mean(s2[1:])) * m_inv}


def _dv_shift_kt(model, k_shifted, vi_kt, dv_fit_kt, first_order_kt, air_data):
    """(|ΔV shift|, kt, and where it is first order): the shifted calibration's ΔV against
    the fit's at each speed where it exists (`delta_v_kt_where_defined`), the first-order
    shift `first_order_kt` where it does not (a missed step large enough to push q_c past the
    pitot relations' Mach range is hidden all the same, and is not a reason to refuse the flight)."""
    dv = np.abs(dv_fit_kt - delta_v_kt_where_defined(model, k_shifted, vi_kt, air_data))
    linear = ~np.isfinite(dv)
    dv[linear] = np.abs(first_order_kt[linear])
    return dv, linear


def _undetected(result, model, onsets, scan, z_detect, sudden=None):
    """The onset where the smallest detected step, z_detect sigma, moves ΔV most against
    its 2-sigma band, and the numbers.

    Step and coefficients are set side by side in white noise, where the ratio of the shift
    to the band is the maneuver's geometry (a real step would widen a colored band by
    counting itself as noise, and the flight's luck would decide), and both are scaled to
    the flight's noise by the variance inflation of the identification's own colored
    covariance over its plain one (median over the coefficients): a step is a slow
    regressor like them.

    The fit that absorbs a step s at t0 sits between the calibration before (it is off it by
    the shift d_k s) and the one after (a change of scale over the whole record, d_all s): the
    error counted is the smaller of the two, so a step near either end of the record, which
    leaves one calibration for most of it, is not counted as hidden. `sudden` (one fraction
    per onset, `_jump_steps`): the abrupt-jump test's smallest caught change, which caps the
    scan's where smaller; the second of the two results returned is for that change (the
    first again when `sudden` is None).
    """
    from pitotcal.core.propagation import band as sigma_of
    from pitotcal.core.propagation import gradient

    nk = len(model.params)
    k = np.asarray(result.internal_params[:nk], dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.diag(result.internal_covariance)[:nk] \
            / np.diag(result.internal_covariance_plain)[:nk]
    ratio = ratio[np.isfinite(ratio) & (ratio > 0)]
    inflation = float(np.median(ratio)) if ratio.size else 1.0
    cov_k = inflation * scan["cov_plain"][:nk, :nk]
    rows = result.correction_table()
    vi = np.array([row["vi_kt"] for row in rows], dtype=float)
    dv_fit = delta_v_kt(model, k, vi, result.air_data)
    grad = gradient(lambda kk: delta_v_kt(model, kk, vi, result.air_data), k)
    band = np.maximum(2.0 * sigma_of(grad, cov_k), 1e-12)

    def at(i, size):
        """(ratio, numbers) of a step of `size` from onset i."""
        off = [scan["shift"][i, :nk] * size,                                   # from before
               (scan["shift"][i, :nk] - scan["shift_all"][:nk]) * size]        # from after
        shifts = [_dv_shift_kt(model, k - dk, vi, dv_fit, dk @ grad, result.air_data)
                  for dk in off]
        pick = int(np.argmin([np.max(d / band) for d, _ in shifts]))
        dk, (dv, linear) = off[pick], shifts[pick]
        j = int(np.argmax(dv / band))
        return dv[j] / band[j], {
            "onset_s": float(onsets[i]), "step": float(size), "power": POWER,
            "dv_shift_kt": float(dv[j]), "dv_2sigma_kt": float(band[j]),
            "vi_kt": float(vi[j]),
            "k_shift_sigma": float(np.sqrt(max(dk @ np.linalg.solve(cov_k, dk), 0.0))),
            # the band printed in the result's table at that speed (the warning's ratio)
            "dv_2sigma_reported_kt": float(rows[j]["dv_2sigma_kt"]),
            # speeds where the shifted calibration has no V_c (beyond the Mach range of
            # the pitot relations): its shift there is the first-order one
            "first_order_vi_kt": [float(v) for v in vi[linear]]}

    best = [None, None]
    for i in range(len(onsets)):
        size = z_detect * scan["plain"][i] * np.sqrt(inflation)
        step = at(i, size)
        quick = step if sudden is None or sudden[i] >= size else at(i, float(sudden[i]))
        for n, got in enumerate((step, quick)):
            if best[n] is None or got[0] > best[n][0]:
                best[n] = got
    return best[0][1], best[1][1]
