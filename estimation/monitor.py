"""`monitor`: near-real-time airspeed health monitoring from a calibration (paper section VI.B).

Every BLOCK_S block of the record, q_ci is predicted from GPS velocity, the tracked wind, the
calibration's pressure-error model and air data (`monitor_model.predict_qci_pa`), and the
measured q_ci is tested against it by the sequential tests of `monitor_cusum` with thresholds
from the calibration's own residual noise model. The monitor adapts: during the warm-up it learns
the flight's turbulence (residual scale and q_ci liveness) and wind, afterwards it follows them
slowly while nothing is suspect. Each alarm is classified from the data of its episode:

=========  ==========================================  ===========================================
kind       what the data showed                        size (``size_unit``)
=========  ==========================================  ===========================================
frozen     q_ci stopped following the gusts            q_ci/predicted − 1 at the end (fraction)
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

from .monitor_cusum import STATISTICS, MonitorOptions, SequentialTest, WindTracker, design
from .monitor_model import Calibration, air_inputs, block_stats, predict_qci_pa

__all__ = ["MonitorResult", "monitor"]

_DW = 0.1        # wind step for the prediction's gradient, m/s


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
        from .monitor_plot import plot
        return plot(self, path)


def _block_inputs(flight, blocks, air):
    """Block means of the prediction's inputs."""
    def mean(x):
        if x is None:
            return None
        c = np.concatenate([[0.0], np.cumsum(x)])
        return (c[blocks.stop] - c[blocks.start]) / (blocks.stop - blocks.start)

    vd_sq = None if flight.gps_vd_mps is None else mean(flight.gps_vd_mps ** 2)
    return (mean(flight.gps_vn_mps), mean(flight.gps_ve_mps), vd_sq, mean(flight.rho_kgm3),
            None if air is None else (mean(air[0]), mean(air[1])))


def _predict_block(cal, inputs, j, wind):
    """Predicted block-mean q_ci and its gradient in the wind (Pa per m/s)."""
    vn, ve, vd_sq, rho, air = inputs
    winds = np.array([wind, wind + (_DW, 0.0), wind + (0.0, _DW)])
    pick = (lambda x: None if x is None else np.full(3, x[j]))
    q = predict_qci_pa(cal, vn[j], ve[j], pick(vd_sq), rho[j],
                       None if air is None else (air[0][j], air[1][j]),
                       wind_ne=(winds[:, 0], winds[:, 1]))
    return float(q[0]), np.array([q[1] - q[0], q[2] - q[0]]) / _DW


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
    cal = calibration if isinstance(calibration, Calibration) else Calibration.from_dict(calibration)
    opts = (options or MonitorOptions()).checked()
    warnings = []
    air = air_inputs(flight) if cal.air_data == "compressible" else None
    if cal.air_data == "compressible" and air is None:
        warnings.append(f"{flight.source}: no static pressure/temperature or altitude for the "
                        f"compressible calibration; q_ci predicted as 1/2 rho V^2")
    if cal.noise.get("fallback"):
        warnings.append(f"{cal.source}: no noise_model in the calibration (written before it "
                        f"was added); residual scale from noise_std_pa, correlation assumed")
    blocks = block_stats(flight.time_s, flight.qci_pa, cal.noise.get("block_s", 0.5))
    if blocks.time_s.size < 4:
        raise FlightDataError(f"{flight.source}: {blocks.time_s.size} usable blocks of "
                              f"{cal.noise.get('block_s', 0.5):g} s (>= 4 samples each); the "
                              f"monitor needs more data")
    plan = design(opts, float(cal.noise.get("block_s", 0.5)))
    trace, alarms = _run(cal, opts, plan, flight, blocks, air)
    predicted = _predicted_samples(cal, flight, blocks, trace, air)
    _classify(alarms, trace, blocks)
    flagged = np.zeros(flight.n, bool)
    for a in alarms:
        flagged |= (flight.time_s >= a["start_s"]) & (flight.time_s <= a["end_s"])
    extra = {"alt_m": flight.alt_m,
             "groundspeed_mps": np.hypot(flight.gps_vn_mps, flight.gps_ve_mps)}
    return MonitorResult(tuple(alarms), flight.time_s, flight.qci_pa, predicted, flagged, trace,
                         plan, dict(cal.noise), trace.pop("adapted"), opts, cal.air_data,
                         flight.source, cal.source, tuple(warnings), extra)


