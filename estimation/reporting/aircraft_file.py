"""The report's aircraft TOML (`report --aircraft`): read, check and turn into title-block rows.

The title block shows `AIRCRAFT_FIELDS` in order, then any other key of the file's tables (a
fuel state, a flap setting: the file is the operator's own record). What is refused, in one
line naming the key: a file that is not TOML; a key that is a misspelling of a known one
(``registraton``, ``[aircaft]``: it would show under a wrong label and leave the field "not
stated"); a known field that is not text, a number or a date; NaN or infinite numbers
anywhere; a negative or zero weight; a negative speed (a key whose name says it is one).

The rule's speeds, KCAS, in [aircraft]: vs0_kcas, vs1_kcas (Part 23), vsr0_kcas, vsr1_kcas
(Part 25), vfe_kcas, vmo_kcas, vne_kcas; they must be positive numbers, each stall speed
below each limit speed (V_S0 at most V_S1, V_SR0 at most V_SR1). With
`configuration` one of cruise, takeoff, approach, landing they set the compliance verdict's
speed ranges (`aircraft_rule`); any other configuration text is shown and the airspeed check
keeps the flown range, except a misspelling of one of those words, which is refused.
"""

import datetime
import difflib
import math
import tomllib

from pitotcal.core.errors import PitotcalError

from ..identification.sensor_inputs import SENSOR_TOML_KEYS
from .regulations import CONFIGURATIONS, STALL_SPEED_KEYS

__all__ = ["AIRCRAFT_FIELDS", "aircraft_rule", "read_aircraft"]

# The title block: (TOML table, key, label), in the order shown.
AIRCRAFT_FIELDS = (
    ("aircraft", "type", "Aircraft"), ("aircraft", "registration", "Registration"),
    ("aircraft", "serial", "Serial number"), ("aircraft", "configuration", "Configuration"),
    ("aircraft", "weight", "Weight"), ("aircraft", "cg", "Centre of gravity"),
    ("aircraft", "pitot_static", "Pitot-static installation"),
    *(("aircraft", key, f"{symbol} (KCAS)") for key, symbol in STALL_SPEED_KEYS),
    ("test", "date", "Test date"), ("test", "location", "Location"),
    ("test", "pilot", "Pilot"), ("test", "engineer", "Flight-test engineer"),
    ("test", "notes", "Notes"),
    *(("sensors", key, label) for key, _, _, label in SENSOR_TOML_KEYS),
)
_TABLES = tuple(dict.fromkeys(table for table, _, _ in AIRCRAFT_FIELDS))
_KEYS = {table: [k for t, k, _ in AIRCRAFT_FIELDS if t == table] for table in _TABLES}
# what a title-block field may hold: text, a number (weight 1050, cg 0.42) or a TOML date
_FIELD_TYPES = (str, int, float, datetime.date, datetime.time)
# a key whose name ends so is a speed: never negative
_SPEED_SUFFIXES = ("_kt", "_kts", "_kias", "_kcas", "_ktas", "_mps", "_kmh", "_kph", "_mph")
_MISSPELT = 0.85        # difflib ratio from which an unknown name is a misspelt known one
# the configurations are four known words, so a closer miss is still a misspelling ("crusie"
# scores 0.83 against "cruise"); free text such as "flaps 10" stays far below
_MISSPELT_CONFIGURATION = 0.75


def read_aircraft(path):
    """The title-block rows [(label, text)] of an aircraft TOML (module docstring).

    Raises
    ------
    PitotcalError
        Not TOML, or a refused key or value; the message names the file and the key.
    """
    doc = _load(path)
    _check(doc, path)
    rows, seen = [], set()
    for table, key, label in AIRCRAFT_FIELDS:
        value = doc.get(table, {}).get(key) if isinstance(doc.get(table), dict) else None
        if value is not None:
            rows.append((label, str(value)))
            seen.add((table, key))
    for table, content in doc.items():
        items = content.items() if isinstance(content, dict) else [(None, content)]
        for key, value in items:
            if (table, key) not in seen:
                rows.append((f"{table}.{key}" if key else table, str(value)))
    return rows


def aircraft_rule(path):
    """{"configuration", "speeds_kcas"} of an aircraft TOML for the compliance verdict.

    configuration is one of `regulations.CONFIGURATIONS` or None (absent, or free text);
    speeds_kcas maps the symbols of `regulations.STALL_SPEED_KEYS` to the speeds given.

    Raises
    ------
    PitotcalError
        As `read_aircraft`; and a speed that is not a positive number, a stall speed not below
        a limit speed (or V_S0 above V_S1, V_SR0 above V_SR1), or a configuration that
        misspells one of the known ones, naming the keys.
    """
    doc = _load(path)
    _check(doc, path)
    table = doc.get("aircraft") if isinstance(doc.get("aircraft"), dict) else {}
    speeds = {}
    for key, symbol in STALL_SPEED_KEYS:
        value = table.get(key)
        if value is None:
            continue
        if not isinstance(value, (int, float)) or isinstance(value, bool) or value <= 0:
            raise PitotcalError(f"`aircraft_path` {path}: key aircraft.{key}: {value!r} is "
                                "not a speed (a positive number of KCAS)")
        speeds[symbol] = float(value)
    _check_speed_order(speeds, path)
    text = table.get("configuration")
    configuration = str(text).strip().lower() if text is not None else None
    if configuration not in CONFIGURATIONS:
        near = difflib.get_close_matches(configuration or "", CONFIGURATIONS, n=1,
                                         cutoff=_MISSPELT_CONFIGURATION)
        if near:
            raise PitotcalError(f"`aircraft_path` {path}: key aircraft.configuration: "
                                f"{text!r} is not one of {', '.join(CONFIGURATIONS)}; did "
                                f"you mean {near[0]!r}?")
        configuration = None
    return {"configuration": configuration, "speeds_kcas": speeds}


