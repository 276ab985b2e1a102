"""Live use of a MAVLink stream (`pitotcal.io.mavlink_live`): the airspeed monitor as data
arrive, and the calibration re-identified on the growing maneuver every second (the paper's
Fig. 6, live) until its 2σ on ΔV meets a target. Whatever ends the stream — it stops, the
connection drops, Ctrl-C — what was received is kept and the final answer is computed from it,
the same as from a file of the same samples.

The live re-identifications are warm-started (`LiveIdentifier`): one `OutputErrorProblem` is
kept for the whole stream (its built solvers and Hessian functions reused), and IPOPT starts
from the previous update's estimate. The problem has no constraints and no bounds, so there are
no multipliers to carry over (IPOPT's warm_start_init_point would have nothing to use). The
updates skip what only the final answer needs (outlier trimming and its refits, the step-change
test): the final answer is `identify` on every sample, as offline.
"""

import time
from dataclasses import dataclass

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.core.measurement import DEFAULT_AIR_DATA
from pitotcal.core.units import RHO0_KGM3, mps_to_kt
from pitotcal.io.mavlink_live import IDLE_TIMEOUT_S, read_stream

__all__ = ["LiveFix", "LiveIdentifier", "identify_stream", "monitor_stream"]

_MIN_IDENTIFY_S = 20.0      # no identification is tried on less than this much record


def monitor_stream(source, calibration, options=None, *, oat_k=None, idle_timeout_s=IDLE_TIMEOUT_S,
                   on_status=None, max_s=None):
    """Monitor a live stream; returns (MonitorResult, stream buffer).

    `on_status(text)` gets a one-line status every second (samples, q_ci measured and
    predicted, alarms so far).
    """
    from .monitor.monitoring import LiveMonitor

    live = LiveMonitor(calibration, options)
    raised = []

    def tick(buf):
        flight = buf.flight()
        raised.extend(live.update(flight))
        if on_status is not None:
            trace = live.loop.trace
            pred = trace["pred_pa"][-1] if trace["pred_pa"] else float("nan")
            alarms = ", ".join(f"{a['statistic']} at {a['start_s']:.1f} s" for a in raised)
            on_status(f"{flight.time_s[-1]:8.1f} s  {flight.n:7d} samples  q_ci "
                      f"{flight.qci_pa[-1]:7.1f} Pa  predicted {pred:7.1f} Pa  "
                      f"alarms: {alarms or 'none'}")

    buf = read_stream(source, oat_k=oat_k, idle_timeout_s=idle_timeout_s, on_tick=tick,
                      max_s=max_s)
    flight = buf.flight()
    return live.result(flight, _stop_note(buf)), buf


@dataclass(frozen=True)
class LiveFix:
    """One live re-identification: record length, ΔV and its 2σ at the middle V_i, seconds
    the update took, and whether the target was met."""

    time_s: float
    n_samples: int
    vi_kt: float
    dv_kt: float
    dv_2sigma_kt: float
    update_s: float
    target_met: bool


class LiveIdentifier:
    """Warm-started re-identification of a growing record (the live updates).

    `update(flight)` fits `flight` (the record so far) with the problem object kept from the
    previous updates and IPOPT started from their last converged estimate; it returns the
    `IdentificationResult` (its coefficients, wind and colored-residual covariance as `identify`
    computes them, without the outlier trimming and the step-change test). Model "auto" has no
    single problem to keep: its updates are cold `identify` calls.

    Parameters
    ----------
    model : str
        As `identify`.
    air : {"compressible", "incompressible"}
        As `identify` (a record without static pressure and temperature is incompressible).
    gps_error : dict, optional
        `identify`'s ``gps_error_sigma_mps`` and ``gps_error_tau_s`` (the receiver's stated
        slow velocity error), counted in every update's bounds.
    """

    def __init__(self, model="inverse", air=DEFAULT_AIR_DATA, gps_error=None):
        from .identification.oe import OutputErrorProblem

        self.model, self.air = model, air
        self.gps_error = dict(gps_error or {})
        self._stated(None)          # a bad statement is refused before any stream is read
        self.problem = None if model == "auto" else OutputErrorProblem(model)
        self.start = None           # the last converged internal parameters

    def _stated(self, flight):
        """The stated GPS error as `identify` checks it against `flight` (None: no record yet)."""
        from .identification.fit import _gps_error

        return _gps_error(self.gps_error.get("gps_error_sigma_mps"),
                          self.gps_error.get("gps_error_tau_s"), flight)

    def update(self, flight, warm=True):
        """The fit of `flight`; `warm=False` starts IPOPT from the linear least-squares start
        values (the cold start, for comparison)."""
        from .identification import fit as identification
        from .identification.identify import identify
        from .robustness import gates

        if self.problem is None:
            return identify(flight, model=self.model, air=self.air, **self.gps_error)
        air_data, _ = identification._air_data(flight, self.air)
        identification._check_flight(flight, air_data)
        flight, _ = gates.gate_flight(flight)
        identification._check_track(flight)
        result = self.problem.solve(flight, start=self.start if warm else None,
                                    air_data=air_data, gps_error=self._stated(flight))
        if result.success:
            self.start = np.asarray(result.internal_params, float)
        return result