def _run(cal, opts, plan, flight, blocks, air):
    """The block loop: predict, test, learn; the per-block trace and the raw alarms."""
    inputs = _block_inputs(flight, blocks, air)
    test = SequentialTest(cal.noise, plan, opts)
    wind = WindTracker((cal.wind_n_mps, cal.wind_e_mps))
    t0, n = float(flight.time_s[0]), blocks.time_s.size
    trace = {k: np.zeros(n) for k in ("time_s", "e", "z", "y", "pred_pa", "wind_n_mps",
                                      "wind_e_mps", *STATISTICS)}
    alarms, active, settled = [], {}, False
    block_s = plan["block_s"]
    for j in range(n):
        t = float(blocks.time_s[j])
        learning = t - t0 < opts.warmup_s
        pred, grad = _predict_block(cal, inputs, j, wind.wind)
        e = (blocks.qci_pa[j] - pred) / pred
        fired, z, y = test.step(t, e, np.log(max(blocks.band_rel_var[j], 1e-30)), learning)
        r_var = (pred * np.sqrt(test.sw2 / max(1.0 - test.a ** 2, 1e-3))) ** 2
        if not learning and not settled:
            wind.settle(grad, r_var, block_s, opts.wind_tau_s)
            settled = True
        if learning or test.quiet():
            wind.update(blocks.qci_pa[j] - pred, grad, r_var, block_s,
                        opts.warmup_wind_tau_s if learning else opts.wind_tau_s)
        for s in fired:
            active[s] = {"start_s": t, "onset_s": test.zero_s[s], "statistic": s, "end_s": t}
        for s in list(active):
            active[s]["end_s"] = t
            if s not in test.open:
                alarms.append(active.pop(s))
        for k, v in (("time_s", t), ("e", e), ("z", z), ("y", y), ("pred_pa", pred),
                     ("wind_n_mps", wind.wind[0]), ("wind_e_mps", wind.wind[1])):
            trace[k][j] = v
        for s in test.values:
            trace[s][j] = test.values[s]
    for a in active.values():          # still in alarm when the record ends
        a["end_s"] = float(flight.time_s[-1])
        alarms.append(a)
    trace["adapted"] = {"innovation_rel_std": float(np.sqrt(test.sw2)),
                        "band_log_mean": test.mu_l, "band_log_std": float(np.sqrt(test.sl2)),
                        "wind_n_mps": float(wind.wind[0]), "wind_e_mps": float(wind.wind[1])}
    return trace, _merge(sorted(alarms, key=lambda a: a["start_s"]))


_SAME_CAUSE_S = 5.0    # statistics firing this close to an episode's first one describe it too


def _merge(alarms):
    """Overlapping alarms of different statistics are one episode (the first statistic names it;
    those that fire within _SAME_CAUSE_S of it help classify it)."""
    out = []
    for a in alarms:
        if out and a["start_s"] <= out[-1]["end_s"]:
            out[-1]["end_s"] = max(out[-1]["end_s"], a["end_s"])
            if a["start_s"] - out[-1]["start_s"] <= _SAME_CAUSE_S:
                out[-1].setdefault("also", []).append(a["statistic"])
        else:
            out.append(dict(a))
    return out


def _predicted_samples(cal, flight, blocks, trace, air):
    """The prediction at every sample with the wind tracked up to its block (held)."""
    j = np.clip(np.searchsorted(blocks.time_s, flight.time_s), 0, blocks.time_s.size - 1)
    vd_sq = None if flight.gps_vd_mps is None else flight.gps_vd_mps ** 2
    return predict_qci_pa(cal, flight.gps_vn_mps, flight.gps_ve_mps, vd_sq, flight.rho_kgm3,
                          air, wind_ne=(trace["wind_n_mps"][j], trace["wind_e_mps"][j]))


def _classify(alarms, trace, blocks):
    """Kind and size of each alarm from its episode's data (module table)."""
    t, e, z = trace["time_s"], trace["e"], trace["z"]
    for a in alarms:
        stats = {a["statistic"], *a.pop("also", [])}
        inside = (t >= a["onset_s"]) & (t <= a["end_s"])
        level = float(e[inside][-1]) if inside.any() else float(e[-1])
        # erratic: the innovations inside the episode far wider than the tracked scale
        spread = float(np.sqrt(np.mean(z[inside][1:] ** 2))) if inside.sum() > 2 else 0.0
        if level < -0.5:
            a.update(kind="drain", size=level, size_unit="fraction")
        elif "still" in stats:
            a.update(kind="frozen", size=level, size_unit="fraction")
        elif "erratic" in stats or spread > 3.0:
            a.update(kind="erratic", size=max(spread, float(np.exp(0.5 * np.mean(
                trace["y"][inside])))) if inside.any() else spread, size_unit="x")
        else:
            window = (t >= a["onset_s"] - _FIT_BEFORE_S) & (t <= a["end_s"])
            a.update(_step_or_drift(t[window], e[window], blocks))


_FIT_BEFORE_S = 60.0     # the change-point fits see this much of the record before the onset


def _step_or_drift(t, e, blocks):
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
    vi_mps = np.sqrt(2.0 * float(np.median(blocks.qci_pa)) / RHO0_KGM3)
    return {"kind": "drift", "size": float(mps_to_kt(0.5 * vi_mps * best["drift"][1] * 60.0)),
            "size_unit": "kt/min"}
