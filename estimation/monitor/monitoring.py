"""`monitor`: near-real-time airspeed health monitoring from a calibration (paper section VI.B).

Every BLOCK_S block of the record, q_ci is predicted from GPS velocity, the tracked wind, the
calibration's pressure-error model and air data (`monitor.model.predict_qci_pa`), and the
measured q_ci is tested against it by the sequential tests of `monitor_cusum` with thresholds
from the calibration's own residual noise model. The monitor adapts: during the warm-up it learns
the flight's turbulence (residual scale and q_ci liveness) and wind, afterwards it follows them
slowly while nothing is suspect. Each alarm is classified from the data of its episode:

=========  ==========================================  ===========================================
kind       what the data showed                        size (``size_unit``)
=========  ==========================================  ===========================================
frozen     q_ci stopped following the gusts (or, in   q_ci/predicted − 1 at the end (fraction)
           calm air, the predicted speed changes)
drain      frozen, and falling below half the          q_ci/predicted − 1 at the end (fraction)
           prediction (blocked total port, drain open)
step       a jump of the residual                      the jump in q_ci/predicted (fraction)
drift      a gradual departure (icing, slow leak)      equivalent indicated airspeed rate (kt/min)
erratic    q_ci fluctuating far more than the          rms ratio of the fluctuation (x)
           turbulence explains (water in the lines)
=========  ==========================================  ===========================================
"""

from dataclasses import dataclass, field

import numpy as np

from pitotcal.core.errors import FlightDataError
from pitotcal.core.units import RHO0_KGM3, mps_to_kt

from .cusum import MonitorOptions
from ..uncertainty.block_noise import robust_std
from .model import Calibration, air_inputs, predict_qci_pa
from .blocks import BlockLoop

__all__ = ["LiveMonitor", "MonitorResult", "monitor"]


@dataclass(frozen=True)
class MonitorResult:
    """What `monitor` found.

    Attributes
    ----------
    alarms : tuple of dict
        {start_s (detection), end_s, onset_s (estimated start of the change), kind, size,
        size_unit, statistic}.
    time_s, qci_pa, predicted_pa, flagged : ndarray (N,)
        The record, the prediction with the tracked wind, and the samples inside an alarm.
    blocks : dict of ndarray
        Per block: time_s, e (relative residual), z, y, the four statistics, wind_n/e_mps.
    plan : dict
        The designed thresholds (`monitor_cusum.design`).
    noise : dict
        The calibration's noise model; `adapted` the scales at the end of the record.
    """

    alarms: tuple
    time_s: np.ndarray
    qci_pa: np.ndarray
    predicted_pa: np.ndarray
    flagged: np.ndarray
    blocks: dict
    plan: dict
    noise: dict
    adapted: dict
    options: MonitorOptions
    air_data: str
    source: str
    calibration: str
    warnings: tuple = ()
    extra: dict = field(default_factory=dict)

    @property
    def monitored_s(self):
        """Seconds of record after the warm-up (when alarms were possible)."""
        return max(0.0, float(self.time_s[-1] - self.time_s[0]) - self.options.warmup_s)

    def to_dict(self):
        """The JSON of `pitotcal monitor --json` (docs/interfaces.md)."""
        from pitotcal.io.jsonfile import json_ready
        return json_ready({
            "alarms": list(self.alarms), "source": self.source,
            "calibration": self.calibration, "air_data": self.air_data,
            "n_samples": int(self.time_s.size),
            "duration_s": float(self.time_s[-1] - self.time_s[0]),
            "warmup_s": self.options.warmup_s, "monitored_s": self.monitored_s,
            "design": self.plan, "noise_model": self.noise, "adapted": self.adapted,
            "warnings": list(self.warnings)})

    def summary(self):
        """One line per alarm (what `pitotcal monitor` prints)."""
        head = (f"{len(self.alarms)} alarm(s) in {self.monitored_s:.0f} s monitored "
                f"(after {self.options.warmup_s:g} s warm-up; designed false-alarm rate "
                f"{self.plan['false_alarms_per_hour']:g} per flight hour)")
        lines = [head]
        for a in self.alarms:
            lines.append(f"  {a['start_s']:8.1f}-{a['end_s']:8.1f} s  {a['kind']:8s} "
                         f"size {a['size']:+.3g} {a['size_unit']}  (change from "
                         f"~{a['onset_s']:.1f} s, {a['statistic']})")
        return "\n".join(lines)

    def plot(self, path=None):
        """Paper Fig. 15 style figure; saved to `path` when given."""
        from .plot import plot
        return plot(self, path)


