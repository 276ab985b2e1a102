"""The uncertainty budget's inputs: sensor classes, the temperature's source, where each came from.

Every Type B input of the budget (`estimation.identification.budget`) is a standard uncertainty
taken from, first to last: the value the caller gives (a `BudgetInputs` field; `origins` names
where the caller got it: a command-line flag, the aircraft TOML's ``[sensors]`` table), then for
u(OAT) the temperature's source, then the sensor class's default. docs/budget_inputs.md cites
the data sheets each class default comes from. Standard uncertainties (a rectangular limit a
counts a/√3):

=========================  ===========  =====  ========
input                      flight-test  ga     mems-uav
=========================  ===========  =====  ========
u_qc_scale (of reading)    0.1 %        0.5 %  1.5 %
u_qc_offset_pa             1            3      5
u_ps_pa (static)           10           50     100
u_oat_probe_k              1            1      1.5
u_gps_latency_s            0.05         0.05   0.1
u_gps_velocity_mps         0.05         0.05   0.05
=========================  ===========  =====  ========

u(OAT) by the temperature's source (`OAT_SOURCES`):

- ``probe``: a logged static OAT (`oat_k`), or the file's own density: the class's probe value;
- ``total-temperature``: a total-temperature probe (`tat_k`) converted with a recovery factor
  r: the probe's value with the recovery factor's own uncertainty, u_r = 0.03 (r known to
  ±0.05), through the ram rise: sqrt(u_probe² + (u_r 0.2 M² T)²) at the flight's 95th
  percentile Mach;
- ``user``: one temperature given for the whole flight (`oat_k` for a log): 1.5 K (the gauge's
  1 K and the air mass's change over the test block);
- ``ground-lapse``: a ground temperature carried up the standard lapse, 6.5 K/km: 3 K (real
  lapse rates run 4-9 K/km, with inversions, over the 1-3 km of a test altitude);
- ``isa``: ISA assumed: 11.5 K (the day's deviation from ISA anywhere within ±20 K);
- ``sensor-chip``: a baro or airspeed chip's own temperature: 11.5 K (the board runs 0-20 K
  above the air, one-sided: the RMS error of a uniform 0-20 K).
"""

import dataclasses
import math

import numpy as np

from pitotcal.core import checks
from pitotcal.core.errors import PitotcalError
from pitotcal.io.oat import GROUND_LAPSE_SOURCE

__all__ = ["CLASS_DEFAULTS", "DEFAULT_SENSOR_CLASS", "OAT_SOURCES", "SENSOR_CLASSES",
           "SENSOR_TOML_KEYS", "BudgetInputs", "detected_oat_source", "inputs_from_table",
           "resolve"]

SENSOR_CLASSES = ("flight-test", "ga", "mems-uav")
DEFAULT_SENSOR_CLASS = "flight-test"
CLASS_DEFAULTS = {
    "flight-test": {"u_qc_scale": 0.001, "u_qc_offset_pa": 1.0, "u_ps_pa": 10.0,
                    "u_oat_probe_k": 1.0, "u_gps_latency_s": 0.05, "u_gps_velocity_mps": 0.05},
    "ga": {"u_qc_scale": 0.005, "u_qc_offset_pa": 3.0, "u_ps_pa": 50.0,
           "u_oat_probe_k": 1.0, "u_gps_latency_s": 0.05, "u_gps_velocity_mps": 0.05},
    "mems-uav": {"u_qc_scale": 0.015, "u_qc_offset_pa": 5.0, "u_ps_pa": 100.0,
                 "u_oat_probe_k": 1.5, "u_gps_latency_s": 0.1, "u_gps_velocity_mps": 0.05},
}
RECTANGULAR_20K = 20.0 / math.sqrt(3.0)
# source name -> (in words, its u(OAT) in K; None: the sensor class's probe value)
OAT_SOURCES = {
    "probe": ("a static OAT probe", None),
    "total-temperature": ("a total-temperature probe with its recovery factor", None),
    "user": ("one temperature given for the whole flight", 1.5),
    "ground-lapse": ("a ground temperature with the standard lapse", 3.0),
    "isa": ("ISA assumed", RECTANGULAR_20K),
    "sensor-chip": ("a pressure chip's own temperature", RECTANGULAR_20K),
}
U_RECOVERY = 0.03                   # a probe's recovery factor known to ±0.05 (rectangular)
ARM_U_FRACTION = 0.1                # a measured lever arm: its own standard uncertainty
RH_U_GIVEN_PCT = 5.0                       # a humidity channel's standard uncertainty
RH_U_UNKNOWN_PCT = 100.0 / math.sqrt(3.0)  # dry assumed, truth anywhere in 0-100 %RH: RMS error
# (field, unit) of every standard uncertainty the budget propagates
UNITS = {"u_oat_k": "K", "u_rh_pct": "%RH", "u_gps_velocity_mps": "m/s",
         "u_gps_latency_s": "s", "u_probe_arm_m": "m", "u_qc_scale": "1",
         "u_qc_offset_pa": "Pa", "u_ps_pa": "Pa"}
