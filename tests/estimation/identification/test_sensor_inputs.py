"""The budget's inputs from the sensors (estimation.identification.sensor_inputs): u(OAT) by the
temperature's source, the static transducer term, the lever arm corrected in the data, the
sensor classes, and the list of every input with where it came from; each against re-solves
of simulated flights with known truth."""

import dataclasses
import math

import numpy as np
import pytest
from pitotcal.estimation import identify
from pitotcal.estimation.identification import budget as bd
from pitotcal.estimation.identification import sensor_inputs as si
from pitotcal.maneuvers.fly.simulator import simulate
from plans import circle_plan

from pitotcal.core.errors import PitotcalError

# the budget with every input zero: one term at a time is switched on
ZERO = bd.BudgetInputs(u_oat_k=0, u_rh_pct=0, u_gps_velocity_mps=0, u_gps_latency_s=0,
                       u_qc_scale=0, u_qc_offset_pa=0, u_ps_pa=0)


@pytest.fixture(scope="module")
def high():
    """180-260 KCAS at 10,000 ft, compressible truth, calm air (test_compressible's case)."""
    plan = circle_plan(duration_s=240.0, cas_kt=(180.0, 260.0), radius_m=4500.0,
                       altitude_m=3048.0, wind_speed_mps=5.0)
    flight, _ = simulate(plan, seed=0, turbulence_mps=0.0, rate_hz=10.0,
                         air_data="compressible")
    return flight, identify(flight)


def test_static_transducer_term_against_a_perturbed_resolve(high):
    """+1 hPa of static pressure moves ΔV by 0.12-0.16 kt at 180-260 KCAS, 10,000 ft (more than
    the flight-test gain and offset terms); the budget's term at u = 1 hPa is that move."""
    flight, result = high
    vi = np.array([180.0, 220.0, 258.0])
    moved = identify(bd.static_pressure_error(flight, result, 100.0))
    shift = moved.delta_v_kt(vi)[0] - result.delta_v_kt(vi)[0]
    assert shift == pytest.approx([0.120, 0.138, 0.155], abs=0.01)
    budget = bd.uncertainty_budget(flight, result, dataclasses.replace(ZERO, u_ps_pa=100.0))
    term = np.interp(vi, budget.vi_kt, budget.terms_kt["static_pressure"])
    assert term == pytest.approx(np.abs(shift), rel=0.05)
    others = bd.uncertainty_budget(flight, result, bd.BudgetInputs(u_ps_pa=100.0))
    assert np.max(others.terms_kt["static_pressure"]) > np.max(others.terms_kt["qc_scale"])
    assert np.max(others.terms_kt["static_pressure"]) > np.max(others.terms_kt["qc_offset"])


@pytest.mark.parametrize("text, source, u_k", [
    ("oat_k", "probe", 1.0),
    ("oat_k=268 K given by the user", "user", 1.5),
    ("ISA at GPS altitude (no temperature in the log)", "isa", 20 / math.sqrt(3)),
    ("BARO[0].Temp: sensor temperature, not OAT", "sensor-chip", 20 / math.sqrt(3)),
])
def test_oat_uncertainty_by_source(high, text, source, u_k):
    flight, _ = high
    read = dataclasses.replace(flight, reading={"oat_source": text})
    inputs, rows = si.resolve(bd.BudgetInputs(), read)
    assert (inputs.oat_source, inputs.u_oat_k) == (source, pytest.approx(u_k))
    by = {r["input"]: r for r in rows}
    assert by["oat_source"]["origin"] == f"the flight: {text}"
    assert by["u_oat_k"]["origin"].startswith(f"default for the source {source}")
    # a stated source or value wins, and says so
    given, rows = si.resolve(bd.BudgetInputs(oat_source="ground-lapse", u_oat_k=0.4,
                                             origins={"u_oat_k": "flag"}), read)
    assert (given.oat_source, given.u_oat_k) == ("ground-lapse", 0.4)
    assert {r["input"]: r["origin"] for r in rows}["u_oat_k"] == "flag"


def test_total_temperature_adds_the_recovery_factor(high):
    """A tat_k probe: u = sqrt(u_probe² + (0.03 · 0.2 M² T)²), M the 95th percentile."""
    flight, _ = high
    read = dataclasses.replace(flight, reading={"oat_source": "tat_k, recovery factor 0.98"})
    inputs, _ = si.resolve(bd.BudgetInputs(), read)
    ram = 0.2 * 0.436 ** 2 * 268.3          # M at 260 KCAS, 10,000 ft; ISA T there
    assert inputs.u_oat_k == pytest.approx(math.hypot(1.0, 0.03 * ram), rel=0.01)


def test_oat_term_scales_with_its_source(high):
    """The OAT term is linear in u(OAT): ISA assumed gives 11.5 times the probe's term."""
    flight, result = high
    probe = bd.uncertainty_budget(flight, result, dataclasses.replace(ZERO, u_oat_k=None))
    isa = bd.uncertainty_budget(dataclasses.replace(flight, reading={"oat_source": "ISA"}),
                                result, dataclasses.replace(ZERO, u_oat_k=None))
    ratio = isa.terms_kt["oat"] / probe.terms_kt["oat"]
    assert ratio == pytest.approx(20 / math.sqrt(3), rel=0.03)


