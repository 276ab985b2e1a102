"""The airspeed parameter an autopilot should load, from a calibration flight.

Derivation. Both autopilots turn the sensor's differential pressure Δp (offset removed; the
q_ci pitotcal reads from the log, ArduPilot ``ARSP.DiffPress``, PX4 ``differential_pressure``)
into an airspeed with one scale, and the calibration says which airspeed that pressure means:
q_c = q_ci / (1 − f(q_ci)) and V_c = CAS law of q_c.

- ArduPilot: EAS = sqrt(ARSPD_RATIO · Δp) (incompressible convention). It is right when
  ratio · q_ci = V_c², so ratio = V_c(q_c)² / q_ci; with the incompressible V_c² = 2 q_c / ρ₀
  and the constant model f = k1 this is ratio = 2 / (ρ₀ (1 − k1)). The log's current ratio
  cancels: ArduPilot logs Δp before applying it (a log with only ``ARSP.Airspeed`` is turned
  back into Δp = EAS² / ratio by the reader), so the new ratio is the current one times
  V_c² / EAS², reported as that factor beside the current value.
- PX4: CAS = ASPD_SCALE_1 · IAS with IAS = sqrt(2 Δp / ρ₀), so scale = V_c / IAS
  = 1 / sqrt(1 − k1) for the constant model.

Both use the best constant model (one scale over the flown range). With the compressible air
data of a result whose ``air_data`` is "compressible", V_c is the isentropic CAS law and the
ratio is evaluated at the median q_ci flown (it then drifts by ~(V/a₀)²/4 across speeds,
0.1 % at 50 kt). The 2σ follows from k1's 2σ (delta method).

Structure misfit. The 2σ is statistical only: one value cannot represent a pressure error that
changes with speed. Beside it the recommendation states what the single value costs over the
flown V_i range against the two-coefficient model (inverse or linear, whichever departs more):
the largest |ΔV_model − ΔV_constant| (kt) with that model's ΔV 2σ there, and the span
(min–max) of the local ratio/scale the model implies, V_c,model(V_i)² / q_ci(V_i) (PX4:
V_c / IAS).

Refusals (a `PitotcalError`, exit 2, one line): the track turned through less than
`MIN_TRACK_SPREAD_DEG`; the constant-model fit did not converge; one scale cannot represent the
error (the scale right at cruise is wrong near the stall; a `ParameterRefused` carrying the
structure misfit): the structure misfit exceeds `misfit_tolerance_kt` (default
`MISFIT_TOLERANCE_KT`, a third of the 5 kt airspeed limit of 23.1323(b)/25.1323(c)) *and* that
model departs from the constant one by more than its own 2σ there (practically and
statistically significant: a departure of 0.03 kt, however certain, costs nothing); the 2σ of
the new value is wider than `TOLERANCE` of it while the current value lies inside that band (the
flight cannot improve on it).

PX4's sensor model. PX4 applies ASPD_SCALE to its IAS *after* its own compensation of an SDP3x
sensor's tube and pitot losses (``CAL_AIR_CMODEL`` with ``CAL_AIR_TUBELEN``,
``CAL_AIR_TUBED_MM``; PX4 ``lib/airspeed/airspeed.cpp``, ``calc_IAS_corrected``), while the scale
here is V_c relative to sqrt(2 Δp / ρ₀) of the logged Δp. When the log enables an SDP3x
(``SENS_EN_SDP3X``) the recommendation warns and states what PX4's compensation adds at the
median q_ci flown (models 0 and 1, the sensor's flow model; model 2's tube loss is not
evaluated): the scale to load is about the one written divided by that factor. Not when q_ci
was itself made of PX4's compensated IAS (the log reader's fallback, ``qc_source``
``airspeed.indicated_airspeed_m_s ...``): the scale is then relative to that IAS already.
"""

import warnings
from dataclasses import dataclass, field

import numpy as np

