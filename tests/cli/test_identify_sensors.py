"""`pitotcal identify` of logs with two airspeed sensors (ArduPilot ARSP instances 0/1, PX4
differential_pressure instances, a tlog's SCALED_PRESSURE2): one shared wind, each sensor's
calibration and parameter; and a MAVLink telemetry log calibrated and converted."""

import json
import warnings

import pytest
from logwriters import write_dataflash_bin, write_tlog, write_ulog
from synthetic import two_sensor_flights

from pitotcal.cli import main
from pitotcal.core.units import RHO0_KGM3
from pitotcal.io.param_files import read_qgc_params

K_A, K_B = (0.02, -15.0), (-0.03, 10.0)


@pytest.fixture(scope="module")
def two():
    """300 s at 10 Hz in 0.3 m/s turbulence; sensor a k = K_A, b = K_B (inverse model)."""
    return two_sensor_flights(seed=2, n=3000, rate_hz=10.0, turbulence_mps=0.3, k_a=K_A,
                              k_b=K_B)


def _true_ratio_of_ratios(flight):
    """ARSPD_RATIO of sensor a over sensor b's, 2 / (rho0 (1 - f)) at the median q_ci: the
    density (and --oat-c's offset from it) cancels."""
    import numpy as np

    q = float(np.median(flight.qci_pa))
    return (1.0 - (K_B[0] + K_B[1] / q)) / (1.0 - (K_A[0] + K_A[1] / q))


def _run(argv):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return main(argv)


def test_two_ardupilot_sensors_share_the_wind_and_get_a_ratio_each(two, tmp_path, capsys):
    fa, fb, _ = two
    log = write_dataflash_bin(tmp_path / "two.bin", fa, second=fb.qci_pa, ratio=1.9,
                              second_ratio=2.1)
    rec, parm = tmp_path / "r.json", tmp_path / "new.parm"
    assert _run(["identify", str(log), "--oat-c", "15", "--no-budget", "--json", str(rec),
                 "--params", str(parm)]) == 0
    out = capsys.readouterr().out
    assert "Airspeed sensor 2 (ARSP[1].DiffPress (Pa)" in out
    doc = json.loads(rec.read_text())
    a, b = doc["sensors"]
    assert (a["sensor"], b["sensor"]) == (1, 2) and a["qc_source"] == "ARSP.DiffPress (Pa)"
    # the top level stays the first sensor's record, every key kept
    assert doc["parameters"] == a["parameters"] and doc["autopilot_parameter"]["name"] == \
        "ARSPD_RATIO"
    for key in ("wind_speed_mps", "wind_from_deg"):
        assert a["parameters"][key]["value"] == b["parameters"][key]["value"]
    ra, rb = a["autopilot_parameter"], b["autopilot_parameter"]
    assert (ra["name"], rb["name"]) == ("ARSPD_RATIO", "ARSPD2_RATIO")
    assert (ra["current"], rb["current"]) == (pytest.approx(1.9), pytest.approx(2.1))
    text = parm.read_text()
    assert f"ARSPD_RATIO,{ra['value']:.6f}" in text and f"ARSPD2_RATIO,{rb['value']:.6f}" in text
    assert "pitotcal: ARSPD2_RATIO" in text
    # the two calibrations differ as the truth does (1.030): the common turbulence cancels
    assert ra["value"] / rb["value"] == pytest.approx(_true_ratio_of_ratios(fa), abs=0.006)
    # and each is a calibration: 2 / (rho0 (1 - f)) of its own fit's f = k1 + k2 / q_ci at
    # the median q_ci (the record is the inverse model's; the ratio a constant fit's)
    import numpy as np

    q = float(np.median(fa.qci_pa))
    for rec, sensor in ((ra, a), (rb, b)):
        p = sensor["parameters"]
        f = p["k1"]["value"] + p["k2"]["value"] / q
        assert rec["value"] == pytest.approx(2.0 / RHO0_KGM3 / (1.0 - f), rel=0.01)


