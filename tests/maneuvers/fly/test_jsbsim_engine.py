"""simulate_jsbsim: the plan flown by JSBSim's six-degree-of-freedom model, checked against
physics it does not share with pitotcal (the wind triangle, the isentropic impact pressure)."""

import json

import numpy as np
import pytest
from plans import circle_plan

from pitotcal.core import airdata as ad
from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import FT_TO_M, mps_to_kt

jsbsim = pytest.importorskip("jsbsim", reason="JSBSim is not installed (pip install jsbsim)")
engine = pytest.importorskip("pitotcal.maneuvers.fly.jsbsim_engine")
from pitotcal.maneuvers.fly.simulator import simulate_jsbsim


@pytest.fixture(scope="module")
def calm_flight():
    plan = circle_plan(duration_s=90.0, cas_kt=(75.0, 95.0), radius_m=800.0, altitude_m=900.0,
                       wind_speed_mps=6.0, wind_from_deg=300.0)
    return plan, *simulate_jsbsim(plan, seed=4, turbulence_mps=0.0, rate_hz=10.0,
                                         gps_noise_mps=0.0, qc_noise_pa=0.0, keep_history=True)


def test_milspec_setting_below_1000_ft_gives_the_sigma_asked_for():
    w20, severity, sigma = engine.milspec_setting(0.8, 150.0)
    h_ft = 150.0 / FT_TO_M
    assert 0.1 * w20 / (0.177 + 0.000823 * h_ft) ** 0.4 * FT_TO_M == pytest.approx(0.8)
    assert sigma == pytest.approx(0.8) and severity >= 1


@pytest.mark.parametrize("sigma_mps, severity", [(0.5, 1), (1.0, 2), (2.2, 3)])
def test_milspec_setting_above_2000_ft_picks_the_nearest_table_row(sigma_mps, severity):
    # MIL-F-8785C fig. 7 at 3000 ft: rows 1-3 give 1.76, 3.41, 7.21 ft/s (0.54, 1.04, 2.2 m/s)
    _, got, sigma = engine.milspec_setting(sigma_mps, 3000.0 * FT_TO_M)
    assert got == severity
    assert sigma == pytest.approx([0.536, 1.040, 2.197][severity - 1], abs=0.005)
    assert engine.milspec_setting(0.0, 900.0) == (0.0, 0, 0.0)


def test_ground_velocity_minus_wind_is_the_true_airspeed(calm_flight):
    _, flight, truth = calm_flight
    h = truth.history
    v_air = np.sqrt((h["vn_mps"] - h["wind_n_mps"]) ** 2 + (h["ve_mps"] - h["wind_e_mps"]) ** 2
                    + h["vd_mps"] ** 2)
    np.testing.assert_allclose(v_air, h["tas_mps"], rtol=2e-4)
    # the logged GPS velocity (no noise, 5 Hz hold) is JSBSim's ground velocity
    assert np.max(np.abs(flight.gps_vn_mps - h["vn_mps"])) < 1.0
    assert truth.parameters["wind_speed_mps"] == pytest.approx(6.0, abs=1e-6)
    assert truth.parameters["wind_from_deg"] == pytest.approx(300.0, abs=1e-4)


def test_impact_pressure_is_jsbsims_isentropic_one(calm_flight):
    _, _, truth = calm_flight
    h = truth.history
    expected = ad.qc_from_tas_sq_pa(h["tas_mps"] ** 2, h["ps_pa"], h["oat_k"])
    np.testing.assert_allclose(h["qc_pa"], expected, rtol=2e-3)
    assert truth.air_data == "compressible"


def test_the_autopilot_flies_the_plan(calm_flight):
    plan, _, truth = calm_flight
    tr = truth.tracking
    assert tr.max_cas_error_kt < 5.0 and tr.max_alt_error_m < 15.0
    assert tr.max_radius_m < plan.settings["radius_m"] + 150.0
    assert truth.options["max_sideslip_deg"] < 3.0 and truth.options["stall_warning_s"] == 0.0
    cas_kt = mps_to_kt(ad.cas_from_qc_mps(truth.history["qc_pa"]))
    assert 72.0 < cas_kt.min() and cas_kt.max() < 98.0


def test_an_aircraft_jsbsim_does_not_ship_is_one_line():
    with pytest.raises(PitotcalError, match="aircraft 'c999' is not one JSBSim ships; e.g. c1"):
        simulate_jsbsim(circle_plan(duration_s=30.0), aircraft="c999")


def test_cli_engine_jsbsim_writes_flight_and_truth(tmp_path, capsys):
    from pitotcal.cli import main
    from pitotcal.io.plan_csv import write_plan

    plan = write_plan(circle_plan(duration_s=40.0, cas_kt=(80.0, 90.0), radius_m=800.0),
                      tmp_path / "p.csv")
    out = tmp_path / "f.csv"
    assert main(["simulate", str(plan), "-o", str(out), "--engine", "jsbsim", "--rate-hz", "5",
                 "--turbulence-mps", "0"]) == 0
    truth = json.loads((tmp_path / "f.truth.json").read_text())
    assert truth["options"]["engine"] == "jsbsim" and truth["options"]["aircraft"] == "c172x"
    assert truth["air_data"] == "compressible"
    assert main(["simulate", str(plan), "-o", str(out), "--aircraft", "c172x"]) == 2
    assert "--aircraft: only --engine jsbsim" in capsys.readouterr().err
    assert main(["simulate", str(plan), "-o", str(out), "--engine", "jsbsim",
                 "--air-data", "incompressible"]) == 2
    assert "JSBSim's impact pressure is its own" in capsys.readouterr().err


def test_the_static_port_carries_the_whole_pressure_error(calm_flight):
    _, flight, truth = calm_flight
    h = truth.history
    # q_ci + p_s,ind is the true total pressure (no transducer noise in this flight)
    np.testing.assert_allclose(flight.qci_pa + flight.ps_pa, h["pt_pa"], rtol=1e-9)
    np.testing.assert_allclose(flight.oat_k, h["oat_k"])


def test_a_jsbsim_flight_is_calibrated_within_3_sigma():
    """JSBSim's c172x (its atmosphere, sideslip, engine and turbulence), identified by the
    compressible output-error problem: the truth inside 3σ."""
    from pitotcal.estimation import identify

    plan = circle_plan(duration_s=240.0, cas_kt=(70.0, 100.0), radius_m=900.0,
                       altitude_m=900.0, wind_speed_mps=5.0, wind_from_deg=250.0)
    flight, truth = simulate_jsbsim(plan, seed=7, turbulence_mps=0.5, rate_hz=10.0)
    result = identify(flight, model="inverse")
    assert result.air_data == "compressible"
    for name, value, std in zip(result.param_names, result.params, np.sqrt(np.diag(
            result.covariance))):
        true = truth.parameters[name]
        err = (value - true + 180.0) % 360.0 - 180.0 if name == "wind_from_deg" else value - true
        assert abs(err) < 3.0 * std, (name, value, true, std)


def test_jsbsims_own_output_file_never_lands_in_the_working_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    simulate_jsbsim(circle_plan(duration_s=20.0, cas_kt=(80.0, 85.0), radius_m=800.0),
                    turbulence_mps=0.0, rate_hz=5.0)
    assert list(tmp_path.iterdir()) == []
