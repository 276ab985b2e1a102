"""The report in a real headless Chromium: every figure decodes, tables and verdict are there,
and a screenshot is taken (kept under pytest's tmp_path for a person to look at).

Chromium is driven from its command line (``--dump-dom``, ``--screenshot``): a copy of the
report gets a small script that, after the page loaded, marks each image with its decoded
width, so the dumped DOM says whether the browser could show it.
"""

import json
import re
import shutil
import subprocess

import pytest
from reportfixtures import result_json

from pitotcal.cli import main

BROWSER = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome")
                if shutil.which(b)), None)
pytestmark = pytest.mark.skipif(
    BROWSER is None, reason="no headless Chromium on PATH (Debian: apt-get install chromium)")

_MARK = """<script>
window.addEventListener("load", () => {
  for (const img of document.images) {
    img.setAttribute("data-decoded", img.complete && img.naturalWidth > 0 ? "yes" : "no");
  }
  document.body.setAttribute("data-loaded", "yes");
});
</script></body>"""


def _chromium(*args):
    cmd = [BROWSER, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
           "--virtual-time-budget=5000", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False)


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """A report with every table and figure the JSON alone gives (the figures of a flight
    are embedded the same way: tests/cli/test_report.py counts them)."""
    tmp = tmp_path_factory.mktemp("browser")
    result = tmp / "result.json"
    result.write_text(json.dumps(result_json(dv_kt=lambda v: -0.05 * (v - 60), u_kt=1.2,
                                             dh_ft=lambda v: 0.1 * (v - 60), legs=True)))
    html = tmp / "report.html"
    assert main(["report", str(result), "-o", str(html)]) == 0
    return html


def test_report_loads_in_chromium_with_every_figure(report):
    probe = report.with_name("probe.html")
    probe.write_text(report.read_text().replace("</body>", _MARK))
    proc = _chromium("--dump-dom", probe.as_uri())
    dom = proc.stdout
    assert 'data-loaded="yes"' in dom, proc.stderr[-500:]
    decoded = re.findall(r'data-decoded="(yes|no)"', dom)
    assert decoded == ["yes"] * 2          # airspeed and altimeter corrections
    for anchor in ('id="airspeed-table"', 'id="altimeter-table"', 'id="mach-table"',
                   'id="legs-table"', 'id="compliance-table"', 'id="verdict"',
                   "Provenance", "Signatures"):
        assert anchor in dom
    assert re.search(r'class="verdict (complies|does-not-comply|not-demonstrated)"', dom)


def test_screenshot(report):
    import matplotlib.image as mpimg

    shot = report.with_name("report.png")
    proc = _chromium("--window-size=1100,3000", f"--screenshot={shot}", report.as_uri())
    assert shot.is_file(), proc.stderr[-500:]
    img = mpimg.imread(shot)
    assert img.shape[0] == 3000 and img.shape[1] == 1100
    assert img[..., :3].std() > 0.05          # not a blank page


@pytest.mark.slow
def test_pdf_through_chromium(tmp_path):
    res = tmp_path / "res.json"
    res.write_text(json.dumps(result_json(u_kt=1.0)))
    pdf = tmp_path / "r.pdf"
    assert main(["report", str(res), "-o", str(tmp_path / "r.html"), "--pdf", str(pdf)]) == 0
    assert pdf.read_bytes()[:5] == b"%PDF-"


def test_report_shows_configuration_windows_and_quoted_paragraphs(tmp_path):
    """The altimeter judged at sea level: 80 ft at 10,000 ft and 262 KCAS complies (59.1 ft
    against 78.6 ft); the page shows the configuration, both speed ranges and the words of
    each paragraph beside the numbers."""
    result = tmp_path / "result.json"
    result.write_text(json.dumps(result_json(dv_kt=-1.0, u_kt=1.5, dh_ft=80.0, dh_u_ft=4.0,
                                             vi_kt=(200.0, 262.0), step_kt=2.0,
                                             altitude_ft=10000.0)))
    aircraft = tmp_path / "aircraft.toml"
    aircraft.write_text('[aircraft]\ntype = "Test"\nconfiguration = "cruise"\n'
                        "vs0_kcas = 100.0\nvs1_kcas = 155.0\nvne_kcas = 300.0\n")
    html = tmp_path / "report.html"
    assert main(["report", str(result), "-o", str(html), "--aircraft", str(aircraft),
                 "--json", str(tmp_path / "out.json")]) == 0
    block = json.loads((tmp_path / "out.json").read_text())["compliance"]
    top = [r for r in block["altimeter"]["rows"] if r["vc_kt"] == pytest.approx(261.0)][0]
    assert top["dh_test_altitude_ft"] == 80.0 and top["dh_ft"] == pytest.approx(59.06, abs=0.05)
    assert top["verdict"] == "complies"
    # altimeter range 1.3 V_S0 = 130 to 1.8 V_S1 = 279 KCAS; airspeed (flaps retracted)
    # 1.3 V_S1 = 201.5 to V_NE = 300: the row at 199 KCAS is shown and not judged
    assert block["altimeter"]["window"]["hi_kt"] == pytest.approx(279.0)
    assert block["speed_range_kt"] == pytest.approx([201.5, 300.0])
    assert {r["verdict"] for r in block["airspeed"]["rows"] if r["vc_kt"] < 201.5} == \
        {"not judged"}
    proc = _chromium("--dump-dom", html.as_uri())
    dom = " ".join(proc.stdout.split())
    assert 'id="configuration">cruise' in dom, proc.stderr[-500:]
    for words in ('id="airspeed-window"', 'id="altimeter-window"', "1.3 V_S1 to V_MO or V_NE",
                  "1.3 V_S0 (flaps extended) to 1.8 V_S1", "14 CFR 23.1323(b)",
                  "14 CFR 23.1325(e)", "need not be less than ±30 feet",
                  "at sea level, with a standard atmosphere", "ASTM F3233",
                  "ΔH at sea level (ft)", "not judged"):
        assert words in dom, words