from pitotcal.core.checks import number
from pitotcal.core.errors import ObservabilityError, PitotcalError
from pitotcal.core.measurement import DEFAULT_AIR_DATA
from pitotcal.core.propagation import band, gradient
from pitotcal.core.units import RHO0_KGM3
from pitotcal.io.param_files import ARDUPILOT_RATIO, PX4_SCALES

from .compliance import REGULATIONS

__all__ = ["MIN_TRACK_SPREAD_DEG", "MISFIT_STEP_KT", "MISFIT_TOLERANCE_KT",
           "MISFIT_TOLERANCE_MAX_KT", "TOLERANCE", "ParameterRecommendation", "ParameterRefused",
           "SENSOR_PARAMETERS", "check_misfit_tolerance", "misfit_text", "px4_sensor_note",
           "recommend", "recommend_sensors", "sensor_parameter", "sensor_params_text",
           "write_parameter_file", "write_parameter_set"]

# A parameter is committed only after turning through three quarters of a circle: wind and
# scale then separate with margin (identify itself needs only more than half a circle).
MIN_TRACK_SPREAD_DEG = 270.0
# Relative 2σ of the airspeed the new parameter gives above which a flight that cannot tell
# the new value from the current one is refused: 1 % of airspeed (2 % of ARSPD_RATIO).
TOLERANCE = 0.01
# The parameter written when the log has none of its names (PX4: the current name first)
PARAMETER = {"ArduPilot": ARDUPILOT_RATIO, "PX4": PX4_SCALES[0]}
# The structure misfit one value may have before it is refused, kt: a third of the smallest
# airspeed limit (5 kt), so that a single scale leaves two thirds of the limit to the rest of
# the position error and the calibration's own uncertainty
MISFIT_TOLERANCE_KT = REGULATIONS["23.1323"]["floor_kt"] / 3.0
# ... and the largest tolerance that still means one: beyond it any single value would pass
MISFIT_TOLERANCE_MAX_KT = 50.0
# Grid of the structure misfit, kt: fine enough that the largest departure between the flown
# ends is not missed (the correction table's coarser grid keeps the refusal rule unchanged)
MISFIT_STEP_KT = 1.0


class ParameterRefused(PitotcalError):
    """No parameter recommended because one value cannot represent the error; `misfit` is the
    structure misfit (`ParameterRecommendation.misfit`) that says what it would cost."""

    def __init__(self, message, misfit):
        super().__init__(message)
        self.misfit = misfit


@dataclass(frozen=True)
class ParameterRecommendation:
    """A new airspeed parameter and why.

    Attributes
    ----------
    autopilot : {"ArduPilot", "PX4"}
    name : str
        ``ARSPD_RATIO`` or ``ASPD_SCALE_1`` (``ASPD_SCALE`` on older PX4 logs that have it).
    value, two_sigma : float
        The recommended value and its 2σ.
    current : float or None
        The value the log was flown with.
    k1, k1_two_sigma : float
        The constant model's coefficient Δp/q_c and its 2σ.
    qci_ref_pa : float
        Median q_ci flown, where a compressible ratio is evaluated.
    air_data : str
    track_spread_deg : float
    departures : dict
        Model -> {max_departure_kt, two_sigma_kt, vi_kt}: the largest |ΔV_model − ΔV_constant|
        over the flown range relative to the model's 2σ there.
    misfit : dict or None
        The structure misfit (module docstring): {model, max_dv_kt, vi_kt, two_sigma_kt,
        local_min, local_max, vi_min_kt, vi_max_kt}; None when no two-coefficient model was
        identifiable.
    notes : tuple of str
    """

    autopilot: str
    name: str
    value: float
    two_sigma: float
    current: float | None
    k1: float
    k1_two_sigma: float
    qci_ref_pa: float
    air_data: str
    track_spread_deg: float
    departures: dict = field(default_factory=dict)
    notes: tuple = ()
    misfit: dict | None = None

    def misfit_line(self):
        """The structure misfit in one line (ASCII: it goes into parameter files)."""
        return misfit_text(self.name, self.misfit)

    def to_dict(self):
        """The JSON record: name, value, two_sigma, current, structure_misfit."""
        return {"name": self.name, "value": self.value, "two_sigma": self.two_sigma,
                "current": self.current, "structure_misfit": self.misfit}

    def comments(self):
        """The comment lines of the parameter file."""
        cur = "not in the log" if self.current is None else f"{self.current:.6g}"
        lines = [f"pitotcal: {self.name} = {self.value:.6f} +/- {self.two_sigma:.6f} (2 sigma)",
                 self.misfit_line(),
                 (f"current value {cur}; constant model k1 = {self.k1:.5f} +/- "
                  f"{self.k1_two_sigma:.5f} (2 sigma), air data {self.air_data}"),
                 f"track turned through {self.track_spread_deg:.0f} deg"]
        if self.current:
            lines.append(f"new / current = {self.value / self.current:.5f}")
        return lines + list(self.notes)


