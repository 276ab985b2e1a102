"""The result record: `identify` computes every product once and `to_dict` writes it; the one
reader, `read_result`, validates what it returns."""

import json

import numpy as np
import pytest
from pitotcal.estimation.identification import static_source
from pitotcal.estimation.identification.budget import BudgetInputs, uncertainty_budget
from pitotcal.estimation.identification.identify import identify
from pitotcal.estimation.monitor.model import Calibration
from pitotcal.estimation.uncertainty.block_noise import block_residual_stats
from pitotcal.estimation.reporting.budget_tables import add_budget
from synthetic import reference_static_flight

from pitotcal.core.errors import PitotcalError
from pitotcal.io import read_flight, write_flight_csv
from pitotcal.io.result_record import read_result, record_calibration

TRUE_K = (0.02, -15.0)       # circle_plan's default truth (tests/plans.py)


@pytest.fixture(scope="module")
def reference_flight():
    """A compressible flight with a reference static pressure 40 Pa below the static port's."""
    return reference_static_flight()


def test_static_source_fit_runs_once_per_identification(reference_flight, monkeypatch, tmp_path):
    calls = []
    fit = static_source.static_error_fit

    def counted(result):
        calls.append(1)
        return fit(result)

    monkeypatch.setattr(static_source, "static_error_fit", counted)
    result = identify(reference_flight, model="inverse")
    assert result.static_fit is not None and result.ps_ref_pa is not None
    record = result.to_dict()
    result.summary()
    result.plot(tmp_path / "c.png")
    result.correction_table()
    assert len(calls) == 1
    # the record carries the one fit: the measured static error is the 40 Pa offset,
    # dp_p = q_c (k1 + k2 / q_ci) with k2 = 40 q_ci / q_c, k1 = 0
    k_static = record["static_source"]["k_static"]
    assert k_static["k1"]["value"] == pytest.approx(0.0, abs=1e-3)
    assert k_static["k2"]["value"] == pytest.approx(40.0 * (1 - TRUE_K[0]), rel=0.02)


def test_record_is_complete_and_equals_the_parts(reference_flight):
    """identify(..., budget=...) carries the noise model, GPS-error statement and budget; its
    record equals the one assembled from the separate pieces (as the CLI used to)."""
    inputs = BudgetInputs(u_qc_offset_pa=2.0)
    result = identify(reference_flight, model="inverse", budget=inputs,
                      gps_error_sigma_mps=0.05, gps_error_tau_s=30.0)
    record = result.to_dict()
    plain = identify(reference_flight, model="inverse", gps_error_sigma_mps=0.05,
                     gps_error_tau_s=30.0)
    budget = uncertainty_budget(reference_flight, plain, inputs, air="compressible")
    parts = json.loads(json.dumps(add_budget(plain.to_dict(), budget)))
    parts["noise_model"] = json.loads(json.dumps(block_residual_stats(plain)))
    del record["timing_s"], parts["timing_s"]
    assert record == parts
    assert record["gps_error"] == {"stated": True, "sigma_mps": 0.05, "tau_s": 30.0}
    assert record["reading"] is None and record["source"] == reference_flight.source
    assert all(row["dv_U_kt"] > row["dv_2sigma_kt"] for row in record["airspeed_correction"])
    assert result.budget is not None and result.monitor_noise["n_blocks"] > 100
    # the true correction is inside the record's U at every speed
    assert record["parameters"]["k1"]["value"] == pytest.approx(TRUE_K[0], abs=0.005)


def test_reading_comes_from_read_flight(reference_flight, tmp_path):
    path = write_flight_csv(reference_flight, tmp_path / "f.csv")
    flight = read_flight(path, start_s=5.0, temp_recovery=0.9)
    record = identify(flight, model="inverse").to_dict()
    assert record["reading"] == {"start_s": 5.0, "end_s": None, "oat_k": None,
                                 "temp_recovery": 0.9, "rh_pct": None, "oat_source": "oat_k"}
    assert record["source"] == str(path) and record["n_dropped"] == 0
    # and it reads back: the monitor's calibration needs no fallback
    back = read_result(json.loads(json.dumps(record)), name="r.json")
    cal = Calibration.from_dict(back, source="r.json")
    assert cal.notes == () and "fallback" not in cal.noise
    assert cal.noise == record["noise_model"]
    model, k, speed, _, air = record_calibration(back, "r.json")
    assert (model, air) == ("inverse", "compressible") and speed == pytest.approx(5.0, abs=0.3)
    assert np.allclose(k, [record["parameters"][n]["value"] for n in ("k1", "k2")])


def _record():
    return {"model": "inverse", "converged": True,
            "parameters": {"k1": {"value": 0.02}, "k2": {"value": -15.0},
                           "wind_speed_mps": {"value": 5.0}, "wind_from_deg": {"value": 270.0}},
            "airspeed_correction": [{"vi_kt": 80.0, "dv_kt": 0.4, "dv_2sigma_kt": 0.1}]}