class LiveMonitor:
    """The monitor fed as data arrive (a live stream) or all at once (`monitor`): the same
    blocks, the same tests, so a record gives the same alarms either way.

    `update(flight)` tests the blocks of `flight` (the record so far) that are complete and new,
    and returns the alarms raised by them (dicts with start_s, statistic); `result(flight)`
    finishes and returns the `MonitorResult`.
    """

    def __init__(self, calibration, options=None, air=None):
        self.cal = (calibration if isinstance(calibration, Calibration)
                    else Calibration.from_dict(calibration))
        self.opts = (options or MonitorOptions()).checked()
        self.air = air
        self.loop = BlockLoop(self.cal, self.opts)
        self.block_s = self.loop.block_s

    @property
    def n_blocks(self):
        return self.loop.n_blocks

    def update(self, flight, final=False):
        air = self.air
        if air is None and self.cal.air_data == "compressible":
            air = air_inputs(flight)
        return self.loop.update(flight, air, final=final)

    def result(self, flight, warnings=()):
        """The `MonitorResult` of everything fed (the last, incomplete block included)."""
        self.update(flight, final=True)
        trace, alarms, adapted = self.loop.snapshot(float(flight.time_s[-1]))
        air = self.air if self.air is not None or self.cal.air_data != "compressible" \
            else air_inputs(flight)
        predicted = _predicted_samples(self.cal, flight, trace, air)
        _classify(alarms, trace)
        flagged = np.zeros(flight.n, bool)
        for a in alarms:
            flagged |= (flight.time_s >= a["start_s"]) & (flight.time_s <= a["end_s"])
        extra = {"alt_m": flight.alt_m,
                 "groundspeed_mps": np.hypot(flight.gps_vn_mps, flight.gps_ve_mps)}
        return MonitorResult(tuple(alarms), flight.time_s, flight.qci_pa, predicted, flagged,
                             trace, self.loop.plan, dict(self.cal.noise), adapted, self.opts,
                             self.cal.air_data, flight.source, self.cal.source,
                             tuple(dict.fromkeys(self.cal.notes + tuple(warnings)
                                                 + tuple(flight.warnings))), extra)


def monitor(flight, calibration, options=None):
    """Test a flight's q_ci against what `calibration` predicts; alarms with kind and size.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
    calibration : Calibration or dict
        `Calibration`, or the JSON dict of `pitotcal identify --json`.
    options : MonitorOptions, optional

    Returns
    -------
    MonitorResult
    """
    cal = (calibration if isinstance(calibration, Calibration)
           else Calibration.from_dict(calibration))
    opts = (options or MonitorOptions()).checked()
    warnings = []
    air = air_inputs(flight) if cal.air_data == "compressible" else None
    if cal.air_data == "compressible" and air is None:
        warnings.append(f"{flight.source}: no static pressure/temperature or altitude for the "
                        f"compressible calibration; q_ci predicted as 1/2 rho V^2")
    live = LiveMonitor(cal, opts, air=air)
    live.update(flight, final=True)
    if live.n_blocks < 4:
        raise FlightDataError(f"{flight.source}: {live.n_blocks} usable blocks of "
                              f"{live.block_s:g} s (>= 4 samples each); the monitor needs more "
                              f"data")
    return live.result(flight, warnings)


def _predicted_samples(cal, flight, trace, air):
    """The prediction at every sample with the wind tracked up to its block (held)."""
    j = np.clip(np.searchsorted(trace["time_s"], flight.time_s), 0, trace["time_s"].size - 1)
    vd_sq = None if flight.gps_vd_mps is None else flight.gps_vd_mps ** 2
    return predict_qci_pa(cal, flight.gps_vn_mps, flight.gps_ve_mps, vd_sq, flight.rho_kgm3,
                          air, wind_ne=(trace["wind_n_mps"][j], trace["wind_e_mps"][j]))


