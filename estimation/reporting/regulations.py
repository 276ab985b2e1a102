"""The regulation paragraphs the compliance verdict checks: their words, limits and speed windows.

Each quotation below was read in a public copy of the paragraph (the `source` beside it) and is
reproduced only as far as it was read there; where a copy showed only part of a paragraph the
quotation is marked as an excerpt, and what was not read is said in words of our own, never put
in quotation marks. The altimeter paragraphs' "at sea level, with a standard atmosphere" and
"need not be less than ±30 feet" were read in 14 CFR 29.1325(f), whose words the fixed-wing
paragraphs 23.1325(e) (to Amdt. 23-63) and 25.1325(e) share; their speed windows (1.3 V_S0 to
1.8 V_S1, and 1.23 V_SR0 to 1.7 V_SR1) and those of 23.1323(b) are applied as these paragraphs
are commonly cited, and the window's text in the report says that they were not read here
(25.1323(c)'s were).

Part 23 since Amdt. 23-64 (2017) and CS-23 since Amdt. 5 are performance-based: the accepted
means of compliance for these limits is the consensus standard ASTM F3233 (instrumentation),
under the umbrella ASTM F3264; neither was available here, so the verdicts apply the legacy
prescriptive numbers and say so.
"""

from pitotcal.core.errors import PitotcalError

__all__ = ["ALTIMETER_FLOOR_FT", "ALTIMETER_FT_PER_KT", "CONFIGURATIONS", "QUOTES",
           "STALL_SPEED_KEYS", "altimeter_limit_ft", "speed_window"]

# 23.1325(e), 25.1325(e): ±30 ft per 100 kt, "need not be less than ±30 feet"
ALTIMETER_FT_PER_KT = 30.0 / 100.0
ALTIMETER_FLOOR_FT = 30.0

# the configuration flown: flaps retracted for cruise, extended otherwise
CONFIGURATIONS = ("cruise", "takeoff", "approach", "landing")
RETRACTED = ("cruise",)

# the aircraft file's speeds, KCAS: (TOML key, symbol)
STALL_SPEED_KEYS = (("vs0_kcas", "V_S0"), ("vs1_kcas", "V_S1"), ("vsr0_kcas", "V_SR0"),
                    ("vsr1_kcas", "V_SR1"), ("vfe_kcas", "V_FE"), ("vmo_kcas", "V_MO"),
                    ("vne_kcas", "V_NE"))

_ECFR_25_1323 = "http://www.pilotfriend.com/FARS/11/Sec.%2025.1323.htm"
_LIQUI = "https://liquisearch.com/position_error/aircraft_design_standards"
_ECFR_29_1325 = "https://self-law.org/code/us/cfr/t14/s%C2%A7%2029.1325"

# paragraph -> (words as read, "full" or "excerpt", where they were read)
QUOTES = {
    "23.1323(b)": (
        "The system error, including position error, ..., may not exceed three percent of the "
        "calibrated airspeed or five knots, whichever is greater, throughout the ...",
        "excerpt", _LIQUI),
    "25.1323(c)": (
        "The airspeed error of the installation, excluding the airspeed indicator instrument "
        "calibration error, may not exceed three percent or five knots, whichever is greater, "
        "throughout the speed range, from -- (1) VMO to 1.23 VSR1, with flaps retracted; and "
        "(2) 1.23 VSR0 to VFE with flaps in the landing position.",
        "full", _ECFR_25_1323),
    "23.1325(e)": (
        "The system error, in indicated pressure altitude, ..., may not exceed ±30 feet per "
        "100 knot speed for the ...",
        "excerpt", _LIQUI),
    "29.1325(f)": (
        "Each system must be designed and installed so that an error in indicated pressure "
        "altitude, at sea level, with a standard atmosphere, excluding instrument calibration "
        "error, does not result in an error of more than ±30 feet per 100 knots speed. "
        "However, the error need not be less than ±30 feet.",
        "full", _ECFR_29_1325),
}

# why a paragraph of another Part is quoted
QUOTE_NOTES = {
    "29.1325(f)": ("read in the rotorcraft paragraph: the full text of the fixed-wing altimeter "
                   "paragraph was not available here; its sea-level, standard-atmosphere basis "
                   "and ±30 ft floor are applied in these words"),
}
# regulation -> the paragraphs quoted beside the airspeed and the altimeter numbers
QUOTED_FOR = {
    "23.1323": {"airspeed": ("23.1323(b)",), "altimeter": ("23.1325(e)", "29.1325(f)")},
    "25.1323": {"airspeed": ("25.1323(c)",), "altimeter": ("29.1325(f)",)},
}