@pytest.mark.parametrize("cls", si.SENSOR_CLASSES)
def test_class_defaults_fill_what_is_not_given(high, cls):
    flight, _ = high
    inputs, rows = si.resolve(bd.BudgetInputs(sensor_class=cls, u_qc_offset_pa=2.0), flight)
    for field in ("u_qc_scale", "u_ps_pa", "u_gps_latency_s"):
        assert getattr(inputs, field) == si.CLASS_DEFAULTS[cls][field]
    by = {r["input"]: r["origin"] for r in rows}
    assert by["u_ps_pa"] == f"default of class {cls}" and by["u_qc_offset_pa"] == "given"
    assert inputs.u_qc_offset_pa == 2.0
    assert {r["input"] for r in rows} >= {"sensor_class", "oat_source", "probe_arm_m",
                                          *si.UNITS}


def test_bad_inputs_name_the_field():
    with pytest.raises(PitotcalError, match="sensor_class"):
        bd.BudgetInputs(sensor_class="hobby").checked()
    with pytest.raises(PitotcalError, match="oat_source"):
        bd.BudgetInputs(oat_source="guess").checked()
    with pytest.raises(PitotcalError, match="sensors.u_ps_pa"):
        si.inputs_from_table({"u_ps_pa": -3.0}, "a.toml")


# --- the lever arm: a correction of the data, with its own uncertainty ---------------------

ARM_M = 2.0
LOW = {"duration_s": 120.0, "cas_kt": (70.0, 100.0), "radius_m": 600.0}
SIM = {"seed": 11, "rate_hz": 10.0, "turbulence_mps": 0.0, "air_data": "compressible"}


@pytest.fixture(scope="module")
def armed():
    """The same flight flown with the probe on the centre line and 2 m out on the wing."""
    plan = circle_plan(**LOW)
    clean, _ = simulate(plan, **SIM, air_sensors={})
    offset, _ = simulate(plan, **SIM, air_sensors={"probe_arm_m": ARM_M})
    return identify(clean), offset


def test_lever_arm_correction_recovers_the_centre_line(armed):
    """Uncorrected, the 2 m arm shifts ΔV by 0.24-0.29 kt (measured); corrected, ΔV is the
    centre-line probe's to 0.01 kt, and the record keeps the arm."""
    base, offset = armed
    vi = np.array([74.0, 85.0, 96.0])
    biased = identify(offset).delta_v_kt(vi)[0] - base.delta_v_kt(vi)[0]
    corrected = identify(offset, probe_arm_m=ARM_M)
    fixed = corrected.delta_v_kt(vi)[0] - base.delta_v_kt(vi)[0]
    assert np.min(np.abs(biased)) > 0.05
    assert np.max(np.abs(fixed)) < 0.01 and np.max(np.abs(fixed)) < np.min(np.abs(biased)) / 5
    assert corrected.to_dict()["reading"]["probe_arm_m"] == ARM_M


def test_corrected_arm_counts_its_own_uncertainty(armed):
    """After the correction the term is the arm's 10 % (0.2 m), a tenth of the whole arm's."""
    _, offset = armed
    result = identify(offset, probe_arm_m=ARM_M, budget=dataclasses.replace(ZERO))
    term = result.budget.terms_kt["probe_lever_arm"]
    rows = {r["input"]: r for r in result.budget.input_list}
    assert rows["u_probe_arm_m"]["value"] == pytest.approx(0.1 * ARM_M)
    assert rows["probe_arm_m"] == {"input": "probe_arm_m", "value": ARM_M, "unit": "m",
                                   "origin": "corrected in the data"}
    whole = bd.uncertainty_budget(offset, identify(offset),
                                  dataclasses.replace(ZERO, probe_arm_m=ARM_M))
    assert np.max(term) == pytest.approx(np.max(whole.terms_kt["probe_lever_arm"]) / 10,
                                         rel=0.1)
    record = result.to_dict()
    assert record["budget_inputs"] == list(result.budget.input_list)
    arm = next(r for r in record["uncertainty_budget"] if r["source"] == "probe_lever_arm")
    assert arm["origin"] == "default: 10 % of the corrected arm"


def test_budget_of_a_corrected_result_from_the_raw_flight(armed):
    """`uncertainty_budget(raw flight, result)` of a result identify corrected for the arm
    re-solves the corrected flight: identify's own budget to 1e-4 (the correction made here
    takes the final fit's wind, identify's the first fit's: they differ by ~1e-6)."""
    _, offset = armed
    inputs = dataclasses.replace(ZERO, u_qc_scale=0.01)
    result = identify(offset, probe_arm_m=ARM_M, budget=inputs)
    again = bd.uncertainty_budget(offset, result, inputs)
    for name, term in result.budget.terms_kt.items():
        np.testing.assert_allclose(again.terms_kt[name], term, rtol=1e-4, atol=1e-9)