def recommend(flight, autopilot, current=None, *, name=None, air=DEFAULT_AIR_DATA,
              misfit_tolerance_kt=None, log_parameters=None, fits=None, **noise):
    """The airspeed parameter for `autopilot` from `flight`, or a refusal.

    Parameters
    ----------
    flight : Flight
    autopilot : {"ArduPilot", "PX4"}
    current : float, optional
        The value the log was flown with.
    name : str, optional
        Parameter name (default ``ARSPD_RATIO`` / ``ASPD_SCALE_1``).
    air : {"compressible", "incompressible"}
        Passed to `identify` (a flight without static pressure is fitted incompressible).
    misfit_tolerance_kt : float, optional
        The structure misfit above which one value is refused, kt (default
        `MISFIT_TOLERANCE_KT`).
    log_parameters : dict, optional
        The log's parameters by name (PX4: ``SENS_EN_SDP3X``, ``CAL_AIR_CMODEL``, ...): a
        warning when PX4 scales a compensated IAS (`px4_sensor_note`).
    fits : dict, optional
        {model: IdentificationResult} of this flight already fitted ("constant", and
        "inverse"/"linear" where identifiable), used instead of fitting again: a sensor's
        results of the joint fit of several sensors sharing one wind
        (`estimation.identification.multi_sensor`).
    **noise
        `identify`'s noise keywords, passed on: ``gps_noise_std_mps``, ``gps_error_sigma_mps``,
        ``gps_error_tau_s``.

    Returns
    -------
    ParameterRecommendation

    Raises
    ------
    PitotcalError
        Exit 2: the track did not turn enough, one scale cannot represent the error, or the
        bounds are too wide to improve on the current value (module docstring).
    """
    from ..identification.identify import identify, track_spread_deg

    if autopilot not in PARAMETER:
        raise PitotcalError(f"no airspeed parameter for autopilot {autopilot!r}: the flight "
                            "must come from an ArduPilot or PX4 log (or its converted CSV)")
    name = name or PARAMETER[autopilot]
    tolerance = (MISFIT_TOLERANCE_KT if misfit_tolerance_kt is None else
                 check_misfit_tolerance(misfit_tolerance_kt))
    spread = track_spread_deg(flight.gps_vn_mps, flight.gps_ve_mps)
    if spread < MIN_TRACK_SPREAD_DEG:
        raise PitotcalError(f"no parameter recommended: the track turned through only "
                            f"{spread:.0f} deg (need {MIN_TRACK_SPREAD_DEG:.0f} before "
                            f"committing {name}); fly a full circle")
    const = identify(flight, model="constant", air=air, **noise) if fits is None \
        else fits["constant"]
    if not const.success:
        raise PitotcalError(f"no parameter recommended: the constant-model fit did not "
                            f"converge ({const.message})")
    fits, notes = (_two_coefficient_fits(flight, noise, air) if fits is None else
                   ({m: fits[m] for m in ("inverse", "linear") if m in fits}, []))
    departures = {m: _departure(const, res) for m, res in fits.items()}
    air = getattr(const, "air_data", None) or "incompressible"
    qref = float(np.median(const.qci_pa))
    k1, k1_sd = const.value("k1"), const.stddev("k1")
    value = _parameter(autopilot, k1, qref, air)
    misfit = _misfit(autopilot, value, const, fits, air)
    notes += [n for n in (_judge_misfit(name, misfit, departures, tolerance),) if n]
    if autopilot == "PX4":
        sensor = px4_sensor_note(log_parameters or {}, flight)
        if sensor:
            warnings.warn(sensor, stacklevel=2)
            notes.append(sensor)
    grad = gradient(lambda k: _parameter(autopilot, k[0], qref, air), [k1])
    two_sigma = 2.0 * float(band(grad, np.array([[k1_sd ** 2]])))
    _check_bounds(name, value, two_sigma, current, autopilot)
    if current is not None and abs(value - current) <= two_sigma:
        notes.append("the current value is inside the 2 sigma band: the change is not "
                     "significant, keeping the current value is as good")
    return ParameterRecommendation(autopilot, name, value, two_sigma, current, k1, 2 * k1_sd,
                                   qref, air, spread, departures, tuple(notes), misfit)


