"""The `monitor` study's summary: false alarms per flight hour (designed, measured, 95 % upper
bound) per condition, detection per fault, and the monitor's targets, met or not."""

import numpy as np

from ..engine.common import column, group

__all__ = ["headline_of", "poisson_upper", "summarize_rows"]


def poisson_upper(count, hours, confidence=0.95):
    """One-sided upper confidence bound of a Poisson rate, per hour (Garwood)."""
    from scipy.stats import chi2

    if hours <= 0:
        return None
    return float(chi2.ppf(confidence, 2 * (count + 1)) / 2.0 / hours)


def _rate(rows, key, hours):
    n = int(np.nansum(column(rows, key)))
    return {"alarms": n, "per_hour": n / hours if hours > 0 else None,
            "upper95_per_hour": poisson_upper(n, hours)}


def _false_alarms(rows, design_rates, gates):
    out = {}
    clean = [r for r in rows if r.get("type") == "clean" and not r.get("error")]
    for (cond,), rs in group(clean, "condition").items():
        hours = float(np.nansum(column(rs, "monitored_s"))) / 3600.0
        out[cond] = {"flights": len(rs), "hours": hours,
                     "by_design": {f"{r:g}": _rate(rs, f"alarms_{r:g}", hours)
                                   for r in design_rates},
                     "fixed": {f"{g:g}_mps": _rate(rs, f"alarms_fixed_{g:g}", hours)
                               for g in gates}}
    return out


def _delays(rs, key):
    x = column(rs, key)
    found = x[np.isfinite(x)]
    return {"detected": float(found.size / len(rs)) if rs else None,
            "median_s": float(np.median(found)) if found.size else None,
            "max_s": float(np.max(found)) if found.size else None}


def _detection(rows, gates):
    out = {}
    faults = [r for r in rows if r.get("type") == "fault" and not r.get("error")]
    for (cond, kind, size), rs in group(faults, "condition", "fault_kind", "fault_size").items():
        ok = [r.get("kind_ok") for r in rs if r.get("kind_ok") is not None]
        entry = {"runs": len(rs), **_delays(rs, "delay_s"),
                 "kind_right": float(np.mean([v in (True, "True") for v in ok])) if ok else None,
                 "available_s": float(np.nanmin(column(rs, "available_s")))}
        for g in gates:
            entry[f"fixed_{g:g}_mps"] = _delays(rs, f"delay_fixed_{g:g}_s")
        if any(r.get("delay_oracle_s") is not None for r in rs):
            entry["oracle"] = _delays(rs, "delay_oracle_s")
        out.setdefault(cond, {})[f"{kind}:{size:g}"] = entry
    return out


def _targets(fa, det, targets):
    """The monitor's targets: the number reached and whether it met the target."""
    def delays(key):
        e = det.get("turb-0.5", {}).get(key)
        if e is None or e["detected"] != 1.0:
            return {"worst_delay_s": None, "median_delay_s": None}
        out = {"worst_delay_s": e["max_s"], "median_delay_s": e["median_s"]}
        if "oracle" in e:
            out.update(oracle_median_s=e["oracle"]["median_s"],
                       oracle_worst_s=e["oracle"]["max_s"])
        return out

    out = {}
    turb = fa.get("turb-1.0")
    if turb:
        rate = turb["by_design"][min(turb["by_design"], key=float)]
        out["false_alarms_turb_1.0"] = {
            "per_hour": rate["per_hour"], "upper95_per_hour": rate["upper95_per_hour"],
            "hours": turb["hours"], "target_per_hour": targets["false_alarms_per_hour_turb_1.0"]}
    for name, key, limit in (("frozen", "blocked:0", targets["frozen_s"]),
                             ("leak_10pct", "leak:0.1", targets["leak_0.1_s"]),
                             ("icing_2ktmin", "icing:2", targets["icing_2_s"])):
        got = delays(key)
        out[name] = {**got, "target_s": limit,
                     "met": got["worst_delay_s"] is not None and got["worst_delay_s"] <= limit}
    return out


def summarize_rows(rows, design_rates, gates, targets):
    """The study's own summary keys: false_alarms, detection, targets."""
    fa = _false_alarms(rows, design_rates, gates)
    det = _detection(rows, gates)
    return {"false_alarms": fa, "detection": det, "targets": _targets(fa, det, targets),
            "design_rates_per_hour": list(design_rates), "fixed_gates_mps": list(gates)}


def headline_of(summary):
    """False alarms in 1 m/s turbulence and the three detection targets, in one line."""
    t = summary.get("targets", {})
    parts = []
    fa = t.get("false_alarms_turb_1.0")
    if fa:
        parts.append(f"{fa['per_hour'] * fa['hours']:.0f} false alarms in {fa['hours']:.1f} h "
                     f"of 1 m/s turbulence (95% bound {fa['upper95_per_hour']:.2g}/h)")
    for name, label in (("frozen", "frozen pitot"), ("leak_10pct", "10% leak"),
                        ("icing_2ktmin", "2 kt/min icing")):
        e = t.get(name)
        if e:
            got = "missed" if e["worst_delay_s"] is None else \
                f"median {e['median_delay_s']:.1f} s, <= {e['worst_delay_s']:.1f} s"
            parts.append(f"{label} {got} (target {e['target_s']:g} s)")
    return "; ".join(parts) or "no runs"
