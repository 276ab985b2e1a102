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
    assert block["airspeed"]["verdict"] == "complies" and _verdicts(block) == {"complies"}
    assert block["uncertainty"] == "expanded"
    assert block["speed_range_source"] == "flown"
    assert block["speed_range_kt"] == pytest.approx([69.0, 99.0])
    assert all(r["u_kt"] == 2.0 and r["limit_kt"] == 5.0 for r in block["airspeed"]["rows"])


def test_three_percent_governs_above_166_kt():
    block = assess(result_json(dv_kt=5.5, band_kt=0.2, vi_kt=(200.0, 250.0)), "25.1323")
    row = block["airspeed"]["rows"][-1]
    assert row["limit_kt"] == pytest.approx(0.03 * (250.0 + 5.5))
    assert block["airspeed"]["verdict"] == "complies"  # 5.7 kt < 3 % of 205.5 kt = 6.2 kt


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
    assert block["airspeed"]["verdict"] == "complies"
    judged = [r for r in block["airspeed"]["rows"] if r["verdict"] != "not judged"]
    first = judged[0]
    # vc = vi - 0.1 (vi - 70) = 72  ->  vi = 72.222, dv = -0.2222
    assert first["vc_kt"] == 72.0 and first["dv_kt"] == pytest.approx(-2.0 / 9.0, abs=1e-9)
    # the table's rows outside the range are shown, not judged
    outside = [r for r in block["airspeed"]["rows"] if r["verdict"] == "not judged"]
    assert outside and all(not 72.0 <= r["vc_kt"] <= 90.0 for r in outside)


def test_statistical_only_is_said():
    block = assess(result_json(dv_kt=-1.0, band_kt=0.3), "23.1323")
    assert block["uncertainty"] == "statistical"
    assert "only the statistical 2σ" in block["uncertainty_note"]
    assert block["airspeed"]["rows"][0]["u_kt"] == 0.3


def test_altimeter_needs_static_data():
    no_dh = assess(result_json(u_kt=1.0), "23.1323")["altimeter"]
    assert no_dh["verdict"] == "not demonstrated" and "no static-source data" in no_dh["reason"]
    # limit 0.3 ft per KCAS, at least 30 ft: 69-99 KCAS -> 30 ft; 15 + 2 inside, 40 - 2 outside
    ok = assess(result_json(u_kt=1.0, dh_ft=15.0), "23.1323")["altimeter"]
    assert ok["verdict"] == "complies"
    assert ok["rows"][0]["limit_ft"] == pytest.approx(30.0)
    bad = assess(result_json(u_kt=1.0, dh_ft=-40.0), "23.1323")["altimeter"]
    assert bad["verdict"] == "does not comply"
    edge = assess(result_json(u_kt=1.0, dh_ft=29.0, dh_2sigma_ft=2.0), "23.1323")["altimeter"]
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
    judged = [r for r in block["airspeed"]["rows"] if r["verdict"] != "not judged"]
    assert [r["vc_kt"] for r in judged] == [150.0, 200.0]
    assert block["verdict"] == "not demonstrated"
    alt = block["altimeter"]
    assert alt["verdict"] == "not demonstrated"
    assert all("not extrapolated" in r["reason"] for r in alt["rows"]
               if r["verdict"] != "not judged")


def test_overall_verdict_is_the_worst_of_airspeed_and_altimeter():
    # airspeed complies (|-1| + 1 < 5 kt), the altimeter does not (40 - 2 > 0.3 ft/KCAS x 69-99)
    block = assess(result_json(dv_kt=-1.0, u_kt=1.0, dh_ft=-40.0), "23.1323")
    assert block["airspeed"]["verdict"] == "complies"
    assert block["altimeter"]["verdict"] == "does not comply"
    assert block["verdict"] == "does not comply"
    # straddling altimeter band (29 ± 2 ft against the 30 ft floor): not demonstrated
    edge = assess(result_json(dv_kt=-1.0, u_kt=1.0, dh_ft=29.0), "23.1323")
    assert edge["verdict"] == "not demonstrated"


def test_transport_regulation_names_its_altimeter_paragraph():
    part25 = assess(result_json(u_kt=1.0, dh_ft=15.0), "25.1323")["altimeter"]
    part23 = assess(result_json(u_kt=1.0, dh_ft=15.0), "23.1323")["altimeter"]
    assert "25.1325" in part25["title"] and "23.1325(e)" in part23["title"]
    # both paragraphs: ±30 ft per 100 kt, and need not be less than ±30 ft
    assert part25["rows"][0]["limit_ft"] == pytest.approx(30.0)
    assert part25["rows"][-1]["limit_ft"] == pytest.approx(30.0)


