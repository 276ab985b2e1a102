"""Compliance of a calibration with the airspeed and altimeter system-error requirements.

Works on the result JSON (`IdentificationResult.to_dict()`, docs/interfaces.md §3) so a report
can be made from a file alone. The paragraphs, their words as read, limits and speed windows are
in `regulations`:

- airspeed, 14 CFR 23.1323(b) (to Amdt. 23-63) and 25.1323(c): the system error may not exceed
  3 % of the calibrated airspeed or 5 kt, whichever is greater, over the paragraph's speed range
  for the configuration flown;
- altimeter, 23.1325(e) and 25.1325(e): the error in indicated pressure altitude *at sea level,
  with a standard atmosphere* may not exceed ±30 ft per 100 kt, and need not be less than
  ±30 ft, between 1.3 V_S0 and 1.8 V_S1 (Part 25: 1.23 V_SR0 and 1.7 V_SR1).

ΔH_pc of the result is at the flight's indicated pressure altitude H_ic
(`static_source.pressure_altitude_ic_ft`); the rule's value is the same static-source error at
sea level. The position error is a function of the indicated airspeed V_ic alone in the
calibration's structure (Δp_p = q_c − q_ci at q_ci of V_ic), so at sea level the same Δp_p holds
and

    Δp_p = p(H_ic) − p(H_ic + ΔH),      ΔH_SL = H(p₀ − Δp_p)

(ISA, `pitotcal.core.airdata`), about ΔH ρ(H_ic)/ρ₀: 80.0 ft at 10,000 ft is 59.1 ft at sea
level. Its expanded uncertainty is reduced the same way (half the reduced interval ΔH ± U).

Verdict per speed, with e the error (ΔV, or ΔH at sea level) and U its expanded uncertainty
(k = 2, the budget's `dv_U_kt` / `dh_U_ft`; a row without one is judged on the statistical 2σ
and the row and the note say so): *complies* when |e| + U <= limit, *does not comply* when
|e| − U > limit, *not demonstrated* when the band straddles the limit or the speed lies outside
the flown range (never extrapolated). A row of the table outside the judged speed range is
shown and *not judged*.
"""

import math

from pitotcal.core import airdata
from pitotcal.core.checks import choice, number
from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import ft_to_m, isa_altitude_m, isa_pressure_pa, m_to_ft

from . import regulations as regs
from .regulations import ALTIMETER_FT_PER_KT

__all__ = ["ALTIMETER_FT_PER_KT", "REGULATIONS", "assess", "flown_range_kcas",
           "sea_level_dh_ft"]

COMPLIES, FAILS, NOT_DEMONSTRATED = "complies", "does not comply", "not demonstrated"
NOT_JUDGED = "not judged"

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
    "25.1323": "14 CFR 25.1325(e) static pressure system",
}
ALTIMETER_REQUIREMENT = ("error in indicated pressure altitude at sea level, with a standard "
                         "atmosphere, at most ±30 ft per 100 kt (±0.30 ft per KCAS) and need not "
                         "be less than ±30 ft")
BASIS_NOTE = ("Limits are the prescriptive ones of 14 CFR 23.1323(b)/23.1325(e) (to Amdt. "
              "23-63) and 25.1323(c)/25.1325(e); for Part 23 Amdt. 23-64+ and CS-23 Amdt. 5+ "
              "the accepted means of compliance is ASTM F3233 (under ASTM F3264), which was "
              "not checked here.")
NOT_FLOWN = "outside the flown range: not extrapolated"
OUTSIDE = "outside the speed range judged: shown, not judged"


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


def sea_level_dh_ft(dh_ft, pressure_altitude_ic_ft):
    """ΔH_pc at sea level in a standard atmosphere of a ΔH_pc found at `pressure_altitude_ic_ft`.

    The same static-source error Δp_p = p(H_ic) − p(H_ic + ΔH) read at sea level (module
    notes); ft in, ft out.
    """
    h_ic = ft_to_m(pressure_altitude_ic_ft)
    # the reduction's own altitudes (H_ic + ΔH, and the sea-level result) may lie beyond the
    # ISA's tabulated range for a large ΔH: its laws, not a refusal, carry them there
    dp = airdata.static_pressure_pa(h_ic) - isa_pressure_pa(h_ic + ft_to_m(dh_ft))
    return float(m_to_ft(isa_altitude_m(airdata.P0_PA - dp)))


