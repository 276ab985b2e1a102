"""`sample-size` (paper Fig. 6): parameters and their 2-σ versus the number of samples used.

An S-2-like flight: two speeds, 70 and 90 KCAS, 320 s at 50 Hz (16,000 samples). Each replicate
flies it once (all sample counts of one replicate share the seed, like the paper's single
flight) and identifies a window of N consecutive samples centred on the speed change, so N/2
samples come from each speed: N = 10,000 is a dwell of 100 s at each airspeed.
"""

import numpy as np

from ..engine.common import (
    accuracy_summary,
    column,
    get_flight,
    group,
    identify_flight,
    ok_rows,
    score,
    stats,
    truth_for,
)
from ..engine.figures import new_figure, plain_log_ticks, save
from ..engine.study import MonteCarloStudy

__all__ = ["S2_PLAN", "SAMPLE_COUNTS", "STUDY"]

SAMPLE_COUNTS = (750, 1500, 3000, 5751, 8000, 10751, 13000, 16000)
QUICK_COUNTS = (3000, 16000)
S2_PLAN = {"profile": "two-speed", "cas_min_kt": 70.0, "cas_max_kt": 90.0, "duration_s": 320.0}
PARAMETERS = ("k1", "k2", "wind_speed_mps", "wind_from_deg")


def task(seed, n_samples_used):
    flight, truth = get_flight(S2_PLAN, {}, seed)
    n = min(int(n_samples_used), flight.n)
    start = max(0, (flight.n - n) // 2)
    mask = np.zeros(flight.n, dtype=bool)
    mask[start:start + n] = True
    used = flight.select(mask)
    row = score(identify_flight(used), truth_for(truth, used), used)
    row["window_s"] = float(used.time_s[-1] - used.time_s[0])
    return row


def cases(runs, quick):
    counts = QUICK_COUNTS if quick else SAMPLE_COUNTS
    return [{"n_samples_used": n, "seed_offset": r} for r in range(runs) for n in counts]


def summarize(rows, cases=None):
    by_n = {}
    for (n,), rs in group(rows, "n_samples_used").items():
        good = ok_rows(rs)
        entry = accuracy_summary(rs, **{f"{p}_err_rms": f"{p}_err" for p in PARAMETERS})
        for p in PARAMETERS:
            entry[p] = stats(good, p)["median"]
            s = stats(good, f"{p}_std")["median"]
            entry[f"{p}_2sigma"] = 2 * s if s is not None else None
        by_n[str(int(n))] = entry
    return {"plan": S2_PLAN, "by_n_samples": by_n, "settled_n_samples": _settled(by_n)}


def headline(summary):
    """The result in one line: the fewest samples that gave an answer, and the 2σ of ΔV there,
    near the paper's 10,751 and at the most samples."""
    by_n = summary["by_n_samples"]
    answered = sorted((int(n) for n, e in by_n.items() if e["dv_2sigma_max_kt"] is not None))
    if not answered:
        return "no run gave an answer"
    picks = sorted({answered[0], min(answered, key=lambda n: abs(n - 10751)), answered[-1]})
    dv = ", ".join(f"{by_n[str(n)]['dv_2sigma_max_kt']:.2f} kt at {n}" for n in picks)
    refused = [int(n) for n, e in by_n.items() if e["dv_2sigma_max_kt"] is None]
    below = f"; no answer below {answered[0]} samples" if refused else ""
    return f"2σ of ΔV {dv} samples{below}"


def _settled(by_n):
    """Smallest N from which the median 2σ of ΔV and of the wind stay within 25% of the
    largest N's (the paper's "stable solution"), or None."""
    keys = sorted(by_n, key=int)
    ref = by_n[keys[-1]]
    names = ("dv_2sigma_max_kt", "wind_speed_mps_2sigma", "wind_from_deg_2sigma")
    if any(ref.get(k) is None for k in names):
        return None
    settled = None
    for key in reversed(keys):
        e = by_n[key]
        if all(e.get(k) is not None and e[k] <= 1.25 * ref[k] for k in names):
            settled = int(key)
        else:
            break
    return settled


def plot(rows, summary, out_dir):
    good = ok_rows(rows)
    fig, ax = new_figure(2, 3, size=(4.2, 3.2))
    panels = (("k1", "p1 = k1", 1.0), ("k2", "p2 = k2, Pa", 1.0),
              ("wind_from_deg", "p3 = wind from, deg", 1.0),
              ("wind_speed_mps", "p4 = wind speed, m/s", 1.0))
    n_all = column(good, "n_samples_used")
    for a, (p, label, _) in zip(ax.flat, panels):
        for rs in group(good, "seed").values():
            a.plot(column(rs, "n_samples_used"), column(rs, p), "-", color="0.7", lw=0.7)
        ns = sorted(set(n_all[np.isfinite(n_all)]))
        med = [np.nanmedian(column([r for r in good if r["n_samples_used"] == n], p)) for n in ns]
        sd = [np.nanmedian(column([r for r in good if r["n_samples_used"] == n], f"{p}_std"))
              for n in ns]
        a.errorbar(ns, med, yerr=2 * np.array(sd), fmt="o-", color="tab:blue", capsize=3,
                   label="median ± median 2σ")
        true = column(good, f"{p}_true")
        if np.isfinite(true).any():
            a.axhline(np.nanmedian(true), color="k", ls="--", lw=0.8, label="truth")
        a.set_xscale("log")
        plain_log_ticks(a, "x")
        a.set_ylabel(label)
        a.set_xlabel("samples used")
        a.legend(fontsize=7)
    by_n = summary["by_n_samples"]
    ns = sorted(int(k) for k in by_n)
    a = ax[1, 1]
    a.plot(ns, [by_n[str(n)]["wind_from_deg_2sigma"] for n in ns], "o-", label="crb3: 2σ wind from, deg")
    a.plot(ns, [by_n[str(n)]["wind_speed_mps_2sigma"] for n in ns], "s-", label="crb4: 2σ wind speed, m/s")
    a.set_xscale("log")
    a.set_yscale("log")
    plain_log_ticks(a, "both")
    a.set_xlabel("samples used")
    a.set_ylabel("2σ of the wind, deg or m/s (median)")
    a.legend(fontsize=7)
    a = ax[1, 2]
    a.plot(ns, [by_n[str(n)]["dv_2sigma_max_kt"] for n in ns], "o-", label="2σ of ΔV (max), kt")
    a.plot(ns, [by_n[str(n)]["dv_err_max_kt_rms"] for n in ns], "s-", label="|ΔV error| (rms of max), kt")
    if summary.get("settled_n_samples"):
        a.axvline(summary["settled_n_samples"], color="tab:green", ls=":", label="settled")
    a.set_xscale("log")
    a.set_yscale("log")
    plain_log_ticks(a, "both")
    a.set_xlabel("samples used")
    a.set_ylabel("ΔV, kt")
    a.legend(fontsize=7)
    fig.suptitle("Effect of sample size, S-2-like two-speed flight (70/90 KCAS, 50 Hz)")
    return [save(fig, out_dir, "sample-size.png")]


STUDY = MonteCarloStudy("sample-size", "parameters and 2σ vs samples used (paper Fig. 6)",
                        task, cases, summarize, plot, headline, default_runs=10, quick_runs=1)