def test_altimeter_is_judged_at_sea_level_in_a_standard_atmosphere():
    # 80.0 ft at 10,000 ft and 262 KCAS, against 78.6 ft: at sea level the same static error is
    # 59.1 ft (about 80 ρ(10,000 ft)/ρ0 = 80 x 0.738), inside the limit
    res = result_json(dv_kt=0.0, u_kt=1.0, dh_ft=80.0, dh_2sigma_ft=0.2, vi_kt=(262.0, 262.0),
                      altitude_ft=10000.0)
    row = assess(res, "23.1323")["altimeter"]["rows"][0]
    assert row["dh_test_altitude_ft"] == 80.0
    assert row["dh_ft"] == pytest.approx(59.06, abs=0.02)
    assert row["limit_ft"] == pytest.approx(0.3 * 262.0)
    assert row["verdict"] == "complies"
    # judged at the test altitude it would not: |80| - 0.2 > 78.6
    at_sea = assess(result_json(dv_kt=0.0, u_kt=1.0, dh_ft=80.0, dh_2sigma_ft=0.2,
                                vi_kt=(262.0, 262.0)), "23.1323")["altimeter"]["rows"][0]
    assert at_sea["dh_ft"] == pytest.approx(80.0, abs=1e-6)
    assert at_sea["verdict"] == "does not comply"


@pytest.mark.parametrize("dh", [17.0, 22.0, 29.0])
def test_the_30_ft_floor_at_low_speed(dh):
    # 46-60 KCAS: 0.3 ft/kt gives 13.8-18 ft, the floor 30 ft; ΔH 17-29 ft +- 0.5 complies
    res = result_json(dv_kt=0.0, u_kt=1.0, dh_ft=dh, dh_2sigma_ft=0.5, vi_kt=(46.0, 60.0),
                      step_kt=2.0)
    alt = assess(res, "23.1323")["altimeter"]
    assert alt["verdict"] == "complies"
    assert all(r["limit_ft"] == 30.0 and "floor" in r["reason"] for r in alt["rows"])


def test_altimeter_complies_only_when_its_expanded_uncertainty_is_inside():
    # 60 ft at sea level, 250 KCAS: limit 75 ft. U 10 ft: 70 <= 75 complies; U 20 ft: straddles
    def one(u):
        return assess(result_json(u_kt=1.0, dh_ft=60.0, dh_u_ft=u, vi_kt=(251.0, 251.0)),
                      "25.1323")["altimeter"]["rows"][0]
    assert one(10.0)["verdict"] == "complies" and one(10.0)["u_kind"] == "expanded"
    assert one(10.0)["u_ft"] == pytest.approx(10.0, abs=1e-6)
    assert one(20.0)["verdict"] == "not demonstrated"
    assert one(20.0)["u_ft"] == pytest.approx(20.0, abs=1e-6)
    # U reduced to sea level with ΔH: at 10,000 ft both shrink by about 0.74
    high = assess(result_json(u_kt=1.0, dh_ft=60.0, dh_u_ft=10.0, vi_kt=(251.0, 251.0),
                              altitude_ft=10000.0), "25.1323")["altimeter"]["rows"][0]
    assert high["u_ft"] == pytest.approx(7.38, abs=0.05)


def test_a_row_without_u_is_judged_on_its_own_2sigma_and_named():
    res = result_json(dv_kt=-1.0, u_kt=1.0, band_kt=0.3)
    res["airspeed_correction"][2]["dv_U_kt"] = None
    block = assess(res, "23.1323")
    kinds = [r["u_kind"] for r in block["airspeed"]["rows"]]
    assert kinds.count("statistical") == 1 and kinds.count("expanded") == len(kinds) - 1
    assert block["airspeed"]["rows"][2]["u_kt"] == 0.3
    assert block["airspeed"]["rows"][0]["u_kt"] == 1.0
    assert "statistical 2σ only" in block["airspeed"]["rows"][2]["reason"]
    assert block["uncertainty"] == "partial" and "79.0 KCAS" in block["uncertainty_note"]


def test_unknown_test_altitude_is_not_demonstrated():
    res = result_json(u_kt=1.0, dh_ft=10.0)
    del res["static_source"]
    alt = assess(res, "23.1323")["altimeter"]
    assert alt["verdict"] == "not demonstrated" and "test altitude is unknown" in alt["reason"]