def test_wind_options_act_on_the_joint_fit(two, tmp_path):
    """`--wind drifting --wind-knot-s 120` on a two-sensor log: both sensors calibrated, the
    drift shared (the same wind model and track in each), no "first sensor alone" warning."""
    fa, fb, truth = two
    log = write_dataflash_bin(tmp_path / "two.bin", fa, second=fb.qci_pa, ratio=1.9,
                              second_ratio=2.1)
    rec = tmp_path / "r.json"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["identify", str(log), "--oat-c", "15", "--no-budget", "--json", str(rec),
                     "--wind", "drifting", "--wind-knot-s", "120"]) == 0
    assert not [w for w in caught if "applies to one sensor's fit" in str(w.message)]
    a, b = json.loads(rec.read_text())["sensors"]
    for sensor in (a, b):
        model = sensor["wind_model"]
        assert (model["kind"], model["knot_s"], model["chosen_by"]) == \
            ("drifting", 120.0, "option")
        assert model["shared_by_sensors"] == 2
    assert a["wind_track"] == b["wind_track"] and len(a["wind_track"]["time_s"]) > 2
    for sensor, k in ((a, K_A), (b, K_B)):
        k1 = sensor["parameters"]["k1"]
        assert abs(k1["value"] - k[0]) < 2.0 * k1["std"]


def test_two_px4_sensors_get_a_scale_each(two, tmp_path, capsys):
    fa, fb, _ = two
    log = write_ulog(tmp_path / "two.ulg", fa, second=fb.qci_pa)
    rec, parm = tmp_path / "r.json", tmp_path / "new.params"
    assert _run(["identify", str(log), "--oat-c", "15", "--no-budget", "--json", str(rec),
                 "--params", str(parm)]) == 0
    doc = json.loads(rec.read_text())
    assert [s["qc_source"].split(".")[0] for s in doc["sensors"]] == \
        ["differential_pressure", "differential_pressure[1]"]
    params = read_qgc_params(parm)
    assert set(params) == {"ASPD_SCALE_1", "ASPD_SCALE_2"}
    # scale = V_c / IAS = 1 / sqrt(1 - f): the square of their ratio is the ratio's
    assert (params["ASPD_SCALE_1"] / params["ASPD_SCALE_2"]) ** 2 == \
        pytest.approx(_true_ratio_of_ratios(fa), abs=0.006)


def test_tlog_with_two_sensors_identifies_and_converts(two, tmp_path, capsys):
    fa, fb, _ = two
    log = write_tlog(tmp_path / "two.tlog", fa, second=fb.qci_pa, params={"ARSPD_RATIO": 1.9})
    rec = tmp_path / "r.json"
    assert _run(["identify", str(log), "--no-budget", "--json", str(rec)]) == 0
    doc = json.loads(rec.read_text())
    assert [s["qc_source"] for s in doc["sensors"]] == [
        "SCALED_PRESSURE.press_diff (hPa)", "SCALED_PRESSURE2.press_diff (hPa)"]
    csv = tmp_path / "c.csv"
    assert _run(["convert", str(log), "-o", str(csv)]) == 0
    head = csv.read_text()[:3000]
    assert "# qc_source: SCALED_PRESSURE.press_diff (hPa)" in head
    assert "# autopilot_ARSPD_RATIO: 1.9" in head
    assert "# airspeed_sensors: SCALED_PRESSURE.press_diff (hPa); SCALED_PRESSURE2" in head
    # the converted CSV holds the first sensor: identified as it alone
    assert _run(["identify", str(csv), "--no-budget", "--json", str(rec)]) == 0
    assert "sensors" not in json.loads(rec.read_text())


def test_tlog_without_airspeed_exits_2_in_one_line(two, tmp_path, capsys):
    log = write_tlog(tmp_path / "nodp.tlog", two[0], press_diff=False)
    assert _run(["identify", str(log), "--no-budget"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "SCALED_PRESSURE.press_diff is zero in all" in err[0]


def test_report_refits_the_sensors_jointly(two, tmp_path):
    """`report --flight` of a two-sensor result re-runs the joint fit the record came from:
    the first sensor's k1 to the last digit (its fit alone differs), so the report's figures
    are the record's and it does not warn that the flight fails to reproduce it."""
    from pitotcal.estimation import identify
    from pitotcal.estimation.reporting.refit import refit

    fa, fb, _ = two
    log = write_dataflash_bin(tmp_path / "two.bin", fa, second=fb.qci_pa, ratio=1.9,
                              second_ratio=2.1)
    rec = tmp_path / "r.json"
    assert _run(["identify", str(log), "--json", str(rec), "--oat-c", "15"]) == 0
    doc = json.loads(rec.read_text())
    flight, ident = refit(doc, log)
    k1 = doc["parameters"]["k1"]["value"]
    assert ident.value("k1") == pytest.approx(k1, rel=1e-9)
    alone = identify(flight, model=doc["model"], air=doc["air_data"], wind="constant")
    assert abs(alone.value("k1") - k1) > 1e-6
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["report", str(rec), "--flight", str(log), "-o",
                     str(tmp_path / "r.html")]) == 0
    assert not [w for w in caught if "does not reproduce" in str(w.message)]