def _without(*path):
    d = json.loads(json.dumps(_record()))
    node = d
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]
    return d


def _with(value, *path):
    d = json.loads(json.dumps(_record()))
    node = d
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return d


@pytest.mark.parametrize("doc, match", [
    (_without("model"), r"r\.json: not a pitotcal identify result JSON \(no key 'model'\)"),
    (_without("parameters"), r"r\.json: .*no key 'parameters'"),
    (_without("airspeed_correction"), r"r\.json: .*no airspeed_correction table"),
    (_without("parameters", "k2"), r"r\.json: .*key 'parameters\.k2' is null"),
    (_without("parameters", "k1", "value"), r"r\.json: .*no key 'parameters\.k1\.value'"),
    (_with("0.02", "parameters", "k1", "value"), r"key 'parameters\.k1\.value' is a string, "
                                                  "expected a number"),
    (_with(True, "parameters", "k1", "value"), r"key 'parameters\.k1\.value' is a boolean"),
    (_with("yes", "converged"), r"key 'converged' is a string, expected true or false"),
    (_with("loose", "air_data"), r"key 'air_data' is 'loose'"),
    (_with("cubic", "model"), r"key 'model' is 'cubic'"),
    (_with([1, 2], "noise_model"), r"key 'noise_model' is a list, expected an object or null"),
    (_with("x", "reading"), r"key 'reading' is a string"),
    (_with([80.0], "airspeed_correction"), r"key 'airspeed_correction\[0\]' is a number"),
    (_with({"vi_kt": "80"}, "airspeed_correction", 0), r"airspeed_correction\[0\]\.vi_kt' is "
                                                       "a string"),
    ([1, 2], r"r\.json: not a pitotcal identify result JSON \(not an object\)"),
])
def test_read_result_names_file_and_key(tmp_path, doc, match):
    path = tmp_path / "r.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(PitotcalError, match=match) as err:
        read_result(path)
    assert "\n" not in str(err.value)


def test_read_result_files(tmp_path):
    bad = tmp_path / "r.json"
    bad.write_text("{not json")
    with pytest.raises(PitotcalError, match=r"r\.json: not JSON"):
        read_result(bad)
    with pytest.raises(PitotcalError, match=r"missing\.json: cannot read it"):
        read_result(tmp_path / "missing.json")
    good = tmp_path / "g.json"
    good.write_text(json.dumps(_record()))
    assert read_result(good) == _record()
    # the monitor and the planner need no table
    assert read_result(_without("airspeed_correction"), table=False)["model"] == "inverse"
    with pytest.raises(PitotcalError, match="parameters.wind_speed_mps.value' is None"):
        record_calibration(_with(None, "parameters", "wind_speed_mps", "value"), "r.json")


def test_an_older_record_is_read_with_a_note():
    """A record written before it had a noise model is still read, with a warning; one whose
    noise model is null (a flight too short for it) says so."""
    old = Calibration.from_dict(_record(), source="old.json")
    assert old.noise.get("fallback") and "written before the record had one" in old.notes[0]
    stated = {"stated": False, "sigma_mps": None, "tau_s": None}
    for short in ({**_record(), "gps_error": stated}, {**_record(), "noise_model": None}):
        cal = Calibration.from_dict(short, source="short.json")
        assert cal.noise.get("fallback") and "too short" in cal.notes[0]


def test_a_large_k1_with_a_small_ratio_over_the_flown_speeds_is_read(tmp_path):
    """The record's pressure error is bounded where it was flown (the rule `simulate` holds its
    truth to), not by k1 alone: inverse k1 0.6, k2 -700 Pa keeps |dp/qc| <= 0.29 at 70-100 kt."""
    doc = {"model": "inverse", "air_data": "incompressible", "noise_std_pa": 1.0,
           "parameters": {"k1": {"value": 0.6}, "k2": {"value": -700.0}},
           "airspeed_correction": [{"vi_kt": v, "dv_kt": 0.0, "dv_2sigma_kt": 0.1}
                                   for v in (70.0, 85.0, 100.0)]}
    assert read_result(doc)["parameters"]["k1"]["value"] == 0.6
    doc["parameters"]["k2"]["value"] = 0.0            # then 0.6 everywhere: refused
    with pytest.raises(PitotcalError, match=r"'parameters.k1.value' 0.6.*reaches 0.6"):
        read_result(doc)


@pytest.mark.parametrize("vi", [0.0, -80.0, None])
def test_a_table_speed_that_is_no_airspeed_is_refused(vi):
    doc = {"model": "constant", "air_data": "incompressible", "noise_std_pa": 1.0,
           "parameters": {"k1": {"value": 0.01}},
           "airspeed_correction": [{"vi_kt": vi, "dv_kt": 0.0, "dv_2sigma_kt": 0.1}]}
    with pytest.raises(PitotcalError, match=r"airspeed_correction\[0\].vi_kt"):
        read_result(doc)
