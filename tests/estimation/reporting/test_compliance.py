"""Compliance verdicts on constructed results: inside, outside, straddling, beyond the flown range."""

import pytest
from pitotcal.estimation.reporting.compliance import assess, flown_range_kcas
from reportfixtures import result_json

from pitotcal.core.errors import PitotcalError


def _verdicts(block):
    return {r["verdict"] for r in block["airspeed"]["rows"]}


def test_inside_complies_with_expanded_uncertainty():
    # |ΔV| + U = 1 + 2 = 3 kt < 5 kt at every speed (3 % of 99 KCAS is 2.97 kt: 5 kt governs)
    block = assess(result_json(dv_kt=-1.0, u_kt=2.0), "23.1323")
    assert block["verdict"] == "complies" and _verdicts(block) == {"complies"}
    assert block["uncertainty"] == "expanded"
    assert block["speed_range_source"] == "flown"
    assert block["speed_range_kt"] == pytest.approx([69.0, 99.0])
    assert all(r["u_kt"] == 2.0 and r["limit_kt"] == 5.0 for r in block["airspeed"]["rows"])


def test_three_percent_governs_above_166_kt():
    block = assess(result_json(dv_kt=5.5, band_kt=0.2, vi_kt=(200.0, 250.0)), "25.1323")
    row = block["airspeed"]["rows"][-1]
    assert row["limit_kt"] == pytest.approx(0.03 * (250.0 + 5.5))
    assert block["verdict"] == "complies"          # 5.7 kt < 3 % of 205.5 kt = 6.2 kt


def test_outside_does_not_comply():
    block = assess(result_json(dv_kt=-7.0, u_kt=1.0), "23.1323")
    assert block["verdict"] == "does not comply" and _verdicts(block) == {"does not comply"}


def test_straddling_is_not_demonstrated():
    block = assess(result_json(dv_kt=4.5, u_kt=1.0), "23.1323")
    assert block["verdict"] == "not demonstrated"
    assert all("straddles" in r["reason"] for r in block["airspeed"]["rows"])


def test_one_failing_speed_fails_the_whole():
    block = assess(result_json(dv_kt=lambda v: -7.0 if v > 95 else -1.0, u_kt=0.5), "23.1323")
    assert block["verdict"] == "does not comply"
    assert _verdicts(block) == {"complies", "does not comply"}


def test_range_beyond_flown_is_not_demonstrated_never_extrapolated():
    block = assess(result_json(dv_kt=-1.0, u_kt=0.5), "23.1323", speed_range_kt=(60.0, 120.0))
    rows = block["airspeed"]["rows"]
    assert block["speed_range_source"] == "given"
    assert block["verdict"] == "not demonstrated"
    ends = [r for r in rows if r["vc_kt"] in (60.0, 120.0)]
    assert len(ends) == 2 and all(r["dv_kt"] is None and "not extrapolated" in r["reason"]
                                  for r in ends)
    assert {r["verdict"] for r in rows if r not in ends} == {"complies"}


def test_range_inside_flown_interpolates_its_ends():
    res = result_json(dv_kt=lambda v: -0.1 * (v - 70.0), u_kt=0.5)
    block = assess(res, "23.1323", speed_range_kt=(72.0, 90.0))
    assert block["verdict"] == "complies"
    first = block["airspeed"]["rows"][0]
    # vc = vi - 0.1 (vi - 70) = 72  ->  vi = 72.222, dv = -0.2222
    assert first["vc_kt"] == 72.0 and first["dv_kt"] == pytest.approx(-2.0 / 9.0, abs=1e-9)


def test_statistical_only_is_said():
    block = assess(result_json(dv_kt=-1.0, band_kt=0.3), "23.1323")
    assert block["uncertainty"] == "statistical"
    assert "only the statistical 2σ" in block["uncertainty_note"]
    assert block["airspeed"]["rows"][0]["u_kt"] == 0.3


def test_altimeter_needs_static_data():
    no_dh = assess(result_json(u_kt=1.0), "23.1323")["altimeter"]
    assert no_dh["verdict"] == "not demonstrated" and "no static-source data" in no_dh["reason"]
    # limit 0.3 ft per KCAS: 69 KCAS -> 20.7 ft; 15 + 2 inside, 25 + 2 outside
    ok = assess(result_json(u_kt=1.0, dh_ft=15.0), "23.1323")["altimeter"]
    assert ok["verdict"] == "complies"
    assert ok["rows"][0]["limit_ft"] == pytest.approx(0.3 * 69.0)
    bad = assess(result_json(u_kt=1.0, dh_ft=-40.0), "23.1323")["altimeter"]
    assert bad["verdict"] == "does not comply"
    edge = assess(result_json(u_kt=1.0, dh_ft=20.0, dh_2sigma_ft=2.0), "23.1323")["altimeter"]
    assert edge["rows"][0]["verdict"] == "not demonstrated"


def test_none_and_bad_arguments():
    assert assess(result_json(), "none")["verdict"] is None
    with pytest.raises(PitotcalError, match="regulation 'CS-VLA' is not one of"):
        assess(result_json(), "CS-VLA")
    with pytest.raises(PitotcalError, match="highest speed must be above"):
        assess(result_json(), "23.1323", speed_range_kt=(90.0, 80.0))
    with pytest.raises(PitotcalError, match="no airspeed_correction rows"):
        assess({"airspeed_correction": []}, "23.1323")
    assert flown_range_kcas(result_json(dv_kt=-1.0)) == (69.0, 99.0)


def test_range_wholly_beyond_flown_has_no_verdict_but_not_demonstrated():
    block = assess(result_json(dv_kt=-1.0, u_kt=0.5, dh_ft=5.0), "25.1323",
                   speed_range_kt=(150.0, 200.0))
    assert [r["vc_kt"] for r in block["airspeed"]["rows"]] == [150.0, 200.0]
    assert block["verdict"] == "not demonstrated"
    alt = block["altimeter"]
    assert alt["verdict"] == "not demonstrated"
    assert all("not extrapolated" in r["reason"] for r in alt["rows"])


def test_overall_verdict_is_the_worst_of_airspeed_and_altimeter():
    # airspeed complies (|-1| + 1 < 5 kt), the altimeter does not (40 - 2 > 0.3 ft/KCAS x 69-99)
    block = assess(result_json(dv_kt=-1.0, u_kt=1.0, dh_ft=-40.0), "23.1323")
    assert block["airspeed"]["verdict"] == "complies"
    assert block["altimeter"]["verdict"] == "does not comply"
    assert block["verdict"] == "does not comply"
    # straddling altimeter band: the headline is not demonstrated
    edge = assess(result_json(dv_kt=-1.0, u_kt=1.0, dh_ft=20.0), "23.1323")
    assert edge["verdict"] == "not demonstrated"


def test_transport_regulation_names_its_altimeter_paragraph():
    part25 = assess(result_json(u_kt=1.0, dh_ft=15.0), "25.1323")["altimeter"]
    part23 = assess(result_json(u_kt=1.0, dh_ft=15.0), "23.1323")["altimeter"]
    assert "25.1325" in part25["title"] and "23.1325(e)" in part23["title"]
    # the 23.1325(e) limit is applied to both (no ±30 ft floor: not confirmed for 25.1325)
    assert part25["rows"][0]["limit_ft"] == pytest.approx(0.3 * 69.0)
