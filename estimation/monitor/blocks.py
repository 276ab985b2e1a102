"""The monitor's block loop, resumable: blocks are tested as they complete, so a live stream
and a file of the same samples give the same alarms (`estimation.monitor.monitoring.LiveMonitor`).

Each block: the predicted block-mean q_ci and its gradient in the wind (`uncertainty.block_noise`), the
relative residual, one step of the sequential tests (`monitor_cusum.SequentialTest`), and — while
nothing is suspect — one step of the wind tracker (fast during the warm-up, then slow).
"""

import numpy as np

from pitotcal.core.units import kt_to_mps

from .cusum import STATISTICS, SequentialTest, WindTracker, design
from ..uncertainty.block_noise import airspeed_residual_mps, block_stats
from .model import predict_qci_pa

__all__ = ["BlockLoop"]

_DW = 0.1                # wind step for the prediction's gradient, m/s
_SAME_CAUSE_S = 5.0      # statistics firing this close to an episode's first one describe it too
_TRACE = ("time_s", "e", "z", "y", "pred_pa", "qci_pa", "wind_n_mps", "wind_e_mps", *STATISTICS)


class BlockLoop:
    """The tests and trackers of one record, fed block by block (`update`)."""

    def __init__(self, cal, opts):
        self.cal, self.opts = cal, opts
        self.block_s = float(cal.noise.get("block_s", 0.5))
        self.plan = design(opts, self.block_s)
        self.test = SequentialTest(cal.noise, self.plan, opts)
        self.wind = WindTracker((cal.wind_n_mps, cal.wind_e_mps))
        self.drift_mps = kt_to_mps(opts.drift_kt_per_min) / 60.0 * self.block_s
        self.trace = {k: [] for k in _TRACE}
        self.alarms, self.active, self.settled = [], {}, False
        self.t0 = None
        self.next_s = None          # start of the first block not yet tested

    @property
    def n_blocks(self):
        return len(self.trace["time_s"])

    def update(self, flight, air=None, final=False):
        """Test the complete blocks of `flight` not tested yet (with `final`, the last one
        too); returns the alarms they raised."""
        t = flight.time_s
        if t.size == 0:
            return []
        if self.t0 is None:
            self.t0 = self.next_s = float(t[0])
        first = int(np.searchsorted(t, self.next_s - 1e-9))
        if first >= t.size:
            return []
        blocks = block_stats(t[first:], flight.qci_pa[first:], self.block_s, t0=self.t0)
        if blocks.time_s.size == 0:
            return []
        ends = self.t0 + (np.floor((blocks.time_s - self.t0) / self.block_s + 1e-9) + 1) * \
            self.block_s
        done = np.ones(blocks.time_s.size, bool) if final else ends <= t[-1] + 1e-9
        if not done.any():
            return []
        n = int(np.flatnonzero(done)[-1]) + 1
        self.next_s = float(ends[n - 1])
        inputs = _block_inputs(flight, blocks, air, first)
        new = []
        for j in range(n):
            new.extend(self._step(blocks, inputs, j))
        return new

    def _step(self, blocks, inputs, j):
        """One block: predict, test, learn, record; the alarms raised."""
        opts, test, wind = self.opts, self.test, self.wind
        t = float(blocks.time_s[j])
        learning = t - self.t0 < opts.warmup_s
        pred, grad = _predict_block(self.cal, inputs, j, wind.wind)
        e = (blocks.qci_pa[j] - pred) / pred
        # the tests run on the residual in the noise model's unit: airspeed (turbulence and
        # icing act on the speed, not on q_ci's fraction) or, for older calibrations, relative
        mps_per_e = float(airspeed_residual_mps(1.0, pred))
        per_e, drift = (mps_per_e, self.drift_mps) if test.velocity else \
            (1.0, self.drift_mps / mps_per_e)
        fired, z, y = test.step(t, e * per_e, np.log(max(blocks.band_rel_var[j], 1e-30)),
                                learning, drift)
        r_var = (pred / per_e) ** 2 * test.sw2 * test.e_var_ratio
        if not learning and not self.settled:
            wind.settle(grad, r_var, self.block_s, opts.wind_tau_s)
            self.settled = True
        if learning or test.quiet():
            wind.update(blocks.qci_pa[j] - pred, grad, r_var, self.block_s,
                        opts.warmup_wind_tau_s if learning else opts.wind_tau_s)
        raised = []
        for s in fired:
            self.active[s] = {"start_s": t, "onset_s": test.zero_s[s], "statistic": s,
                              "end_s": t}
            raised.append(self.active[s])
        for s in list(self.active):
            self.active[s]["end_s"] = t
            if s not in test.open:
                self.alarms.append(self.active.pop(s))
        for k, v in (("time_s", t), ("e", e), ("z", z), ("y", y), ("pred_pa", pred),
                     ("qci_pa", blocks.qci_pa[j]), ("wind_n_mps", wind.wind[0]),
                     ("wind_e_mps", wind.wind[1]), *test.values.items()):
            self.trace[k].append(float(v))
        return raised

    def snapshot(self, end_s):
        """(trace as arrays, alarms merged into episodes, adapted scales and wind); alarms
        still open end at `end_s`. The loop can go on being fed afterwards."""
        open_now = [{**a, "end_s": end_s} for a in self.active.values()]
        alarms = _merge(sorted([dict(a) for a in self.alarms] + open_now,
                               key=lambda a: a["start_s"]))
        trace = {k: np.asarray(v, float) for k, v in self.trace.items()}
        scale = "innovation_std_mps" if self.test.velocity else "innovation_rel_std"
        adapted = {scale: float(np.sqrt(self.test.sw2)),
                   "band_log_mean": self.test.mu_l,
                   "band_log_std": float(np.sqrt(self.test.sl2 or 0.0)),
                   "wind_n_mps": float(self.wind.wind[0]),
                   "wind_e_mps": float(self.wind.wind[1])}
        return trace, alarms, adapted


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


def _block_inputs(flight, blocks, air, offset):
    """Block means of the prediction's inputs (`blocks` index the samples from `offset` on)."""
    start, stop = blocks.start + offset, blocks.stop + offset

    def mean(x):
        if x is None:
            return None
        c = np.concatenate([[0.0], np.cumsum(x[offset:stop[-1]])])
        return (c[stop - offset] - c[start - offset]) / (stop - start)

    vd_sq = None if flight.gps_vd_mps is None else mean(flight.gps_vd_mps ** 2)
    return (mean(flight.gps_vn_mps), mean(flight.gps_ve_mps), vd_sq, mean(flight.rho_kgm3),
            None if air is None else type(air)(*map(mean, air)))


def _predict_block(cal, inputs, j, wind):
    """Predicted block-mean q_ci and its gradient in the wind (Pa per m/s)."""
    vn, ve, vd_sq, rho, air = inputs
    winds = np.array([wind, wind + (_DW, 0.0), wind + (0.0, _DW)])

    def pick(x):
        return None if x is None else np.full(3, x[j])

    q = predict_qci_pa(cal, vn[j], ve[j], pick(vd_sq), rho[j],
                       None if air is None else type(air)(*(c[j] for c in air)),
                       wind_ne=(winds[:, 0], winds[:, 1]))
    return float(q[0]), np.array([q[1] - q[0], q[2] - q[0]]) / _DW
