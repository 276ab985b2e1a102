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