# the aircraft TOML's [sensors] keys: (key, BudgetInputs field, scale to the field's unit, label)
SENSOR_TOML_KEYS = (
    ("class", "sensor_class", None, "Sensor class"),
    ("oat_source", "oat_source", None, "Temperature source"),
    ("u_oat_k", "u_oat_k", 1.0, "u(OAT), K"),
    ("u_rh_percent", "u_rh_pct", 1.0, "u(RH), %RH"),
    ("u_gps_velocity_mps", "u_gps_velocity_mps", 1.0, "u(GPS velocity bias), m/s"),
    ("u_gps_latency_s", "u_gps_latency_s", 1.0, "u(GPS latency), s"),
    ("probe_arm_m", "probe_arm_m", 1.0, "Probe lever arm, m"),
    ("u_probe_arm_m", "u_probe_arm_m", 1.0, "u(probe lever arm), m"),
    ("u_qc_scale_percent", "u_qc_scale", 0.01, "u(impact-pressure gain), % of reading"),
    ("u_qc_offset_pa", "u_qc_offset_pa", 1.0, "u(impact-pressure offset), Pa"),
    ("u_ps_pa", "u_ps_pa", 1.0, "u(static pressure), Pa"),
)


@dataclasses.dataclass(frozen=True)
class BudgetInputs:
    """The budget's Type B inputs; None takes the default (module notes).

    Attributes
    ----------
    u_oat_k, u_rh_pct, u_gps_velocity_mps, u_gps_latency_s, u_qc_scale, u_qc_offset_pa, u_ps_pa :
        Standard uncertainties (K, %RH, m/s, s, fraction of reading, Pa, Pa). `u_rh_pct` None:
        5 %RH with a humidity, else 58 %RH (dry assumed).
    probe_arm_m : float
        A lateral probe offset the data were NOT corrected for, m: counted wholly as the
        lever-arm term. An arm known and corrected is `identify(..., probe_arm_m=)`; its
        uncertainty is `u_probe_arm_m` (default 10 % of the arm).
    u_probe_arm_m : float or None
    sensor_class : {"flight-test", "ga", "mems-uav"} or None
        The class whose defaults fill what is not given; None: "flight-test".
    oat_source : str or None
        One of `OAT_SOURCES`; None: from the flight (`detected_oat_source`).
    origins : dict
        Field -> where the caller's value came from (e.g. a flag); a given value without one
        is "given".
    """

    u_oat_k: float | None = None
    u_rh_pct: float | None = None
    u_gps_velocity_mps: float | None = None
    u_gps_latency_s: float | None = None
    probe_arm_m: float = 0.0
    u_qc_scale: float | None = None
    u_qc_offset_pa: float | None = None
    u_ps_pa: float | None = None
    u_probe_arm_m: float | None = None
    sensor_class: str | None = None
    oat_source: str | None = None
    origins: dict = dataclasses.field(default_factory=dict)

    def checked(self):
        """A copy with every value checked (PitotcalError naming the field)."""
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is None or f.name == "origins":
                out[f.name] = value
            elif f.name == "sensor_class":
                out[f.name] = checks.choice("sensor_class", value, SENSOR_CLASSES)
            elif f.name == "oat_source":
                out[f.name] = checks.choice("oat_source", value, tuple(OAT_SOURCES))
            elif f.name == "probe_arm_m":
                out[f.name] = checks.number(f.name, value, -50.0, 50.0)
            else:
                out[f.name] = checks.number(f.name, value, 0.0)
        if not isinstance(self.origins, dict):
            raise PitotcalError("`origins` must be a dict of field -> text", param="origins")
        return BudgetInputs(**out)


def detected_oat_source(flight):
    """(source name of `OAT_SOURCES`, what the flight says): from its reading's `oat_source`."""
    reading = getattr(flight, "reading", None) or {}
    text = reading.get("oat_source") or flight.meta.get("temperature_source") \
        or flight.meta.get("oat_k_source")
    if text is None:
        if flight.tat_k is not None:
            return "total-temperature", "tat_k"
        return "probe", "oat_k" if flight.oat_k is not None else "the flight's rho_kgm3"
    text = str(text)
    if GROUND_LAPSE_SOURCE in text:
        return "ground-lapse", text
    if "given by the user" in text:
        return "user", text
    if "sensor temperature" in text:
        return "sensor-chip", text
    if text.startswith("ISA"):
        return "isa", text
    if text.startswith("tat_k"):
        return "total-temperature", text
    return "probe", text


def _u_total_temperature(flight, u_probe_k):
    """u(OAT) of a total-temperature probe: the probe's and the recovery factor's, K."""
    from pitotcal.core.airdata import mach_from_qc
    from pitotcal.core.units import R_AIR_JKGK

    if flight.ps_pa is None:
        return u_probe_k
    mach = np.nanpercentile(mach_from_qc(np.maximum(flight.qci_pa, 0.0), flight.ps_pa), 95)
    t_k = flight.oat_k if flight.oat_k is not None else flight.ps_pa / (R_AIR_JKGK
                                                                        * flight.rho_kgm3)
    ram_k = 0.2 * mach ** 2 * float(np.nanmedian(t_k))
    return math.hypot(u_probe_k, U_RECOVERY * ram_k)