# A stall speed is below every limit speed, and the flaps-extended one at most the clean one:
# otherwise the rule's speed range is empty or reversed (1.3 V_S1 above V_NE) and nothing the
# verdict says could be trusted.
_STALL = (("V_S0", "vs0_kcas"), ("V_S1", "vs1_kcas"), ("V_SR0", "vsr0_kcas"),
          ("V_SR1", "vsr1_kcas"))
_LIMIT = (("V_FE", "vfe_kcas"), ("V_MO", "vmo_kcas"), ("V_NE", "vne_kcas"))


def _check_speed_order(speeds, path):
    """Refuse stall and limit speeds in an impossible order, naming both keys."""
    # (lower, higher, may they be equal)
    pairs = [(a, b, False) for a in _STALL for b in _LIMIT]
    pairs += [(_STALL[0], _STALL[1], True), (_STALL[2], _STALL[3], True)]
    for (low, low_key), (high, high_key), equal in pairs:
        if low not in speeds or high not in speeds:
            continue
        if speeds[low] > speeds[high] or (speeds[low] == speeds[high] and not equal):
            rule = "at most" if equal else "below"
            raise PitotcalError(
                f"`aircraft_path` {path}: keys aircraft.{low_key} {speeds[low]:g} and "
                f"aircraft.{high_key} {speeds[high]:g}: {low} must be {rule} {high}")


def _load(path):
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except tomllib.TOMLDecodeError as exc:
        raise PitotcalError(f"`aircraft_path` {path}: not valid TOML ({exc})") from None
    except UnicodeDecodeError:
        raise PitotcalError(f"`aircraft_path` {path}: not valid TOML (binary content, not "
                            "UTF-8 text)") from None
    except RecursionError:
        raise PitotcalError(f"`aircraft_path` {path}: not valid TOML (nested too deeply)") \
            from None
    except OSError as exc:
        raise PitotcalError(f"`aircraft_path` {path}: cannot read it ({exc.strerror})") \
            from None


def _check(doc, path):
    """Refuse misspelt names, wrongly typed fields and bad numbers (module docstring)."""
    def refuse(key, problem):
        raise PitotcalError(f"`aircraft_path` {path}: key {key}: {problem}")

    for table, content in doc.items():
        if not isinstance(content, dict):
            home = next((t for t, keys in _KEYS.items() if _near(table, keys)), None)
            if home:
                refuse(table, f"outside a table; put it under [{home}]")
        elif table not in _TABLES and _near(table, _TABLES):
            refuse(table, f"unknown table; did you mean [{_near(table, _TABLES)}]?")
        if not isinstance(content, dict):
            _check_value(table, content, refuse)
            continue
        known = _KEYS.get(table, [])
        for key, value in content.items():
            name = f"{table}.{key}"
            if key not in known and _near(key, known):
                refuse(name, f"unknown; did you mean {table}.{_near(key, known)}?")
            if key in known and (not isinstance(value, _FIELD_TYPES) or isinstance(value, bool)):
                refuse(name, f"{_type_name(value)}, expected text, a number or a date")
            _check_value(name, value, refuse)
            if name == "aircraft.weight" and isinstance(value, (int, float)) and value <= 0:
                refuse(name, f"{value:g} is not a weight (must be positive)")


def _check_value(name, value, refuse):
    """Numbers finite (recursively), speeds not negative."""
    if isinstance(value, dict):
        for key, inner in value.items():
            _check_value(f"{name}.{key}", inner, refuse)
    elif isinstance(value, list):
        for k, inner in enumerate(value):
            _check_value(f"{name}[{k}]", inner, refuse)
    elif isinstance(value, float) and not math.isfinite(value):
        refuse(name, f"{value} is not a finite number")
    elif isinstance(value, (int, float)) and not isinstance(value, bool) and value < 0 \
            and (name.lower().endswith(_SPEED_SUFFIXES) or "speed" in name.lower()):
        refuse(name, f"{value:g} is a negative speed")


def _near(name, candidates):
    """The known name `name` misspells, or None: a known name with a prefix or suffix added
    (`weight_kg`, `copilot`) is an extra key of its own, not a misspelling."""
    low = str(name).lower()
    close = difflib.get_close_matches(low, candidates, n=1, cutoff=_MISSPELT)
    if not close:
        return None
    known = close[0]
    added = len(low) - len(known)           # two letters or more: a word of its own
    if added >= 2 and (low.startswith(known) or low.endswith(known)):
        return None
    return known


def _type_name(value):
    kinds = {dict: "a table", list: "an array", bool: "true/false"}
    return next((text for kind, text in kinds.items() if isinstance(value, kind)),
                type(value).__name__)