def identify_stream(source, *, model="inverse", target_2sigma_kt=1.0, oat_k=None,
                    idle_timeout_s=IDLE_TIMEOUT_S, on_fix=None, max_s=None, air=DEFAULT_AIR_DATA,
                    gps_error=None, temp_recovery=1.0, rh_pct=None, budget=None,
                    record_options=None):
    """Re-identify the growing maneuver every second (warm-started, `LiveIdentifier`); returns
    (final result, flight, fixes, stream buffer). The final result is `identify` (with `air`,
    the stated `gps_error`, as `LiveIdentifier` takes it, the uncertainty `budget` and
    `record_options`: identify's `wind`, `wind_knot_s`, `hides_threshold_kt`) on every
    sample received, as offline, so its record (`to_dict`) has the offline record's keys. The
    air data is made as `read_flight` makes it, with `temp_recovery` and `rh_pct`, and the
    flight's `reading` records it. Bad options are refused before the stream is opened."""
    from pitotcal.core.moist_air import check_air_options, with_static_air
    from pitotcal.io import with_reading

    from .identification.identify import identify
    from .identification.identify import budget_inputs

    fixes = []
    live = LiveIdentifier(model, air, gps_error)
    temp_recovery, rh_pct = check_air_options(temp_recovery, rh_pct)
    budget = budget_inputs(budget)
    record_options = _record_options(record_options)

    def air_data(buf):
        return with_static_air(buf.flight(), temp_recovery=temp_recovery, rh_pct=rh_pct)

    def tick(buf):
        flight = air_data(buf)
        if flight.time_s[-1] - flight.time_s[0] < _MIN_IDENTIFY_S:
            return
        start = time.perf_counter()
        try:
            result = live.update(flight)
        except PitotcalError as exc:          # too little yet (e.g. no heading change)
            if on_fix is not None:
                on_fix(None, str(exc))
            return
        fix = _fix(result, flight, time.perf_counter() - start, target_2sigma_kt)
        fixes.append(fix)
        if on_fix is not None:
            on_fix(fix, None)

    buf = read_stream(source, oat_k=oat_k, idle_timeout_s=idle_timeout_s, on_tick=tick,
                      max_s=max_s)
    flight = with_reading(air_data(buf), {"start_s": None, "end_s": None, "oat_k": oat_k,
                                          "temp_recovery": temp_recovery, "rh_pct": rh_pct})
    result = identify(flight, model=model, air=air, budget=budget, **live.gps_error,
                      **record_options)
    return result, flight, fixes, buf


def _record_options(options):
    """identify's final-record options (`identify_stream`), checked before the stream opens."""
    from pitotcal.core.checks import option_dict

    from .identification.wind_drift import check_wind_options
    from .robustness.consistency import hides_threshold

    options = option_dict("record_options", options)
    unknown = sorted(set(options) - {"wind", "wind_knot_s", "hides_threshold_kt"})
    if unknown:
        raise PitotcalError(f"`record_options`: unknown key {unknown[0]!r}; known: wind, "
                            "wind_knot_s, hides_threshold_kt", param="record_options")
    check_wind_options(options.get("wind", "auto"), options.get("wind_knot_s"))
    if options.get("hides_threshold_kt") is not None:
        hides_threshold(options["hides_threshold_kt"])
    return {k: v for k, v in options.items() if v is not None}


def _fix(result, flight, update_s, target):
    vi_kt = float(mps_to_kt(np.median(np.sqrt(2.0 * np.maximum(flight.qci_pa, 0.0) / RHO0_KGM3))))
    dv, band = result.delta_v_kt(vi_kt)
    dv, band = float(np.asarray(dv)), float(np.asarray(band))
    return LiveFix(float(flight.time_s[-1]), flight.n, vi_kt, dv, band, update_s,
                   bool(band <= target))


def _stop_note(buf):
    how = {"interrupted": "Ctrl-C", "idle": "no message for the idle timeout"}.get(buf.stopped,
                                                                                buf.stopped)
    return [f"{buf.source}: stream ended ({how}) after {buf.n} samples"]
