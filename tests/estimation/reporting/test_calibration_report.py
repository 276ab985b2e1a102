"""The calibration report's HTML from constructed results, with and without the newer keys."""

import base64
import re

import pytest
from pitotcal.estimation.reporting.calibration_report import (
    build_report,
    read_aircraft,
    read_result,
    render_html,
)
from reportfixtures import result_json

from pitotcal.core.errors import PitotcalError


def _html(result, **kw):
    return render_html(build_report(result, **kw))


def _images(html):
    return re.findall(r'src="data:image/png;base64,([^"]+)"', html)


def test_full_result_shows_u_altimeter_mach_and_budget():
    res = result_json(dv_kt=-1.0, u_kt=1.2, dh_ft=10.0)
    html = _html(res, options={"regulation": "23.1323"})
    for anchor in ('id="airspeed-table"', 'id="altimeter-table"', 'id="mach-table"',
                   'id="compliance-table"', 'id="altimeter-compliance-table"',
                   "Uncertainty budget", "transducer calibration", "option regulation"):
        assert anchor in html, anchor
    assert "U not available" not in html
    images = _images(html)
    assert len(images) == 2            # airspeed and altimeter corrections
    assert all(base64.b64decode(i)[:8] == b"\x89PNG\r\n\x1a\n" for i in images)
    assert re.search(r'id="verdict">Airspeed system:\s*<span class="verdict complies">COMPLIES',
                     html)


def test_bare_result_says_what_is_missing():
    html = _html(result_json(dv_kt=-1.0))
    assert "U not available in this result" in html
    assert "only the statistical 2σ" in html
    assert "no static-source data" in html and 'id="mach-table"' not in html
    assert len(_images(html)) == 1
    assert "No aircraft file given" in html


def test_legs_are_shown_when_present():
    html = _html(result_json(legs=True))
    assert 'id="legs-table"' in html and "three-leg" in html and "global: dv_kt_at_80" in html
    assert 'id="legs-table"' not in _html(result_json())


def test_ratio_column_is_dp_over_qci_from_the_speeds():
    # ΔV = -1 kt at 70 KIAS: q ∝ V², so Δp/q_ci = (69/70)² - 1 = -0.0284 (incompressible)
    ctx = build_report(result_json(dv_kt=-1.0, dh_ft=1.0))
    row = next(r for r in ctx["mach_rows"] if r["vi"] == 70.0)
    assert row["ratio"] == pytest.approx((69.0 / 70.0) ** 2 - 1.0, abs=2e-4)


def test_text_is_escaped():
    res = result_json()
    res["warnings"] = ["<script>alert(1)</script>"]
    html = _html(res)
    assert "<script>alert" not in html and "&lt;script&gt;" in html


def test_aircraft_toml(tmp_path):
    path = tmp_path / "a.toml"
    path.write_text('[aircraft]\nregistration = "D-EABC"\ntype = "DR400"\n'
                    '[test]\npilot = "P"\nfuel = "full"\n')
    rows = read_aircraft(path)
    assert rows[:2] == [("Aircraft", "DR400"), ("Registration", "D-EABC")]
    assert ("test.fuel", "full") in rows
    path.write_text("[aircraft\n")
    with pytest.raises(PitotcalError, match="not valid TOML"):
        read_aircraft(path)


def test_read_result_refuses_other_files(tmp_path):
    bad = tmp_path / "x.json"
    bad.write_text("{not json")
    with pytest.raises(PitotcalError, match="not a JSON file"):
        read_result(bad)
    bad.write_text('{"model": "inverse"}')
    with pytest.raises(PitotcalError, match="no airspeed_correction table"):
        read_result(bad)


def test_a_flight_that_does_not_reproduce_the_result_is_a_warning():
    from pitotcal.estimation import identify
    from pitotcal.estimation.reporting.refit import reproduces as _reproduces
    from synthetic import synthetic_flight

    ident = identify(synthetic_flight(seed=7, n=1500)[0])
    doc = ident.to_dict()
    assert _reproduces(doc, ident) == []
    doc["parameters"]["k1"]["value"] += 0.2 * doc["parameters"]["k1"]["std"]
    (warning,) = _reproduces(doc, ident)
    assert warning.startswith("the flight given does not reproduce the result (k1")


def test_regulation_none_makes_no_statement():
    html = _html(result_json(u_kt=1.0), regulation="none")
    assert "No regulation chosen" in html and 'id="compliance-table"' not in html