def assess(result, regulation="23.1323", speed_range_kt=None, *, configuration=None,
           speeds_kcas=None):
    """The compliance verdict of a result JSON against `regulation`.

    Parameters
    ----------
    result : dict
        The result JSON (rows of `airspeed_correction` with vi_kt, dv_kt, dv_2sigma_kt, vc_kt;
        used when present: dv_U_kt, dh_ft, dh_2sigma_ft, dh_U_ft, and
        static_source.pressure_altitude_ic_ft, the altitude dh_ft is for).
    regulation : {"23.1323", "25.1323", "none"}
    speed_range_kt : (float, float), optional
        Calibrated-airspeed range to judge both checks over, KCAS; default the rule's window from
        `speeds_kcas` and `configuration`, else the flown range (the block says which). Parts
        outside the flown range are *not demonstrated*.
    configuration : {"cruise", "takeoff", "approach", "landing"}, optional
        The configuration flown: it picks the airspeed paragraph's speed range.
    speeds_kcas : dict, optional
        Symbol -> KCAS of the stall and limit speeds (`regulations.STALL_SPEED_KEYS`).

    Returns
    -------
    dict
        The ``compliance`` block of docs/interfaces.md (section "Calibration report"):
        regulation, title, requirement, basis, configuration, speed_range_kt (the airspeed
        check's), speed_range_source ("flown", "given", "rule", "rule and flown" or "none"),
        flown_range_kcas, uncertainty ("expanded", "partial" or "statistical"),
        uncertainty_note, verdict (the worst of the airspeed and altimeter rows judged),
        quotes, airspeed {verdict, window, rows}, altimeter {verdict, reason, window, rows}.
        Each airspeed row: vi_kt, vc_kt, dv_kt, u_kt, u_kind, limit_kt, verdict, reason; each
        altimeter row: vc_kt, dh_ft (at sea level), dh_test_altitude_ft, u_ft, u_kind,
        limit_ft, verdict, reason.
    """
    choice("regulation", regulation, [*REGULATIONS, "none"])
    if regulation == "none":
        return {"regulation": "none", "verdict": None,
                "note": "no regulation chosen: no compliance statement"}
    reg = REGULATIONS[regulation]
    rows = _rows(result)
    flown = (rows[0]["vc_kt"], rows[-1]["vc_kt"])
    windows = {check: _window(regulation, check, configuration, speeds_kcas or {},
                              speed_range_kt, flown) for check in ("airspeed", "altimeter")}
    air_window = windows["airspeed"]
    air = [_airspeed_row(r, reg) if _inside(r, air_window) else _outside_row(r, "kt")
           for r in _grid(rows, air_window, flown)]
    alt = _altimeter(result, rows, windows["altimeter"], flown, regulation)
    kinds = {r["u_kind"] for r in air + alt["rows"] if r.get("u_kind")}
    uncertainty = ("expanded" if kinds == {"expanded"} else
                   "statistical" if kinds <= {"statistical"} else "partial")
    return {
        "regulation": regulation, "title": reg["title"], "requirement": reg["requirement"],
        "basis": BASIS_NOTE, "configuration": configuration,
        "speed_range_kt": [air_window["lo_kt"], air_window["hi_kt"]],
        "speed_range_source": air_window["source"],
        "flown_range_kcas": list(flown),
        "uncertainty": uncertainty, "uncertainty_note": _uncertainty_note(air, alt["rows"]),
        # both checks count: an altimeter that does not comply, or that could not be judged
        # (no static-source data), is not hidden by the airspeed
        "verdict": _worst([_worst(r["verdict"] for r in air), alt["verdict"]]),
        "quotes": _quotes(regulation),
        "airspeed": {"verdict": _worst(r["verdict"] for r in air), "window": air_window,
                     "rows": air},
        "altimeter": alt,
    }


