"""Compliance of a calibration with the airspeed and altimeter system-error requirements.

Works on the result JSON (`IdentificationResult.to_dict()`, docs/interfaces.md §3) so a report
can be made from a file alone. The requirements (prescriptive text checked for this module):

- 14 CFR 23.1323(b) (up to Amdt. 23-63): the airspeed system error, excluding the instrument
  calibration error, may not exceed 3 % of the calibrated airspeed or 5 kt, whichever is
  greater, over the stated speed ranges.
- 14 CFR 25.1323(c): the airspeed error of the installation, excluding the indicator's
  calibration error, may not exceed 3 % or 5 kt, whichever is greater, over the stated range.
- 14 CFR 23.1325(e): the system error in indicated pressure altitude may not exceed ±30 ft per
  100 kt of speed; applied as ±0.30 ft per KCAS, with no 30 ft floor (29.1325(f) has one; it
  could not be confirmed for 23.1325(e), and the check without it is the stricter one).
  With 25.1323 the altimeter paragraph is 25.1325's; its text could not be checked here, so
  the same 23.1325(e) limit is applied (no floor) and the block's title says so.

Part 23 since Amdt. 23-64 (2017) and CS-23 since Amdt. 5 are performance-based: the numbers
live in the accepted means of compliance (ASTM F3264 and the standards it calls up), which
were not available here. The verdicts apply the legacy numbers above and say so.

Verdict per speed, with ΔV the correction and U its expanded uncertainty (k = 2; the
statistical 2σ alone when the result carries no `dv_U_kt`, and the verdict says so):
*complies* when |ΔV| + U <= limit, *does not comply* when |ΔV| − U > limit, *not
demonstrated* when the band straddles the limit or the speed lies outside the flown range
(never extrapolated).
"""

import math

from pitotcal.core.checks import choice, number
from pitotcal.core.errors import PitotcalError

__all__ = ["ALTIMETER_FT_PER_KT", "REGULATIONS", "assess", "flown_range_kcas"]

COMPLIES, FAILS, NOT_DEMONSTRATED = "complies", "does not comply", "not demonstrated"

# 23.1325(e): ±30 ft per 100 kt.
ALTIMETER_FT_PER_KT = 30.0 / 100.0

REGULATIONS = {
    "23.1323": {
        "title": "14 CFR / CS 23.1323(b) airspeed indicating system",
        "requirement": "airspeed system error at most 3 % of the calibrated airspeed or 5 kt, "
                       "whichever is greater",
        "fraction": 0.03, "floor_kt": 5.0},
    "25.1323": {
        "title": "14 CFR / CS 25.1323(c) airspeed indicating system",
        "requirement": "airspeed error of the installation at most 3 % or 5 kt, whichever is "
                       "greater",
        "fraction": 0.03, "floor_kt": 5.0},
}
ALTIMETER_TITLES = {
    "23.1323": "14 CFR 23.1325(e) static pressure system",
    "25.1323": ("14 CFR 25.1325 static pressure system (the 23.1325(e) limit applied: "
                "25.1325's own text, and any ±30 ft floor, not checked here)"),
}
ALTIMETER_REQUIREMENT = "altimeter system error at most ±30 ft per 100 kt (±0.30 ft per KCAS)"
BASIS_NOTE = ("Limits are the prescriptive ones of 14 CFR 23.1323(b)/23.1325(e) (to Amdt. "
              "23-63) and 25.1323(c); for Part 23 Amdt. 23-64+ and CS-23 Amdt. 5+ the accepted "
              "means of compliance (ASTM F3264) governs and was not checked here.")
NOT_FLOWN = "outside the flown range: not extrapolated"


def flown_range_kcas(result):
    """(lowest, highest) calibrated airspeed V_c of the result's correction table, kt."""
    rows = _rows(result)
    vc = [r["vc_kt"] for r in rows]
    return min(vc), max(vc)


def _rows(result):
    rows = result.get("airspeed_correction") or []
    good = [r for r in rows if _finite(r.get("vc_kt")) and _finite(r.get("dv_kt"))]
    if not good:
        raise PitotcalError("the result has no airspeed_correction rows with vc_kt and dv_kt")
    return sorted(good, key=lambda r: r["vc_kt"])


