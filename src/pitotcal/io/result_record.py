"""Reading a result record (`pitotcal identify --json`, docs/interfaces.md §3): the one
reader, for `identify --live`, `report`, `monitor` and `plan --calibration` alike.

`read_result` validates what it returns: a missing or wrong-typed key is a one-line
PitotcalError naming the file and the key. Records written before the noise model, the stated
GPS error and the reading were part of them (`RECORD_KEYS`) are read as they are;
`missing_record_keys` says what they lack, for a warning.
"""

import math
import os

from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import MAX_PRESSURE_ERROR, MODELS, get_model, worst_pressure_error

from .jsonfile import read_json

__all__ = ["RECORD_KEYS", "check_noise_model", "missing_record_keys", "read_result",
           "record_calibration"]

# Keys a record holds since the monitor's noise model, the stated GPS error and the reading
# were added to it.
RECORD_KEYS = ("noise_model", "gps_error", "reading")
_AIR_DATA = ("incompressible", "compressible")
_WIND = ("wind_speed_mps", "wind_from_deg")

_NUMBER = (int, float)
# (key, accepted types, description); checked when present, the first three also required
_TOP = (
    ("airspeed_correction", list, "a list of rows"),
    ("model", str, "a model name"),
    ("parameters", dict, "an object"),
    ("air_data", str, "compressible or incompressible"),
    ("converged", bool, "true or false"),
    ("warnings", list, "a list"),
    ("noise_std_pa", (*_NUMBER, type(None)), "a number"),
    ("gps_noise_std_mps", (*_NUMBER, type(None)), "a number"),
    ("noise_model", (dict, type(None)), "an object or null"),
    ("gps_error", (dict, type(None)), "an object or null"),
    ("reading", (dict, type(None)), "an object or null"),
    ("uncertainty_budget", list, "a list"),
    ("static_source", dict, "an object"),
)
_REQUIRED = 3
# every row has its speed; the correction and its 2-sigma are checked when present
_ROW_KEYS = ("vi_kt", "dv_kt", "dv_2sigma_kt")


def read_result(source, *, name=None, table=True):
    """A result record of `pitotcal identify --json`, validated.

    Parameters
    ----------
    source : str, path-like or dict
        The JSON file, or its content already parsed (anything but an object is refused).
    name : str, optional
        How errors name the record (e.g. ``"--calibration result.json"``); default the path,
        or ``"<memory>"`` for a dict.
    table : bool
        Require the airspeed-correction table (a report does; the monitor and the planner use
        only the model, its coefficients and the wind).

    Returns
    -------
    dict
        The record (a shallow copy). Keys an older record lacks (`RECORD_KEYS`) stay absent:
        `missing_record_keys` lists them.

    Raises
    ------
    PitotcalError
        One line naming the file and the key: not JSON, not an object, a required key
        (airspeed_correction with each row's vi_kt, model, parameters with each
        coefficient's value) missing, or any known key of the wrong type (the wind's
        parameters included).
    """
    if not isinstance(source, (str, os.PathLike)):
        # a document already parsed (an object, or whatever else the JSON held)
        label, doc = name or "<memory>", source
    else:
        label = name or str(source)
        doc = read_json(source, label)
    if not isinstance(doc, dict):
        raise PitotcalError(f"{label}: not a pitotcal identify result JSON (not an object)")
    for i, (key, types, what) in enumerate(_TOP):
        if key not in doc:
            if i < _REQUIRED and (table or key != "airspeed_correction"):
                missing = "airspeed_correction table" if i == 0 else f"key '{key}'"
                raise PitotcalError(f"{label}: not a pitotcal identify result JSON "
                                    f"(no {missing})")
            continue
        _check_type(label, key, doc[key], types, what)
    if table and not doc["airspeed_correction"]:
        raise PitotcalError(f"{label}: not a pitotcal identify result JSON (no "
                            "airspeed_correction table: the list is empty)")
    for j, row in enumerate(doc.get("airspeed_correction", ())):
        _check_type(label, f"airspeed_correction[{j}]", row, dict, "an object")
        for key in _ROW_KEYS:
            if key == "vi_kt" or key in row:
                _check_number(label, f"airspeed_correction[{j}].{key}", row, key)
        _check_range(label, f"airspeed_correction[{j}].vi_kt", float("nan") if
                     row["vi_kt"] is None else row["vi_kt"], 0.0, math.inf, "an airspeed",
                     low_open=True)
    if doc["model"] not in MODELS:
        raise PitotcalError(f"{label}: not a pitotcal identify result JSON: key 'model' is "
                            f"{doc['model']!r}, not one of "
                            f"{', '.join(MODELS)}")
    if doc.get("air_data", "incompressible") not in _AIR_DATA:
        raise PitotcalError(f"{label}: not a pitotcal identify result JSON: key 'air_data' is "
                            f"{doc['air_data']!r}, not "
                            f"{' or '.join(_AIR_DATA)}")
    for par in (*get_model(doc["model"]).params, *_WIND):
        if par in _WIND and par not in doc["parameters"]:
            continue                    # needed by the monitor only: `record_calibration`
        entry = doc["parameters"].get(par)
        _check_type(label, f"parameters.{par}", entry, dict, "an object with a value")
        _check_number(label, f"parameters.{par}.value", entry, "value")
    _check_pressure_error(label, doc)
    _check_range(label, "noise_std_pa", doc.get("noise_std_pa"), 0.0, math.inf,
                 "a positive noise", low_open=True)
    if doc.get("noise_model") is not None:
        check_noise_model(label, doc["noise_model"])
    return dict(doc)


_WHERE = {True: "at the table's speeds", False: "(k1, no table)"}


