"""`pitotcal identify LOG` without a window: the windows chosen from the log, in the summary, the
JSON and the report (which re-reads the flight the same way)."""

import json

from wholeflight import OAT_K, calibration, straight, write_log

from pitotcal.cli import main


def test_identify_a_whole_flight_log_says_its_windows(tmp_path, capsys):
    path, spans = write_log(tmp_path, [("ground", straight(20, 3.0, 0.0)),
                                       ("climb", straight(40, 35.0, 25.0)),
                                       ("cal", calibration(200, seed=9)),
                                       ("dive", straight(30, 45.0, -30.0)),
                                       ("ground", straight(20, 3.0, 0.0))])
    out, html = tmp_path / "r.json", tmp_path / "r.html"
    oat_c = f"{OAT_K - 273.15:.4f}"
    assert main(["identify", str(path), "--model", "constant", "--air", "incompressible",
                 "--oat-c", oat_c, "--no-budget", "--json", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    (c0, c1), = spans["cal"]
    assert lines[1].startswith("  window 1: ") and "track turns" in lines[1]
    assert lines[2].startswith("  cut: ") and "climb or dive (flight-path angle > 15 deg)" in lines[2]
    record = json.loads(out.read_text())
    (w,) = record["windows"]
    assert c0 <= w["start_s"] < c0 + 5 and c1 - 5 < w["end_s"] <= c1
    assert record["cut_s"]["climb or dive (flight-path angle > 15 deg)"] > 60
    assert "windows" not in record["reading"]
    # --windows all: the climb and the dive too, and no windows key
    assert main(["identify", str(path), "--model", "constant", "--air", "incompressible",
                 "--oat-c", oat_c, "--no-budget", "--windows", "all", "--json", str(out)]) == 0
    assert "windows" not in json.loads(out.read_text())
    # the report re-reads the flight as identify did: it reproduces, and shows the windows
    main(["identify", str(path), "--model", "constant", "--air", "incompressible",
          "--oat-c", oat_c, "--no-budget", "--json", str(out)])
    capsys.readouterr()
    main(["report", str(out), "--flight", str(path), "-o", str(html)])
    cap = capsys.readouterr()
    text = html.read_text()
    assert "does not reproduce" not in cap.err + text
    assert "Calibration windows" in text and "Cut from the log" in text
