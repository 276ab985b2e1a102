"""simulate(..., air_sensors=...): the issue 9 air-data sensors against truth, the default files
unchanged, and each injected effect covered by its uncertainty-budget term."""

import dataclasses
import hashlib
import json

import numpy as np
import pytest
from pitotcal.estimation.identification import budget as bd
from pitotcal.estimation import identify
from pitotcal.maneuvers.fly.options import AirSensors
from pitotcal.maneuvers.fly.simulator import simulate
from pitotcal.maneuvers.fly.truth import write_truth_json
from plans import circle_plan

from pitotcal.core.errors import PitotcalError
from pitotcal.core.moist_air import moist_density_kgm3, virtual_temperature_k
from pitotcal.core.units import isa_pressure_pa, isa_temperature_k
from pitotcal.io import read_flight, write_flight_csv

# sha256 of the default files without air sensors: seed 7, 60 s circle, 10 Hz (the plan's KCAS
# by the standard CAS law, flown as calibrated airspeed)
GOLDEN_CSV = "220766c82834503d6a3059b57f7efe65dcf0b06b15e33a751887d8589b910e15"
GOLDEN_TRUTH = "bd985f3d59af8d71288939734781f4c624489dfdb7c89f2d2cf499573bc400ce"


def _sha(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def test_default_files_byte_identical(tmp_path):
    # the golden files are the incompressible flight's (the default air data before it became
    # the compressible one, which adds ps_pa and oat_k)
    flight, truth = simulate(circle_plan(duration_s=60.0), seed=7, rate_hz=10.0,
                             air_data="incompressible")
    csv = write_flight_csv(flight, tmp_path / "f.csv")
    assert "air_sensors" not in truth.options and flight.ps_pa is None
    assert _sha(csv) == GOLDEN_CSV
    assert _sha(write_truth_json(truth, tmp_path / "f.truth.json")) == GOLDEN_TRUTH


def test_sensor_records_against_truth(tmp_path):
    sensors = AirSensors(tat_recovery=0.97, rh_pct=70.0, oat_bias_k=0.0)
    flight, truth = simulate(circle_plan(duration_s=60.0), seed=7, rate_hz=10.0,
                             air_sensors=sensors, turbulence_mps=0.0)
    assert truth.options["air_sensors"]["tat_recovery"] == 0.97
    path = write_flight_csv(flight, tmp_path / "f.csv")
    with open(path) as f:
        header = next(line for line in f if not line.startswith("#"))
    assert header.strip().endswith("ps_pa,tat_k,rh_pct")
    # the reader converts with the probe's recovery factor (identify --temp-recovery 0.97)
    back = read_flight(path, temp_recovery=0.97)
    ts = isa_temperature_k(flight.alt_m)
    # humid: oat_k is the virtual temperature; M from the measured q_ci (its pressure error
    # and noise) instead of the true one
    assert back.oat_k == pytest.approx(virtual_temperature_k(ts, flight.ps_pa, 70.0), abs=0.04)
    assert back.rho_kgm3 == pytest.approx(moist_density_kgm3(isa_pressure_pa(flight.alt_m),
                                                             ts, 70.0), rel=2e-4)
    assert json.loads(json.dumps(truth.options))["air_sensors"]["gps_bias_mps"] == [0, 0, 0]


@pytest.mark.parametrize("bad, match", [({"tat_recovery": 2.0}, "tat_recovery"),
                                        ({"rh_pct": -5.0}, "rh_percent"),
                                        ({"gps_bias_mps": (1.0, 2.0)}, "gps_bias_mps")])
def test_bad_sensor_options(bad, match):
    with pytest.raises(PitotcalError, match=match):
        simulate(circle_plan(duration_s=30.0), rate_hz=5.0, air_sensors=bad)


# --- each effect injected, and the budget term that should cover it -------------------------

PLAN = {"duration_s": 120.0, "cas_kt": (70.0, 100.0), "radius_m": 600.0}
# compressible truth, every flight logging ps_pa and oat_k: the default compressible fit
SIM = {"seed": 11, "rate_hz": 10.0, "turbulence_mps": 0.3, "air_data": "compressible"}
ZERO = bd.BudgetInputs(u_oat_k=0, u_rh_pct=0, u_gps_velocity_mps=0, u_gps_latency_s=0,
                       u_qc_scale=0, u_qc_offset_pa=0)
# (source, simulate options injecting it, the budget input set to its size)
EFFECTS = [
    ("oat", {"air_sensors": {"oat_bias_k": 2.0}}, {"u_oat_k": 2.0}),
    ("humidity", {"air_sensors": {"rh_pct": 90.0}}, {"u_rh_pct": 90.0}),
    ("probe_lever_arm", {"air_sensors": {"probe_arm_m": 2.0}}, {"probe_arm_m": 2.0}),
    ("gps_latency", {"gps_latency_s": 0.2}, {"u_gps_latency_s": 0.2}),
    ("gps_velocity_bias", {"air_sensors": {"gps_bias_mps": (0.3, -0.3, 0.0)}},
     {"u_gps_velocity_mps": 0.3}),
    ("qc_scale", {"qc_scale_error": 0.005}, {"u_qc_scale": 0.005}),
    ("qc_offset", {"qc_bias_pa": 3.0}, {"u_qc_offset_pa": 3.0}),
]


@pytest.fixture(scope="module")
def clean():
    plan = circle_plan(**PLAN)
    flight, _ = simulate(plan, **SIM, air_sensors={})
    return plan, identify(flight)


@pytest.mark.parametrize("source, inject, inputs", EFFECTS, ids=[e[0] for e in EFFECTS])
def test_budget_term_covers_injected_bias(clean, source, inject, inputs):
    plan, base = clean
    flight, _ = simulate(plan, **SIM, **{"air_sensors": {}, **inject})
    if flight.rh_pct is not None:            # the logger does not know the humidity
        flight = dataclasses.replace(flight, rh_pct=None)
    result = identify(flight)
    vi = np.array([74.0, 85.0, 96.0])
    bias = np.abs(result.delta_v_kt(vi)[0] - base.delta_v_kt(vi)[0])
    budget = bd.uncertainty_budget(flight, result, dataclasses.replace(ZERO, **inputs))
    term = np.interp(vi, budget.vi_kt, budget.terms_kt[source])
    # the term is the size of the bias the effect causes (same seed: the noise cancels)
    assert bias == pytest.approx(term, rel=0.1, abs=0.005)
