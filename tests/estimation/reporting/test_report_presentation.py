"""What a reader of the calibration report sees: options as given (no Python values), no empty
rows, the budget by source and by speed in words, every speed axis in KIAS and kt, the U band
on the figures, and headings kept with what follows them in print."""

import re
import warnings

import pytest
from pitotcal.estimation.reporting import figures as figs
from pitotcal.estimation.reporting.budget_tables import add_budget
from pitotcal.estimation.reporting.calibration_report import build_report, render_html
from reportfixtures import result_json

import pitotcal
from pitotcal.core.scenario import T2_PLAN
from pitotcal.core.units import m_to_ft
from pitotcal.estimation.identification.budget import uncertainty_budget


@pytest.fixture(scope="module")
def fitted():
    """(flight, ident, result JSON with the budget) of a short simulated T-2 flight."""
    plan = pitotcal.plan_maneuver(**{**T2_PLAN, "duration_s": 180.0})
    flight, _ = pitotcal.simulate(plan, seed=1, turbulence_mps=0.5, rate_hz=10.0,
                                  air_data="compressible")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ident = pitotcal.identify(flight, model="inverse", air="compressible")
        budget = uncertainty_budget(flight, ident, air="compressible")
    return flight, ident, add_budget(ident.to_dict(), budget)


def _rows(html, section):
    part = html.split(f'<section id="{section}">')[1].split("</section>")[0]
    return dict(re.findall(r"<tr><th>([^<]*)</th><td>(.*?)</td></tr>", part, flags=re.S))


def test_provenance_lists_options_given_as_a_person_reads_them():
    options = {"end_s": None, "verbose": False, "speed_range_kt": [70.0, 100.0], "pdf": True,
               "regulation": "23.1323", "rh_percent": 40.0, "aircraft": ""}
    rows = _rows(render_html(build_report(result_json(dv_kt=-1.0), options=options)),
                 "provenance")
    opts = {k.removeprefix("option "): re.sub(r"</?code>", "", v) for k, v in rows.items()
            if k.startswith("option ")}
    assert opts == {"pdf": "yes", "regulation": "23.1323", "rh percent": "40",
                    "speed range kt": "70 100"}


def test_no_result_source_row_without_a_source():
    res = result_json(dv_kt=-1.0)
    assert _rows(render_html(build_report(res)), "conditions")["Result source"] == "flight.csv"
    del res["source"]
    assert "Result source" not in _rows(render_html(build_report(res)), "conditions")


def test_level_flight_altitude_and_density_are_one_value(fitted):
    flight, ident, result = fitted
    rows = _rows(render_html(build_report(result, flight=flight, ident=ident)), "conditions")
    assert rows["Altitude (GPS)"] == f"{m_to_ft(flight.alt_m.mean()):.0f} ft"
    assert "–" not in rows["Air density"]


def test_budget_in_words_with_a_speed_column(fitted):
    flight, ident, result = fitted
    html = render_html(build_report(result, flight=flight, ident=ident))
    assert 'id="budget-table"' in html and 'id="budget-speed-table"' in html
    for snake in ("gps_velocity_bias", "qc_scale", "probe_lever_arm"):
        assert snake not in html
    assert "Outside air temperature" in html and "0.1 % of reading" in html
    # where each input came from, and the settings behind the defaults, in words
    table = html.split('id="budget-table"')[1].split("</table>")[0]
    assert "<th>Input from</th>" in table and "default of class flight-test" in table
    assert "Static-pressure transducer" in table
    settings = html.split('id="budget-settings"')[1].split("</p>")[0]
    assert "Sensor class: flight-test (default)" in settings
    assert "Temperature source: probe (the flight: oat_k)" in settings
    assert "Probe lever arm corrected in the data: 0 m (none corrected)" in settings
    table = html.split('id="budget-speed-table"')[1].split("</table>")[0]
    body = re.findall(r"<tr><td class=\"num\">([\d.]+)</td>", table)
    assert [float(v) for v in body] == [r["vi_kt"] for r in result["airspeed_correction"]]
    # each row's U is 2 u_c of its sources (GUM, k = 2)
    for row in result["airspeed_correction"]:
        u = row["u_dv_by_source_kt"]
        assert row["dv_U_kt"] == pytest.approx(2 * sum(x * x for x in u.values()) ** 0.5,
                                               rel=1e-9)


def test_figures_speak_kias_and_kt_and_show_u(fitted, monkeypatch):
    flight, ident, result = fitted
    made = []
    monkeypatch.setattr(figs, "png_bytes", lambda fig: made.append(fig) or b"")
    build_report(result, flight=flight, ident=ident)
    assert len(made) == 4                   # correction, altimeter, calibration, track
    speed_axes = [ax for fig in made for ax in fig.axes if "airspeed" in ax.get_xlabel()]
    assert len(speed_axes) == 4
    assert {ax.get_xlabel() for ax in speed_axes} == {figs.VI_LABEL}
    for fig in made[:1] + made[2:3]:        # the ΔV panels: 2σ and U
        labels = fig.axes[0].get_legend_handles_labels()[1]
        assert any(lab.startswith("U (k = 2)") for lab in labels), labels
    titles = " ".join(ax.get_title() for fig in made for ax in fig.axes)
    assert "m/s" not in titles and " kt from " in titles


def test_headings_stay_with_what_follows_in_print():
    html = render_html(build_report(result_json(dv_kt=-1.0, u_kt=1.0, dh_ft=1.0)))
    css = html.split("<style>")[1].split("</style>")[0]
    assert re.search(r"h1, h2, h3 \{ break-after: avoid; page-break-after: avoid; \}", css)
    assert re.search(r"table, figure, li, \.keep \{ break-inside: avoid;", css)
    # each sub-heading of the corrections is kept with its note and table
    corrections = html.split('<section id="tables">')[1].split("</section>")[0]
    assert corrections.count('<div class="keep">\n<h3>') == corrections.count("<h3>")


def test_the_demo_calibration_figure_and_report_show_u(tmp_path, monkeypatch):
    import pitotcal.io.atomic as atomic
    from pitotcal.studies.demo import run_demo

    saved, real = {}, atomic.save_figure
    monkeypatch.setattr(atomic, "save_figure",
                        lambda fig, path, **kw: saved.setdefault(path.name, fig) and
                        real(fig, path, **kw))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        demo = run_demo(tmp_path, duration_s=180.0, rate_hz=10.0)
    labels = saved["calibration.png"].axes[0].get_legend_handles_labels()[1]
    assert any(lab.startswith("U (k = 2)") for lab in labels), labels
    html = demo.files["report_html"].read_text()
    assert "U not available" not in html and 'id="budget-speed-table"' in html