def _finite(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def assess(result, regulation="23.1323", speed_range_kt=None):
    """The compliance verdict of a result JSON against `regulation`.

    Parameters
    ----------
    result : dict
        The result JSON (rows of `airspeed_correction` with vi_kt, dv_kt, dv_2sigma_kt, vc_kt;
        used when present: dv_U_kt, dh_ft, dh_2sigma_ft).
    regulation : {"23.1323", "25.1323", "none"}
    speed_range_kt : (float, float), optional
        Calibrated-airspeed range to assess, KCAS; default the flown range (and the block says
        so). Parts outside the flown range are *not demonstrated*.

    Returns
    -------
    dict
        The ``compliance`` block of docs/interfaces.md (section "Calibration report"):
        regulation, title, requirement, basis, speed_range_kt, speed_range_source ("flown" or
        "given"), flown_range_kcas, uncertainty ("expanded" or "statistical"), uncertainty_note,
        verdict (the worst of the airspeed and altimeter rows), airspeed {verdict, rows}, altimeter {verdict,
        reason, rows}. Each airspeed row: vi_kt, vc_kt, dv_kt, u_kt, limit_kt, verdict, reason;
        each altimeter row: vc_kt, dh_ft, u_ft, limit_ft, verdict, reason.
    """
    choice("regulation", regulation, [*REGULATIONS, "none"])
    if regulation == "none":
        return {"regulation": "none", "verdict": None,
                "note": "no regulation chosen: no compliance statement"}
    reg = REGULATIONS[regulation]
    rows = _rows(result)
    flown = (rows[0]["vc_kt"], rows[-1]["vc_kt"])
    lo, hi, source = _speed_range(speed_range_kt, flown)
    expanded = all(_finite(r.get("dv_U_kt")) for r in rows)
    grid = _grid(rows, lo, hi, flown)
    air = [_airspeed_row(r, reg, expanded) for r in grid]
    alt = _altimeter(grid, all(_finite(r.get("dh_ft")) for r in rows), regulation)
    return {
        "regulation": regulation, "title": reg["title"], "requirement": reg["requirement"],
        "basis": BASIS_NOTE,
        "speed_range_kt": [lo, hi], "speed_range_source": source,
        "flown_range_kcas": list(flown),
        "uncertainty": "expanded" if expanded else "statistical",
        "uncertainty_note": ("U is the expanded uncertainty (k = 2) of the result's "
                             "uncertainty budget" if expanded else
                             "the result has no expanded uncertainty (dv_U_kt): only the "
                             "statistical 2σ is included, so the verdict is optimistic"),
        # every row counts: an altimeter that does not comply is not hidden by the airspeed
        "verdict": _worst(r["verdict"] for r in air + alt["rows"]),
        "airspeed": {"verdict": _worst(r["verdict"] for r in air), "rows": air},
        "altimeter": alt,
    }


def _speed_range(speed_range_kt, flown):
    if speed_range_kt is None:
        return flown[0], flown[1], "flown"
    if len(speed_range_kt) != 2:
        raise PitotcalError("speed_range_kt must be two speeds, LO HI", param="speed_range_kt")
    lo = number("speed_range_kt", speed_range_kt[0], 0.0, lo_open=True)
    hi = number("speed_range_kt", speed_range_kt[1], 0.0, lo_open=True)
    if hi <= lo:
        raise PitotcalError(f"speed_range_kt {lo:g} {hi:g}: the highest speed must be above "
                            "the lowest", param="speed_range_kt")
    return lo, hi, "given"


_KEYS = ("vi_kt", "dv_kt", "dv_2sigma_kt", "dv_U_kt", "dh_ft", "dh_2sigma_ft")


def _grid(rows, lo, hi, flown):
    """The table rows inside [lo, hi], the ends interpolated when inside the flown range,
    and one row per end beyond it (no numbers: not flown)."""
    out = [dict(r) for r in rows if lo <= r["vc_kt"] <= hi]
    for end in (lo, hi):
        if end < flown[0] - 1e-9 or end > flown[1] + 1e-9:
            out.append({"vc_kt": end, "flown": False})
        elif not any(abs(r["vc_kt"] - end) < 1e-9 for r in out):
            out.append(_interpolate(rows, end))
    return sorted(out, key=lambda r: r["vc_kt"])


def _interpolate(rows, vc):
    """A row at calibrated airspeed `vc` by linear interpolation between its table neighbours
    (the table is dense: 1-10 kt steps over a smooth correction)."""
    i = next(i for i in range(1, len(rows)) if rows[i]["vc_kt"] >= vc)
    a, b = rows[i - 1], rows[i]
    w = (vc - a["vc_kt"]) / (b["vc_kt"] - a["vc_kt"])
    row = {"vc_kt": vc}
    for key in _KEYS:
        if _finite(a.get(key)) and _finite(b.get(key)):
            row[key] = a[key] + w * (b[key] - a[key])
    return row


def _verdict(error, u, limit):
    if abs(error) + u <= limit:
        return COMPLIES, "error and its uncertainty inside the limit"
    if abs(error) - u > limit:
        return FAILS, "error outside the limit by more than its uncertainty"
    return NOT_DEMONSTRATED, "the uncertainty band straddles the limit"


def _airspeed_row(row, reg, expanded):
    vc = row["vc_kt"]
    limit = max(reg["fraction"] * vc, reg["floor_kt"])
    if row.get("flown") is False:
        return {"vi_kt": None, "vc_kt": vc, "dv_kt": None, "u_kt": None, "limit_kt": limit,
                "verdict": NOT_DEMONSTRATED, "reason": NOT_FLOWN}
    u = row["dv_U_kt"] if expanded else row.get("dv_2sigma_kt")
    if not _finite(u):
        return {"vi_kt": row.get("vi_kt"), "vc_kt": vc, "dv_kt": row["dv_kt"], "u_kt": None,
                "limit_kt": limit, "verdict": NOT_DEMONSTRATED, "reason": "no uncertainty"}
    verdict, reason = _verdict(row["dv_kt"], u, limit)
    return {"vi_kt": row.get("vi_kt"), "vc_kt": vc, "dv_kt": row["dv_kt"], "u_kt": u,
            "limit_kt": limit, "verdict": verdict, "reason": reason}


def _altimeter(grid, has_dh, regulation):
    title = ALTIMETER_TITLES[regulation]
    if not has_dh:
        return {"title": title, "requirement": ALTIMETER_REQUIREMENT,
                "verdict": NOT_DEMONSTRATED, "reason": "no static-source data (dh_ft)",
                "rows": []}
    rows = []
    for r in grid:
        vc = r["vc_kt"]
        limit = ALTIMETER_FT_PER_KT * vc
        if r.get("flown") is False:
            rows.append({"vc_kt": vc, "dh_ft": None, "u_ft": None, "limit_ft": limit,
                         "verdict": NOT_DEMONSTRATED, "reason": NOT_FLOWN})
            continue
        u = r.get("dh_2sigma_ft")
        if not _finite(u):
            rows.append({"vc_kt": vc, "dh_ft": r["dh_ft"], "u_ft": None, "limit_ft": limit,
                         "verdict": NOT_DEMONSTRATED, "reason": "no uncertainty"})
            continue
        verdict, reason = _verdict(r["dh_ft"], u, limit)
        rows.append({"vc_kt": vc, "dh_ft": r["dh_ft"], "u_ft": u, "limit_ft": limit,
                     "verdict": verdict, "reason": reason})
    verdict = _worst(r["verdict"] for r in rows)
    return {"title": title, "requirement": ALTIMETER_REQUIREMENT, "verdict": verdict,
            "reason": "per speed below (u_ft: the statistical 2σ of dh_ft)", "rows": rows}


def _worst(verdicts):
    """Does not comply if any speed does not; complies only if every speed does."""
    verdicts = list(verdicts)
    if FAILS in verdicts:
        return FAILS
    if verdicts and all(v == COMPLIES for v in verdicts):
        return COMPLIES
    return NOT_DEMONSTRATED