def _window(regulation, check, configuration, speeds, speed_range_kt, flown):
    if speed_range_kt is None:
        return regs.speed_window(regulation, check, configuration, speeds, flown)
    lo, hi = _speed_range(speed_range_kt)
    return {"lo_kt": lo, "hi_kt": hi, "source": "given", "text": "as given (speed_range_kt)"}


def _speed_range(speed_range_kt):
    if len(speed_range_kt) != 2:
        raise PitotcalError("speed_range_kt must be two speeds, LO HI", param="speed_range_kt")
    lo = number("speed_range_kt", speed_range_kt[0], 0.0, lo_open=True)
    hi = number("speed_range_kt", speed_range_kt[1], 0.0, lo_open=True)
    if hi <= lo:
        raise PitotcalError(f"speed_range_kt {lo:g} {hi:g}: the highest speed must be above "
                            "the lowest", param="speed_range_kt")
    return lo, hi


def _quotes(regulation):
    out = []
    for check, paragraphs in regs.QUOTED_FOR[regulation].items():
        for para in paragraphs:
            words, extent, source = regs.QUOTES[para]
            out.append({"check": check, "paragraph": f"14 CFR {para}", "text": words,
                        "extent": extent, "source": source,
                        "note": regs.QUOTE_NOTES.get(para)})
    return out


def _uncertainty_note(air, alt):
    judged = [r for r in air + alt if r.get("u_kind")]
    plain = [r for r in judged if r["u_kind"] == "statistical"]
    if not plain:
        return ("U is the expanded uncertainty (k = 2) of the result's uncertainty budget, "
                "statistical and Type B")
    where = ", ".join(f"{r['vc_kt']:.1f} KCAS ({'ΔV' if 'dv_kt' in r else 'ΔH'})"
                      for r in plain)
    if len(plain) == len(judged):
        return ("the result has no expanded uncertainty (dv_U_kt, dh_U_ft): only the "
                "statistical 2σ is included, so the verdict is optimistic")
    return (f"rows without an expanded uncertainty are judged on the statistical 2σ alone "
            f"(optimistic): {where}; the others on U (k = 2)")


_KEYS = ("vi_kt", "dv_kt", "dv_2sigma_kt", "dv_U_kt", "dh_ft", "dh_2sigma_ft", "dh_U_ft")


def _inside(row, window):
    lo, hi = window["lo_kt"], window["hi_kt"]
    return lo is not None and lo - 1e-9 <= row["vc_kt"] <= hi + 1e-9


def _grid(rows, window, flown):
    """Every table row, the window's ends interpolated when inside the flown range, and one
    row per end beyond it (no numbers: not flown)."""
    out = [dict(r) for r in rows]
    if window["lo_kt"] is None:
        return out
    for end in (window["lo_kt"], window["hi_kt"]):
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


def _uncertainty(row, expanded_key, plain_key):
    """(u, kind) of a row: its expanded U when it has one, else its statistical 2σ.

    A negative band is refused: |e| + U ≤ limit would let it pass an error above the limit.
    """
    for key, kind in ((expanded_key, "expanded"), (plain_key, "statistical")):
        if _finite(row.get(key)):
            if row[key] < 0:
                raise PitotcalError(f"`result` airspeed_correction row at {row['vc_kt']:.1f} "
                                    f"KCAS: {key} {row[key]:g} is negative (an uncertainty "
                                    "is at least 0)", param="result")
            return row[key], kind
    return None, None


def _outside_row(row, unit):
    if unit == "kt":
        return {"vi_kt": row.get("vi_kt"), "vc_kt": row["vc_kt"], "dv_kt": row.get("dv_kt"),
                "u_kt": None, "u_kind": None, "limit_kt": None, "verdict": NOT_JUDGED,
                "reason": OUTSIDE}
    return {"vc_kt": row["vc_kt"], "dh_ft": row.get("dh_ft"),
            "dh_test_altitude_ft": row.get("dh_test_altitude_ft"), "u_ft": None,
            "u_kind": None, "limit_ft": None, "verdict": NOT_JUDGED, "reason": OUTSIDE}