# The flight's `qc_source` when the PX4 reader made q_ci of PX4's compensated IAS (½ ρ0 IAS²)
_PX4_COMPENSATED_QC = "airspeed.indicated_airspeed_m_s"
# PX4 CAL_AIR_CMODEL values whose SDP3x flow model `px4_sensor_note` evaluates
_PX4_FLOW_MODELS = {0: "model with pitot", 1: "model without pitot"}


def px4_sensor_note(log_parameters, flight):
    """A warning (str) when the log's PX4 scales an IAS its SDP3x compensation has changed, else
    None (module docstring); the factor IAS_PX4 / sqrt(2 Δp/ρ₀) at the median q_ci flown."""
    if not log_parameters.get("SENS_EN_SDP3X"):
        return None
    if str(flight.meta.get("qc_source", "")).startswith(_PX4_COMPENSATED_QC):
        # q_ci made of PX4's own IAS: the scale is already relative to the compensated IAS
        return None
    cmodel = int(log_parameters.get("CAL_AIR_CMODEL", 0))
    tube_m = float(log_parameters.get("CAL_AIR_TUBELEN", 0.2))
    text = (f"PX4 applies ASPD_SCALE to an IAS that already includes its SDP3x compensation "
            f"(SENS_EN_SDP3X set, CAL_AIR_CMODEL {cmodel}); the scale here is relative to "
            "sqrt(2 dp/rho0) without it")
    if cmodel not in _PX4_FLOW_MODELS:
        return text + ": check the scale against PX4's own IAS before loading it"
    qci = float(np.median(flight.qci_pa))
    ps = float(np.median(flight.ps_pa)) if flight.ps_pa is not None else 101325.0
    rho = float(np.median(flight.rho_kgm3))
    factor = _sdp3x_ias(qci, ps, rho, tube_m, cmodel == 0) / np.sqrt(2 * qci / RHO0_KGM3)
    return (text + f": at the median dp flown ({qci:.0f} Pa) PX4's {_PX4_FLOW_MODELS[cmodel]} "
            f"raises IAS by a factor {factor:.4f}, so load about the value written / "
            f"{factor:.4f}")


def _sdp3x_ias(dp_pa, ps_pa, rho_kgm3, tube_m, pitot):
    """PX4's compensated IAS of an SDP3x (calc_IAS_corrected, CAL_AIR_CMODEL 0 or 1), m/s."""
    dp_corr = dp_pa * 96600.0 / ps_pa
    flow = max((300.805 - 300.878 / (0.00344205 * dp_corr ** 0.68698 + 1.0)) * 1.29 / rho_kgm3,
               0.0)
    dp_pitot = (0.0032 * flow ** 2 + 0.0123 * flow + 1.0) * 1.29 / rho_kgm3 if pitot else 0.0
    dp_tube = flow * 0.674 / 450.0 * tube_m * rho_kgm3 / 1.29
    return np.sqrt(2.0 * (dp_corr + dp_tube + dp_pitot) / RHO0_KGM3) + 0.125 * flow


