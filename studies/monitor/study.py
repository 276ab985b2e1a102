"""`monitor`: false alarms per flight hour on clean flights and detection delay per fault, for
`pitotcal monitor` and a fixed-threshold check in the style of the autopilots (same flights).

One calibration flight (the T-2 maneuver in 0.5 m/s turbulence, seed CAL_SEED) is identified;
every run flies the maneuver again with its own seed in one of CONDITIONS (calm, 0.5 and 1 m/s
turbulence, a different and drifting wind) and monitors it clean, then with each fault of
FAULTS from ONSET_S on (maneuvers.fly.faults; the aircraft flies on as planned). The clean flight is
monitored at several designed false-alarm rates, so the measured rate can be checked against
the design where alarms are frequent enough to count, and the design extrapolated to where they
are not; the one-sided 95 % Poisson upper bound states what the hours flown show alone. Leak
and icing faults are also given to an oracle (`monitor_oracle`): the delay no detector can
expect to beat at the same false-alarm rate.
"""

import functools

import numpy as np

from ..engine.common import column, get_flight, group
from ..engine.figures import new_figure, save
from .baseline import fixed_threshold_alarms
from ..engine.study import MonteCarloStudy

__all__ = ["CONDITIONS", "DESIGN_RATES", "FAULTS", "STUDY"]

CAL_SEED = 10_000
ONSET_S = 60.0
DESIGN_RATES = (0.02, 0.2, 2.0, 20.0)          # per flight hour; 0.02 is the default
GATES_MPS = (5.0, 2.0)                          # PX4 ASPD_FS_INNOV default, and a tight gate
CONDITIONS = {
    "calm": {"turbulence_mps": 0.0},
    "turb-0.5": {"turbulence_mps": 0.5},
    "turb-1.0": {"turbulence_mps": 1.0},
    # the calibration was flown in 5 m/s from 270°: 7 m/s from 250°, drifting 1.4 m/s in 240 s
    "wind-drift": {"turbulence_mps": 0.5, "wind_speed_mps": 7.0, "wind_from_deg": 250.0,
                   "wind_drift_mps2": (0.004, -0.004)},
}
FAULT_CONDITIONS = ("calm", "turb-0.5", "turb-1.0")
# clean-only flights per condition per run of the grid: at 30 runs, 210 flights and 12.25
# monitored hours per condition (the target: < 1 false alarm per 10 flight-hours)
EXTRA_CLEAN = 6
# (kind, size, the classification that is right for it)
FAULTS = (("blocked", 0.0, "frozen"), ("blocked", 3.0, "drain"),
          ("leak", 0.02, "step"), ("leak", 0.05, "step"), ("leak", 0.1, "step"),
          ("leak", 0.2, "step"), ("icing", 0.5, "drift"), ("icing", 1.0, "drift"),
          ("icing", 2.0, "drift"), ("icing", 4.0, "drift"), ("water", 0.02, "erratic"),
          ("water", 0.05, "erratic"), ("static", 0.0, None))
QUICK_FAULTS = (("blocked", 0.0, "frozen"), ("leak", 0.1, "step"), ("icing", 2.0, "drift"))
ORACLE_KINDS = ("leak", "icing")
_HELD_WIND_TAU_S = 1e9          # the oracle's wind: learned in the warm-up, then held
TARGETS = {"false_alarms_per_hour_turb_1.0": 0.1, "frozen_s": 5.0, "leak_0.1_s": 10.0,
           "icing_2_s": 90.0}


@functools.lru_cache(maxsize=2)
def calibration():
    """The calibration every run is monitored against (cached per process)."""
    from pitotcal.estimation import identify
    from pitotcal.estimation.monitor.model import Calibration

    flight, _ = get_flight(None, {"turbulence_mps": 0.5}, CAL_SEED)
    return Calibration.from_result(identify(flight))


def _sim(condition):
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in CONDITIONS[condition].items()}


def task(seed, condition, faults):
    """One flight: its clean row and one row per fault."""
    from pitotcal.estimation.monitor.monitoring import monitor
    from pitotcal.estimation.monitor.cusum import MonitorOptions
    from pitotcal.maneuvers.fly.faults import Fault, apply_fault

    cal = calibration()
    flight, truth = get_flight(None, _sim(condition), seed)
    base = {"condition": condition, "turbulence_mps": CONDITIONS[condition]["turbulence_mps"]}
    rows = []
    for rate in DESIGN_RATES:
        res = monitor(flight, cal, MonitorOptions(false_alarms_per_hour=rate))
        if rate == DESIGN_RATES[0]:
            row = {**base, "type": "clean", "monitored_s": res.monitored_s}
            default = res
        row[f"alarms_{rate:g}"] = len(res.alarms)
    for gate in GATES_MPS:
        row[f"alarms_fixed_{gate:g}"] = len(fixed_threshold_alarms(
            default, flight, cal, innov_mps=gate, warmup_s=default.options.warmup_s))
    rows.append(row)
    for kind, size, expected in faults:
        fault = Fault(kind, ONSET_S, size, seed=seed)
        spoiled = apply_fault(flight, truth, fault)
        res = monitor(spoiled, cal)
        rows.append({**base, "type": "fault", **_detection(res, spoiled, cal, fault, expected),
                     "delay_oracle_s": _oracle(flight, spoiled, cal, fault)})
    return rows