def _check_pressure_error(label, doc):
    """The record's pressure error |f(q_ci; k)| within MAX_PRESSURE_ERROR at the speeds of its
    table (the rule `simulate` holds its truth to), or |k1| without a table."""
    model = get_model(doc["model"])
    k = [doc["parameters"][name]["value"] for name in model.params]
    for name, value in zip(model.params, k):
        if value is None:       # its table, if any, is no calibration's either
            raise PitotcalError(f"{label}: key 'parameters.{name}.value' is null: the fit gave "
                                "no value, so the record is not a calibration",
                                param=f"parameters.{name}.value")
    vi = [row["vi_kt"] for row in doc.get("airspeed_correction", ())]
    worst = (worst_pressure_error(model, k, vi, doc.get("air_data", "incompressible")) if vi
             else abs(k[0]))
    if not worst < MAX_PRESSURE_ERROR:
        keys = ", ".join(f"'parameters.{n}.value' {v:g}" for n, v in zip(model.params, k))
        raise PitotcalError(f"{label}: keys {keys}: not a pitot-static system's "
                            f"calibration: |dp/qc| reaches {worst:.3g} "
                            f"{_WHERE[bool(vi)]}, at "
                            f"most {MAX_PRESSURE_ERROR:g}")
# The noise model's scales (relative to q_ci; m/s): positive, finite and below these bounds
# (a residual as large as q_ci itself, or 50 m/s of airspeed, is no calibration's noise).
_NOISE_BOUNDS = (("block_s", 1e6), ("rel_std", 1.0), ("innovation_rel_std", 1.0),
                 ("std_mps", 50.0), ("innovation_std_mps", 50.0))


def check_noise_model(label, noise):
    """A record's `noise_model` (a dict): positive finite scales within `_NOISE_BOUNDS`, AR
    coefficients finite and |ar1| < 1; a PitotcalError naming `label` and the key otherwise.
    `identify` holds its own noise model to this rule, so a record it writes is one the
    monitor reads."""
    for key, upper in _NOISE_BOUNDS:
        if key in noise or key in ("block_s", "rel_std"):
            value = noise.get(key)
            _check_type(label, f"noise_model.{key}", value, _NUMBER, "a number")
            _check_range(label, f"noise_model.{key}", value, 0.0, upper,
                         f"a positive noise scale up to {upper:g}", low_open=True)
    if "ar1" in noise:
        _check_type(label, "noise_model.ar1", noise["ar1"], _NUMBER, "a number")
        _check_range(label, "noise_model.ar1", noise["ar1"], -1.0, 1.0,
                     "an AR(1) coefficient, |ar1| < 1", low_open=True, high_open=True)
    for key in ("ar", "ar_mps"):
        values = noise.get(key, [])
        _check_type(label, f"noise_model.{key}", values, list, "a list of numbers")
        for i, value in enumerate(values):
            _check_type(label, f"noise_model.{key}[{i}]", value, _NUMBER, "a number")
            _check_range(label, f"noise_model.{key}[{i}]", value, -math.inf, math.inf,
                         "a finite number")


def _check_range(label, key, value, lo, hi, what, low_open=False, high_open=False):
    """A number `value` (None passes: a null the reader of that key handles) finite and in
    [lo, hi] (open at an end when asked); a PitotcalError naming `key` otherwise."""
    if value is None:
        return
    x = float(value)
    if not math.isfinite(x) or x < lo or x > hi or (low_open and x == lo) \
            or (high_open and x == hi):
        raise PitotcalError(f"{label}: key '{key}' is {value!r}, not {what}: the record is "
                            "not a usable calibration", param=key)


def _check_type(label, key, value, types, what):
    # bool is an int to isinstance: a number key must not take true/false
    wrong_bool = isinstance(value, bool) and bool not in (types if isinstance(types, tuple)
                                                          else (types,))
    if wrong_bool or not isinstance(value, types):
        raise PitotcalError(f"{label}: not a pitotcal identify result JSON: key '{key}' is "
                            f"{_json_type(value)}, expected {what}")


def _check_number(label, key, entry, field):
    if field not in entry:
        raise PitotcalError(f"{label}: not a pitotcal identify result JSON (no key '{key}')")
    _check_type(label, key, entry[field], (*_NUMBER, type(None)), "a number")
    # JSON has no NaN or Infinity; Python's parser reads them, pitotcal writes null
    if entry[field] is not None and not math.isfinite(entry[field]):
        raise PitotcalError(f"{label}: key '{key}' is {entry[field]!r}, not a finite number "
                            "(null where a value is missing)", param=key)


def _json_type(value):
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean",
            type(None): "null"}.get(type(value), "a number")


def missing_record_keys(record):
    """The `RECORD_KEYS` an (older) record lacks."""
    return tuple(key for key in RECORD_KEYS if key not in record)


def record_calibration(record, name="<memory>", wind=True):
    """(model, k, wind_speed_mps, wind_from_deg, air_data) of a validated record; a
    PitotcalError naming `name` and the key when a value the calibration needs is not finite
    (a solve that did not converge writes null). `wind` False: the wind is not needed (None)."""
    model = get_model(record["model"])
    values = {}
    for par in (*model.params, *(_WIND if wind else ())):
        if par not in record["parameters"]:
            raise PitotcalError(f"{name}: not a pitotcal identify result JSON (no key "
                                f"'parameters.{par}')")
        value = record["parameters"][par]["value"]
        if value is None or not math.isfinite(value):
            raise PitotcalError(f"{name}: key 'parameters.{par}.value' is {value}, not a "
                                "finite number: the result is not a calibration")
        values[par] = float(value)
    return (model.name, tuple(values[p] for p in model.params), values.get(_WIND[0]),
            values.get(_WIND[1]), record.get("air_data", "incompressible"))