def check_misfit_tolerance(misfit_tolerance_kt):
    """`misfit_tolerance_kt` checked: above 0, at most `MISFIT_TOLERANCE_MAX_KT` kt."""
    return number("misfit_tolerance_kt", misfit_tolerance_kt, 0.0, MISFIT_TOLERANCE_MAX_KT,
                  lo_open=True)


def _judge_misfit(name, misfit, departures, tolerance):
    """The note stating the structure misfit of one value, or a `ParameterRefused` when it is
    beyond `tolerance` and its model departs beyond its own 2σ (module docstring)."""
    if misfit is None:            # no two-coefficient model: its notes say so
        return None
    significant = [m for m, d in departures.items() if d["max_departure_kt"] > d["two_sigma_kt"]]
    if significant and misfit["max_dv_kt"] > tolerance:
        d = departures[significant[0]]
        raise ParameterRefused(
            f"no parameter recommended: the {significant[0]} model departs from one scale by "
            f"{d['max_departure_kt']:.2f} kt at {d['vi_kt']:.0f} KIAS (its 2 sigma "
            f"{d['two_sigma_kt']:.2f} kt): a single {name} cannot represent the error "
            f"over the flown range ({_misfit_brief(misfit)}; more than the tolerance "
            f"`misfit_tolerance_kt` {tolerance:.2f} kt)", misfit)
    return (f"one {name} accepted: its structure misfit {misfit['max_dv_kt']:.2f} kt "
            + (f"is within the tolerance {tolerance:.2f} kt" if misfit["max_dv_kt"] <= tolerance
               else f"exceeds the tolerance {tolerance:.2f} kt but lies inside its own 2 sigma: "
               "not established by this flight"))


def _parameter(autopilot, k1, qci_pa, air_data):
    """ARSPD_RATIO = V_c² / q_ci, or ASPD_SCALE = V_c / IAS, at q_ci for the constant k1."""
    from pitotcal.core.airdata import airspeed_law

    qc = qci_pa / (1.0 - k1)
    vc_sq = float(airspeed_law(air_data)[1](qc)) ** 2
    if autopilot == "ArduPilot":
        return vc_sq / qci_pa
    return float(np.sqrt(vc_sq / (2.0 * qci_pa / RHO0_KGM3)))


def _check_bounds(name, value, two_sigma, current, autopilot):
    # the airspeed goes as the ratio's square root and as the scale itself
    rel_airspeed = (0.5 if autopilot == "ArduPilot" else 1.0) * two_sigma / value
    if rel_airspeed <= TOLERANCE:
        return
    if current is None or abs(value - current) <= two_sigma:
        where = ("the log has no current value" if current is None
                 else f"the current {current:.6g} lies inside it")
        raise PitotcalError(
            f"no parameter recommended: bounds too wide to improve on the current value: "
            f"{name} = {value:.4f} +/- {two_sigma:.4f} (2 sigma, {100 * rel_airspeed:.1f} % "
            f"of airspeed, need <= {100 * TOLERANCE:g} %) and {where}; fly longer or steadier")


def _two_coefficient_fits(flight, noise, air):
    """The inverse and linear fits the constant one is tested against, and notes on those that
    could not be identified."""
    from ..identification.identify import identify

    fits, notes = {}, []
    for model in ("inverse", "linear"):
        try:
            fits[model] = identify(flight, model=model, air=air, **noise)
        except ObservabilityError as exc:
            notes.append(f"{model} model not identifiable ({exc}); one scale not tested "
                         "against it")
    return fits, notes