def resolve(inputs, flight):
    """(`inputs` with every uncertainty filled, the input list [{input, value, unit, origin}]).

    The list is the JSON's ``budget_inputs``: the sensor class, the temperature's source, the
    lever arm corrected in the data (from `flight.reading`), then each standard uncertainty.
    """
    inputs = (inputs or BudgetInputs()).checked()
    given = {k: v for k, v in inputs.origins.items()}

    def origin(field, fallback):
        return given.get(field, "given") if getattr(inputs, field) is not None else fallback

    cls = inputs.sensor_class or DEFAULT_SENSOR_CLASS
    defaults = CLASS_DEFAULTS[cls]
    rows = [{"input": "sensor_class", "value": cls, "unit": "",
             "origin": origin("sensor_class", "default")}]
    detected, said = detected_oat_source(flight)
    source = inputs.oat_source or detected
    rows.append({"input": "oat_source", "value": source, "unit": "",
                 "origin": origin("oat_source", f"the flight: {said}")})
    corrected = float((getattr(flight, "reading", None) or {}).get("probe_arm_m") or 0.0)
    rows.append({"input": "probe_arm_m", "value": corrected, "unit": "m",
                 "origin": "corrected in the data" if corrected else "none corrected"})

    values, where = {}, {}
    class_note = f"default of class {cls}"
    for field in ("u_qc_scale", "u_qc_offset_pa", "u_ps_pa", "u_gps_latency_s",
                  "u_gps_velocity_mps"):
        values[field] = getattr(inputs, field, None)
        values[field] = defaults[field] if values[field] is None else values[field]
        where[field] = origin(field, class_note)
    u_oat = OAT_SOURCES[source][1]
    if u_oat is None:
        u_oat = defaults["u_oat_probe_k"]
        if source == "total-temperature":
            u_oat = _u_total_temperature(flight, u_oat)
    values["u_oat_k"] = u_oat if inputs.u_oat_k is None else inputs.u_oat_k
    where["u_oat_k"] = origin("u_oat_k", f"default for the source {source}"
                              + (f", class {cls}" if OAT_SOURCES[source][1] is None else ""))
    has_rh = flight.rh_pct is not None
    values["u_rh_pct"] = (inputs.u_rh_pct if inputs.u_rh_pct is not None
                          else RH_U_GIVEN_PCT if has_rh else RH_U_UNKNOWN_PCT)
    where["u_rh_pct"] = origin("u_rh_pct", "default with a humidity" if has_rh
                               else "default: dry air assumed")
    values["u_probe_arm_m"], where["u_probe_arm_m"] = _arm_uncertainty(inputs, corrected, origin)
    for field, unit in UNITS.items():
        rows.append({"input": field, "value": float(values[field]), "unit": unit,
                     "origin": where[field]})
    out = dataclasses.replace(inputs, sensor_class=cls, oat_source=source, **values)
    return out, rows


def _arm_uncertainty(inputs, corrected_m, origin):
    """(u of the lever arm, m; where from): given; 10 % of an arm corrected in the data; else
    the whole of an arm stated but not corrected (`BudgetInputs.probe_arm_m`)."""
    if inputs.u_probe_arm_m is not None:
        return inputs.u_probe_arm_m, origin("u_probe_arm_m", "")
    if corrected_m:
        return ARM_U_FRACTION * abs(corrected_m), "default: 10 % of the corrected arm"
    if inputs.probe_arm_m:
        return abs(inputs.probe_arm_m), "the arm not corrected, counted wholly"
    return 0.0, "default: probe on the centre line"


def inputs_from_table(table, where):
    """`BudgetInputs` keyword options and their origins from an aircraft TOML's ``[sensors]``.

    Parameters
    ----------
    table : dict
        The ``[sensors]`` table (keys `SENSOR_TOML_KEYS`; other keys are the operator's own).
    where : str
        The file, for the messages and origins.

    Returns
    -------
    (dict, dict)
        Field -> value, field -> origin.
    """
    options, origins = {}, {}
    for key, field, scale, _ in SENSOR_TOML_KEYS:
        if key not in table:
            continue
        value = table[key]
        name = f"`aircraft_path` {where}: key sensors.{key}"
        if scale is None:
            choices = SENSOR_CLASSES if field == "sensor_class" else tuple(OAT_SOURCES)
            value = checks.choice(name, value, choices)
        else:
            lo = -50.0 if field == "probe_arm_m" else 0.0
            value = checks.number(name, value, lo, 50.0 if field == "probe_arm_m" else math.inf)
            value *= scale
        options[field] = value
        origins[field] = f"aircraft file sensors.{key}"
    return options, origins