def test_the_rule_window_from_stall_speeds_and_configuration():
    speeds = {"V_S0": 40.0, "V_S1": 50.0, "V_FE": 85.0, "V_NE": 150.0}
    res = result_json(dv_kt=-1.0, u_kt=1.0, dh_ft=10.0, vi_kt=(50.0, 100.0))
    block = assess(res, "23.1323", configuration="cruise", speeds_kcas=speeds)
    # airspeed, flaps retracted: 1.3 V_S1 = 65 to V_NE = 150 (beyond the flown 99: not shown
    # as compliant); altimeter: 1.3 V_S0 = 52 to 1.8 V_S1 = 90
    assert block["speed_range_kt"] == pytest.approx([65.0, 150.0])
    assert block["speed_range_source"] == "rule" and block["configuration"] == "cruise"
    air = block["airspeed"]["rows"]
    assert {r["verdict"] for r in air if r["vc_kt"] < 65.0} == {"not judged"}
    assert air[-1]["vc_kt"] == 150.0 and "not extrapolated" in air[-1]["reason"]
    assert block["airspeed"]["verdict"] == "not demonstrated"
    alt = block["altimeter"]
    assert alt["window"]["lo_kt"] == pytest.approx(52.0)
    assert alt["window"]["hi_kt"] == pytest.approx(90.0)
    assert alt["verdict"] == "complies"
    assert {r["verdict"] for r in alt["rows"] if not 52.0 <= r["vc_kt"] <= 90.0} == \
        {"not judged"}
    landing = assess(res, "23.1323", configuration="landing", speeds_kcas=speeds)
    assert landing["speed_range_kt"] == pytest.approx([65.0, 85.0])
    assert landing["airspeed"]["verdict"] == "complies"
    part25 = assess(res, "25.1323", configuration="approach",
                    speeds_kcas={"V_SR0": 45.0, "V_SR1": 55.0})
    assert part25["speed_range_source"] == "none"
    assert part25["airspeed"]["verdict"] == "not demonstrated"
    with pytest.raises(PitotcalError, match="`configuration` 'landng' is not one of"):
        assess(res, "23.1323", configuration="landng", speeds_kcas=speeds)


def test_quotes_name_the_paragraphs_and_the_consensus_standard():
    block = assess(result_json(u_kt=1.0, dh_ft=10.0), "23.1323")
    paragraphs = {q["paragraph"] for q in block["quotes"]}
    assert {"14 CFR 23.1323(b)", "14 CFR 23.1325(e)", "14 CFR 29.1325(f)"} <= paragraphs
    assert any("need not be less than ±30 feet" in q["text"] for q in block["quotes"])
    assert "ASTM F3233" in block["basis"]


@pytest.mark.parametrize("kwargs, key", [
    ({"u_kt": -2.0}, "dv_U_kt"),
    ({"band_kt": -2.0}, "dv_2sigma_kt"),
    ({"u_kt": 0.5, "dh_ft": 80.0, "dh_u_ft": -30.0, "altitude_ft": 10000.0}, "dh_U_ft"),
])
def test_a_negative_uncertainty_is_refused_not_passed(kwargs, key):
    # ΔV 6 kt against the 5 kt limit: |6| + (-2) <= 5 would have said "complies"
    kwargs = {"dv_kt": 6.0, "band_kt": 0.3, **kwargs}
    if "dh_ft" in kwargs:
        kwargs["dv_kt"] = -1.0
    with pytest.raises(PitotcalError, match=f"`result`.*{key} -[0-9.]+ is negative"):
        assess(result_json(**kwargs))


def test_a_large_altimeter_error_is_judged_not_refused():
    """ΔH −2,500 ft at sea level lies below the ISA table's −2,000 ft: the reduction's laws
    carry it (unchanged at sea level) and the row does not comply; the report is written."""
    block = assess(result_json(dv_kt=-1.0, u_kt=0.5, dh_ft=-2500.0, dh_u_ft=3.0))
    row = block["altimeter"]["rows"][0]
    assert row["dh_ft"] == pytest.approx(-2500.0, abs=1e-6)
    assert block["altimeter"]["verdict"] == "does not comply"


def test_an_altimeter_that_cannot_be_judged_keeps_the_headline_from_complying():
    """No static-source data: the airspeed complies, the altimeter is not demonstrated, and so
    is the whole verdict (a certification reader must not see "complies" for half a check)."""
    block = assess(result_json(dv_kt=-1.0, u_kt=2.0), "23.1323")
    assert block["airspeed"]["verdict"] == "complies"
    assert block["altimeter"]["verdict"] == "not demonstrated" and block["altimeter"]["rows"] == []
    assert block["verdict"] == "not demonstrated"