def _departure(const, res):
    """How far `res` departs from the constant fit over the flown range, against its 2σ."""
    rows = res.correction_table()
    vi = np.array([r["vi_kt"] for r in rows])
    dv_m = np.array([r["dv_kt"] for r in rows])
    band = np.array([r["dv_2sigma_kt"] for r in rows])
    dv_c, _ = const.delta_v_kt(vi)
    excess = np.abs(dv_m - dv_c) - band
    i = int(np.argmax(excess))
    return {"max_departure_kt": float(abs(dv_m[i] - dv_c[i])),
            "two_sigma_kt": float(band[i]), "vi_kt": float(vi[i])}


def _misfit(autopilot, value, const, fits, air_data):
    """The structure misfit of the single `value` (module docstring), or None without a fit."""
    from pitotcal.core.airdata import airspeed_law
    from pitotcal.core.units import kt_to_mps

    best = None
    for model, res in fits.items():
        rows = res.correction_table(step_kt=MISFIT_STEP_KT)
        vi_kt = np.array([r["vi_kt"] for r in rows])
        dv_m = np.array([r["dv_kt"] for r in rows])
        dv_c, _ = const.delta_v_kt(vi_kt)
        err = np.abs(dv_m - dv_c)
        i = int(np.argmax(err))
        if best is not None and err[i] <= best["max_dv_kt"]:
            continue
        qci = airspeed_law(air_data)[0](kt_to_mps(vi_kt))
        vc_sq = kt_to_mps(vi_kt + dv_m) ** 2
        # ArduPilot: ratio = V_c² / q_ci; PX4: scale = V_c / IAS with IAS² = 2 q_ci / ρ₀
        local = vc_sq / qci if autopilot == "ArduPilot" else np.sqrt(vc_sq * RHO0_KGM3 / (2 * qci))
        best = {"model": model, "max_dv_kt": float(err[i]), "vi_kt": float(vi_kt[i]),
                "two_sigma_kt": float(rows[i]["dv_2sigma_kt"]),
                "local_min": float(local.min()), "local_max": float(local.max()),
                "vi_min_kt": float(vi_kt[0]), "vi_max_kt": float(vi_kt[-1])}
    return best


def _misfit_brief(m):
    """The refusal's short form of a structure misfit (never None there: a model departed)."""
    return (f"one value is off by up to {m['max_dv_kt']:.2f} kt at {m['vi_kt']:.0f} KIAS over "
            f"{m['vi_min_kt']:.0f}-{m['vi_max_kt']:.0f} KIAS; the local value spans "
            f"{m['local_min']:.4f} to {m['local_max']:.4f}")


def misfit_text(name, misfit):
    """One ASCII line stating a structure misfit (`ParameterRecommendation.misfit`)."""
    if misfit is None:
        return "structure misfit not assessed: no two-coefficient model identifiable"
    m = misfit
    return (f"structure misfit over {m['vi_min_kt']:.0f}-{m['vi_max_kt']:.0f} KIAS: one "
            f"{name} is off the {m['model']} model by up to {m['max_dv_kt']:.2f} kt at "
            f"{m['vi_kt']:.0f} KIAS (its 2 sigma {m['two_sigma_kt']:.2f} kt); local {name} "
            f"{m['local_min']:.4f} to {m['local_max']:.4f}")


def write_parameter_file(rec, path):
    """Write `rec` as the file its autopilot loads: ArduPilot a Mission Planner / MAVProxy
    parameter file, PX4 a QGroundControl parameter file. Returns the path."""
    from pitotcal.io.param_files import write_ardupilot_params, write_qgc_params

    writer = write_ardupilot_params if rec.autopilot == "ArduPilot" else write_qgc_params
    return writer(path, rec.name, rec.value, rec.comments())


# Each airspeed sensor's parameter, by autopilot: ArduPilot has two sensors (ARSPD_, ARSPD2_),
# PX4 a scale per sensor (ASPD_SCALE_1..3)
SENSOR_PARAMETERS = {"ArduPilot": (ARDUPILOT_RATIO, "ARSPD2_RATIO"),
                     "PX4": ("ASPD_SCALE_1", "ASPD_SCALE_2", "ASPD_SCALE_3")}