def altimeter_limit_ft(vc_kt):
    """The altimeter limit at calibrated airspeed `vc_kt`: ±30 ft per 100 kt, at least ±30 ft."""
    return max(ALTIMETER_FT_PER_KT * vc_kt, ALTIMETER_FLOOR_FT)


def _window_ends(regulation, check, configuration):
    """((factor, symbol), (factor, symbol) or tuple of alternatives, paragraph words) of the
    window, or None when the paragraph has no window for this configuration."""
    retracted = configuration in RETRACTED
    if check == "altimeter":
        if regulation == "23.1323":
            return (1.3, "V_S0"), ((1.8, "V_S1"),), "1.3 V_S0 (flaps extended) to 1.8 V_S1 " \
                "(flaps retracted), 23.1325(e)"
        return (1.23, "V_SR0"), ((1.7, "V_SR1"),), "1.23 V_SR0 (flaps extended) to 1.7 V_SR1 " \
            "(flaps retracted), 25.1325(e)"
    if regulation == "23.1323":
        if retracted:
            return (1.3, "V_S1"), ((1.0, "V_MO"), (1.0, "V_NE")), \
                "1.3 V_S1 to V_MO or V_NE, flaps retracted, 23.1323(b)(1)"
        return (1.3, "V_S1"), ((1.0, "V_FE"),), "1.3 V_S1 to V_FE, flaps extended, 23.1323(b)(2)"
    if retracted:
        return (1.23, "V_SR1"), ((1.0, "V_MO"),), "V_MO to 1.23 V_SR1, flaps retracted, " \
            "25.1323(c)(1)"
    if configuration == "landing":
        return (1.23, "V_SR0"), ((1.0, "V_FE"),), "1.23 V_SR0 to V_FE, flaps in the landing " \
            "position, 25.1323(c)(2)"
    return None


def speed_window(regulation, check, configuration, speeds_kcas, flown):
    """The speed range the rule judges `check` over, KCAS.

    Parameters
    ----------
    regulation : {"23.1323", "25.1323"}
    check : {"airspeed", "altimeter"}
    configuration : str or None
        One of `CONFIGURATIONS`; None: not stated.
    speeds_kcas : dict
        Symbol (`STALL_SPEED_KEYS`) -> speed, KCAS, of the speeds the user gave.
    flown : (float, float)
        The flown calibrated-airspeed range, KCAS: an end the user's speeds do not fix.

    Returns
    -------
    dict
        lo_kt, hi_kt, source ("rule", or "flown" when a needed speed is missing), text (the
        window in the paragraph's terms and what was used for an end not given).
    """
    if configuration is not None and configuration not in CONFIGURATIONS:
        raise PitotcalError(f"`configuration` {configuration!r} is not one of "
                            f"{', '.join(CONFIGURATIONS)}", param="configuration")
    if not speeds_kcas:
        return {"lo_kt": flown[0], "hi_kt": flown[1], "source": "flown",
                "text": "the flown range: no stall speeds were given"}
    if configuration is None and check == "airspeed":
        return {"lo_kt": flown[0], "hi_kt": flown[1], "source": "flown",
                "text": "the flown range: the configuration flown was not stated"}
    ends = _window_ends(regulation, check, configuration or "cruise")
    if ends is None:
        return {"lo_kt": None, "hi_kt": None, "source": "none",
                "text": f"{regulation}(c) has no speed range for the {configuration} "
                        "configuration: not judged"}
    (f_lo, s_lo), highs, words = ends
    if not words.endswith("25.1323(c)(1)") and not words.endswith("25.1323(c)(2)"):
        words += " (this range as the paragraph is cited; its text not read here)"
    lo = f_lo * speeds_kcas[s_lo] if s_lo in speeds_kcas else None
    hi = next((f * speeds_kcas[s] for f, s in highs if s in speeds_kcas), None)
    missing = [s for s, v in ((s_lo, lo), ("/".join(s for _, s in highs), hi)) if v is None]
    text = words
    if missing:
        text += f"; {' and '.join(missing)} not given: that end is the flown range's"
    return {"lo_kt": flown[0] if lo is None else lo, "hi_kt": flown[1] if hi is None else hi,
            "source": "rule" if not missing else "rule and flown", "text": text}