def _oracle(flight, spoiled, cal, fault):
    """The oracle's delay (`monitor_oracle`) at the monitor's default designed rate, for the
    faults that add a known signal to the residual (a leak's step, an icing ramp; None
    otherwise). It is also told the wind: the residuals are the monitor's with the wind held
    at the calibration's after the warm-up (the fault conditions fly in that wind)."""
    from pitotcal.estimation.monitor.monitoring import monitor
    from pitotcal.estimation.monitor.cusum import MonitorOptions, ar_coefficients, in_velocity

    from .oracle import oracle_delay_s

    if fault.kind not in ORACLE_KINDS:
        return None
    opts = MonitorOptions(wind_tau_s=_HELD_WIND_TAU_S)
    clean, faulty = monitor(flight, cal, opts), monitor(spoiled, cal, opts)
    return oracle_delay_s(clean.blocks, faulty.blocks, ar_coefficients(cal.noise),
                          fault.onset_s, opts.false_alarms_per_hour, opts.warmup_s,
                          in_velocity(cal.noise))


def _detection(res, flight, cal, fault, expected):
    """Delay and classification of the first alarm at or after the onset."""
    after = [a for a in res.alarms if a["start_s"] >= fault.onset_s]
    first = after[0] if after else None
    out = {"fault_kind": fault.kind, "fault_size": fault.size, "expected_kind": expected,
           "false_before_onset": len(res.alarms) - len(after),
           "delay_s": None if first is None else first["start_s"] - fault.onset_s,
           "kind": None if first is None else first["kind"],
           "statistic": None if first is None else first["statistic"],
           "size": None if first is None else first["size"],
           "kind_ok": None if first is None else first["kind"] == expected,
           "available_s": float(flight.time_s[-1] - fault.onset_s)}
    for gate in GATES_MPS:
        starts = [s for s in fixed_threshold_alarms(res, flight, cal, innov_mps=gate,
                                                    warmup_s=res.options.warmup_s)
                  if s >= fault.onset_s]
        out[f"delay_fixed_{gate:g}_s"] = starts[0] - fault.onset_s if starts else None
    return out


def cases(runs, quick):
    if quick:
        return [{"condition": "turb-0.5", "faults": QUICK_FAULTS, "seed_offset": r}
                for r in range(runs)]
    grid = [{"condition": c, "faults": FAULTS if c in FAULT_CONDITIONS else (),
             "seed_offset": r} for c in CONDITIONS for r in range(runs)]
    # false alarms need hours: more clean-only flights (cheap) in every condition
    return grid + [{"condition": c, "faults": (), "seed_offset": runs + r}
                   for c in CONDITIONS for r in range(EXTRA_CLEAN * runs)]


def summarize(rows, cases=None):
    from .summary import summarize_rows
    return summarize_rows(rows, DESIGN_RATES, GATES_MPS, TARGETS)


def headline(summary):
    from .summary import headline_of
    return headline_of(summary)


def plot(rows, summary, out_dir):
    """Left, middle: median detection delay against leak and icing size per turbulence level
    (solid: the monitor; dashed: the fixed 2 m/s gate; dotted: the oracle told the fault,
    `monitor_oracle`; a point only where at least half the runs detected it). Right: measured
    against designed false-alarm rate per condition."""
    fig, ax = new_figure(1, 3, size=(4.6, 3.8))
    faults = [r for r in rows if r.get("type") == "fault" and not r.get("error")]
    colors = dict(zip(CONDITIONS, ("C0", "C1", "C3", "C2")))
    for a, kind, unit in ((ax[0, 0], "leak", "fraction of q_ci"),
                          (ax[0, 1], "icing", "kt/min")):
        for (cond,), rs in group([r for r in faults if r["fault_kind"] == kind],
                                 "condition").items():
            sizes = sorted({float(r["fault_size"]) for r in rs})
            for key, ls, label in (("delay_s", "-o", cond),
                                   ("delay_fixed_2_s", "--s", f"{cond}, fixed 2 m/s"),
                                   ("delay_oracle_s", ":", f"{cond}, oracle")):
                med = [_median_or_nan([r for r in rs if float(r["fault_size"]) == s], key)
                       for s in sizes]
                a.plot(sizes, med, ls, color=colors[cond], ms=4, label=label)
        a.set_xlabel(f"{kind} size, {unit}")
        a.set_ylabel("median detection delay, s")
        a.set_yscale("log")
        a.set_title(f"{kind} from {ONSET_S:g} s (undetected by 240 s: no point)", fontsize=9)
        a.legend(fontsize=7)
    a = ax[0, 2]
    for cond, fa in summary.get("false_alarms", {}).items():
        design = [float(r) for r in fa["by_design"]]
        measured = [fa["by_design"][r]["per_hour"] or np.nan for r in fa["by_design"]]
        a.plot(design, measured, "o-", color=colors.get(cond), ms=4,
               label=f"{cond} ({fa['hours']:.1f} h)")
    a.plot([0.01, 30], [0.01, 30], "k--", lw=0.8, label="measured = designed")
    a.set_xscale("log")
    a.set_yscale("log")
    a.set_xlabel("designed false alarms per flight hour")
    a.set_ylabel("measured per flight hour (0: not shown)")
    a.set_title("false alarms on clean flights", fontsize=9)
    a.legend(fontsize=7)
    fig.suptitle("pitotcal monitor: detection delay and false-alarm rate (T-2 maneuver, "
                 "calibrated in 0.5 m/s turbulence)")
    return [save(fig, out_dir, "monitor.png")]


def _median_or_nan(rows, key):
    x = column(rows, key)
    x = x[np.isfinite(x)]
    return float(np.median(x)) if x.size and x.size * 2 >= len(rows) else np.nan


STUDY = MonteCarloStudy("monitor", "false alarms per flight hour and detection delay per "
                        "fault of pitotcal monitor, against a fixed-threshold check",
                        task, cases, summarize, plot, headline, default_runs=40, quick_runs=1)