def sensor_parameter(autopilot, index):
    """The parameter name of airspeed sensor `index` (0 the first) of `autopilot`, or None
    when the autopilot has no parameter for that many sensors."""
    names = SENSOR_PARAMETERS.get(autopilot, ())
    return names[index] if index < len(names) else None


def write_parameter_set(recs, path):
    """Write several sensors' recommendations (`ParameterRecommendation`, one autopilot) as one
    parameter file its autopilot loads, each with its comment lines. Returns the path."""
    from pitotcal.io.param_files import write_ardupilot_param_set, write_qgc_param_set

    writer = (write_ardupilot_param_set if recs[0].autopilot == "ArduPilot"
              else write_qgc_param_set)
    return writer(path, [(r.name, r.value, r.comments()) for r in recs])


def recommend_sensors(flights, autopilot, current, *, air=DEFAULT_AIR_DATA,
                      misfit_tolerance_kt=None, gps_noise_std_mps=None, path=None, wind="auto",
                      wind_knot_s=None):
    """Each airspeed sensor's parameter from the joint fits of several sensors sharing one
    wind (`estimation.identification.multi_sensor`): the constant, inverse and linear models
    fitted jointly, then `recommend` per sensor on its results.

    Parameters
    ----------
    flights : sequence of Flight
        One per sensor, the first sensor's first (`pitotcal.io.sensors`).
    autopilot : {"ArduPilot", "PX4"}
    current : dict
        The log's parameters by name (current values: ``ARSPD2_RATIO``, ``ASPD_SCALE_2``...).
    path : str or Path, optional
        Write the recommended ones there as one parameter file (`write_parameter_set`).
    wind, wind_knot_s
        The shared wind model of the joint fits (`identify_sensors`).

    Returns
    -------
    list of (ParameterRecommendation or None, PitotcalError or None)
        Per sensor: its recommendation (named by `sensor_parameter`), or why none.
    """
    from ..identification.multi_sensor import identify_sensors

    fits = {}
    for model in ("constant", "inverse", "linear"):
        try:
            fits[model] = identify_sensors(flights, model=model, air=air,
                                           gps_noise_std_mps=gps_noise_std_mps, wind=wind,
                                           wind_knot_s=wind_knot_s)
        except ObservabilityError:
            if model == "constant":
                raise
    out = []
    for i, flight in enumerate(flights):
        # PX4 has one scale per sensor only under the names ASPD_SCALE_1, _2, ...
        name = sensor_parameter(autopilot, i)
        if name is None:
            out.append((None, PitotcalError(f"no parameter recommended for airspeed sensor "
                                            f"{i + 1}: {autopilot} has none for it")))
            continue
        try:
            out.append((recommend(flight, autopilot, current.get(name), name=name, air=air,
                                  misfit_tolerance_kt=misfit_tolerance_kt,
                                  log_parameters=current,
                                  fits={m: r[i] for m, r in fits.items()},
                                  gps_noise_std_mps=gps_noise_std_mps), None))
        except PitotcalError as exc:
            out.append((None, PitotcalError(f"airspeed sensor {i + 1}: {exc}")))
    recs = [rec for rec, _ in out if rec is not None]
    if path is not None and recs:
        write_parameter_set(recs, path)
    return out


def sensor_params_text(per_sensor, path):
    """Each sensor's recommended parameter (the refusals, already naming their sensor, are
    the caller's to raise)."""
    out = []
    for i, (rec, _) in enumerate(per_sensor, start=1):
        if rec is None:
            continue
        out.append(f"\nAirspeed sensor {i}: recommended {rec.name} = {rec.value:.4f} ± "
                   f"{rec.two_sigma:.4f} (2σ)"
                   + ("" if rec.current is None else f", now {rec.current:.6g}")
                   + f"; wrote {path}")
        out.append(f"  {rec.misfit_line()}")
        out += [f"  note: {note}" for note in rec.notes]
    return "\n".join(out)