# Innovations this much wider than their tracked scale (robust spread) are erratic: a step or a
# drift leaves them about 1 (the scale of the turbulence); water in the lines, 3 and more.
_ERRATIC_SPREAD = 2.0


def _classify(alarms, trace):
    """Kind and size of each alarm from its episode's data (module table)."""
    t, e, z = trace["time_s"], trace["e"], trace["z"]
    for a in alarms:
        stats = {a["statistic"], *a.pop("also", [])}
        inside = (t >= a["onset_s"]) & (t <= a["end_s"])
        level = float(e[inside][-1]) if inside.any() else float(e[-1])
        # erratic: the innovations inside the episode far wider than the tracked scale (their
        # robust spread about their median: the one big innovation of a jump, or a shifted
        # mean, is a step or a drift, not erratic)
        spread = robust_std(z[inside]) if inside.sum() > 2 else 0.0
        if level < -0.5:
            a.update(kind="drain", size=level, size_unit="fraction")
        elif "still" in stats or _not_following(trace, inside):
            a.update(kind="frozen", size=level, size_unit="fraction")
        elif a["statistic"] == "erratic" or spread > _ERRATIC_SPREAD:
            # (liveness rising beside a mean shift is a large leak in calm air: q_ci's own
            # noise grows relative to a lower q_ci; that is a step, not water)
            a.update(kind="erratic", size=max(spread, float(np.exp(0.5 * np.mean(
                trace["y"][inside])))) if inside.any() else spread, size_unit="x")
        else:
            window = (t >= a["onset_s"] - _FIT_BEFORE_S) & (t <= a["end_s"])
            a.update(_step_or_drift(t[window], e[window], trace["qci_pa"]))


_FIT_BEFORE_S = 60.0     # the change-point fits see this much of the record before the onset
# Frozen without the gusts to show it (calm air): over the episode the prediction moved by more
# than _MOVED of itself and the measured q_ci followed it by less than _FOLLOWS (slope of the
# block means). Measured on the T-2 maneuver in calm air (3 flights each): frozen 0.00, icing
# 4 kt/min 0.38-0.41, 2 kt/min 0.66-0.71, a 5 % leak 0.92-0.97.
_MOVED, _FOLLOWS = 0.03, 0.15


def _not_following(trace, inside):
    """The measured q_ci stayed put while the prediction moved (a frozen pitot in calm air)."""
    if inside.sum() < 8:
        return False
    pred, qci = trace["pred_pa"][inside], trace["qci_pa"][inside]
    if np.ptp(pred) < _MOVED * np.mean(pred):
        return False
    return abs(float(np.polyfit(pred, qci, 1)[0])) < _FOLLOWS


def _step_or_drift(t, e, qci_pa):
    """A step (e = b + δ after τ) or a drift (e = b + s (t − τ) after τ), whichever fits the
    episode best, τ searched over the window (least squares on the block residuals)."""
    if t.size < 4:
        return {"kind": "step", "size": float(e[-1] - e[0]) if e.size else 0.0,
                "size_unit": "fraction"}
    best = {}
    for tau in t[1:-1]:
        for kind, x in (("step", (t > tau).astype(float)), ("drift", np.maximum(t - tau, 0.0))):
            a = np.column_stack([np.ones_like(t), x])
            coef, *_ = np.linalg.lstsq(a, e, rcond=None)
            sse = float(np.sum((e - a @ coef) ** 2))
            if kind not in best or sse < best[kind][0]:
                best[kind] = (sse, float(coef[1]))
    if best["step"][0] <= best["drift"][0]:
        return {"kind": "step", "size": best["step"][1], "size_unit": "fraction"}
    # q_ci ∝ V_i²: d(V_i)/V_i = ½ d(q_ci)/q_ci
    vi_mps = np.sqrt(2.0 * float(np.median(qci_pa)) / RHO0_KGM3)
    return {"kind": "drift", "size": float(mps_to_kt(0.5 * vi_mps * best["drift"][1] * 60.0)),
            "size_unit": "kt/min"}