def _airspeed_row(row, reg):
    vc = row["vc_kt"]
    limit = max(reg["fraction"] * vc, reg["floor_kt"])
    out = {"vi_kt": row.get("vi_kt"), "vc_kt": vc, "dv_kt": row.get("dv_kt"), "u_kt": None,
           "u_kind": None, "limit_kt": limit}
    if row.get("flown") is False:
        return {**out, "verdict": NOT_DEMONSTRATED, "reason": NOT_FLOWN}
    u, kind = _uncertainty(row, "dv_U_kt", "dv_2sigma_kt")
    if u is None:
        return {**out, "verdict": NOT_DEMONSTRATED, "reason": "no uncertainty"}
    verdict, reason = _verdict(row["dv_kt"], u, limit)
    if kind == "statistical":
        reason += " (statistical 2σ only: this row has no U)"
    return {**out, "u_kt": u, "u_kind": kind, "verdict": verdict, "reason": reason}


def _altimeter(result, rows, window, flown, regulation):
    head = {"title": ALTIMETER_TITLES[regulation], "requirement": ALTIMETER_REQUIREMENT,
            "window": window}
    if not all(_finite(r.get("dh_ft")) for r in rows):
        return {**head, "verdict": NOT_DEMONSTRATED, "reason": "no static-source data (dh_ft)",
                "rows": []}
    h_ic = (result.get("static_source") or {}).get("pressure_altitude_ic_ft")
    out = [_altimeter_row(r, h_ic) if _inside(r, window) else
           _outside_row(_at_sea_level(r, h_ic), "ft") for r in _grid(rows, window, flown)]
    reason = ("per speed below: ΔH reduced to sea level in a standard atmosphere from "
              f"{h_ic:.0f} ft" if _finite(h_ic) else
              "the test altitude is unknown (static_source.pressure_altitude_ic_ft): ΔH "
              "cannot be reduced to sea level")
    return {**head, "verdict": _worst(r["verdict"] for r in out), "reason": reason,
            "rows": out}


def _at_sea_level(row, h_ic):
    """`row` with dh_ft at sea level and the test-altitude value as dh_test_altitude_ft."""
    if not _finite(row.get("dh_ft")):
        return {**row, "dh_ft": None, "dh_test_altitude_ft": None}
    sea = sea_level_dh_ft(row["dh_ft"], h_ic) if _finite(h_ic) else None
    return {**row, "dh_ft": sea, "dh_test_altitude_ft": row["dh_ft"]}


def _altimeter_row(row, h_ic):
    vc = row["vc_kt"]
    out = {"vc_kt": vc, "dh_ft": None, "dh_test_altitude_ft": row.get("dh_ft"), "u_ft": None,
           "u_kind": None, "limit_ft": regs.altimeter_limit_ft(vc)}
    if row.get("flown") is False:
        return {**out, "verdict": NOT_DEMONSTRATED, "reason": NOT_FLOWN}
    if not _finite(h_ic):
        return {**out, "verdict": NOT_DEMONSTRATED, "reason": "test altitude unknown"}
    u, kind = _uncertainty(row, "dh_U_ft", "dh_2sigma_ft")
    dh = row["dh_ft"]
    out["dh_ft"] = sea_level_dh_ft(dh, h_ic)
    if u is None:
        return {**out, "verdict": NOT_DEMONSTRATED, "reason": "no uncertainty"}
    # the interval dh ± u reduced to sea level: its half-width is U at sea level
    u_sea = 0.5 * abs(sea_level_dh_ft(dh + u, h_ic) - sea_level_dh_ft(dh - u, h_ic))
    verdict, reason = _verdict(out["dh_ft"], u_sea, out["limit_ft"])
    if kind == "statistical":
        reason += " (statistical 2σ only: this row has no U)"
    if ALTIMETER_FT_PER_KT * vc < regs.ALTIMETER_FLOOR_FT:
        reason += "; the ±30 ft floor governs"
    return {**out, "u_ft": u_sea, "u_kind": kind, "verdict": verdict, "reason": reason}


def _worst(verdicts):
    """Does not comply if any speed judged does not; complies only if every one judged does."""
    verdicts = [v for v in verdicts if v != NOT_JUDGED]
    if FAILS in verdicts:
        return FAILS
    if verdicts and all(v == COMPLIES for v in verdicts):
        return COMPLIES
    return NOT_DEMONSTRATED
