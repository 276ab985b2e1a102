"""`pitotcal legs FLIGHT.csv`: legs detected or windowed, the time-series fit beside the
leg-level one, --legs-out read back by read_legs, and one-line refusals."""

import json

import numpy as np
import pytest
from pitotcal.maneuvers.fly.legs import LEGS_TRUE_K, simulate_leg_flight

from pitotcal.cli import main
from pitotcal.io.flight_csv import write_flight_csv
from pitotcal.io.legs_csv import read_legs


@pytest.fixture(scope="module")
def flight_csv(tmp_path_factory):
    flight, truth, windows = simulate_leg_flight(seed=7, rate_hz=2.0)
    path = tmp_path_factory.mktemp("legflight") / "flight.csv"
    write_flight_csv(flight, path)
    return path, truth, windows


def test_detected_legs_json_and_legs_out(flight_csv, tmp_path, capsys):
    path, _, windows = flight_csv
    before = path.read_bytes()
    out_json, out_legs, out_png = tmp_path / "r.json", tmp_path / "legs.csv", tmp_path / "f.png"
    status = main(["legs", str(path), "--json", str(out_json), "--legs-out", str(out_legs),
                   "--plot", str(out_png)])
    out = capsys.readouterr().out
    assert status == 0 and path.read_bytes() == before
    assert "Legs from the time series (detected: min_leg_s 30" in out
    assert "Global fit over the legs' time series (identify" in out
    d = json.loads(out_json.read_text())
    assert d["input"] == "flight" and len(d["segments"]) == 16
    assert len({s["groundspeed_sd_kt"] for s in d["segments"]}) == 1      # pooled
    assert len({s["groundspeed_sd_own_kt"] for s in d["segments"]}) == 16
    assert [s["point"] for s in d["segments"]] == [w[2] for w in windows]
    series = d["global_timeseries"]
    for name, true in zip(("k1", "k2"), LEGS_TRUE_K):
        p = series["parameters"][name]
        assert abs(p["value"] - true) < 3 * p["std"]
    assert d["global"]["n_samples"] == 16 and d["global"]["converged"]
    legs = read_legs(out_legs)                     # the engineer's check by hand
    assert legs.n == 16 and legs.point == tuple(s["point"] for s in d["segments"])
    assert np.allclose(legs.groundspeed_mps / 0.514444,
                       [s["groundspeed_kt"] for s in d["segments"]], atol=2e-3)
    assert np.allclose(legs.ias_kt, [p["ias_kt"] for p in d["points"] for _ in range(4)],
                       atol=0.05)
    assert out_png.stat().st_size > 20_000


def test_windows_text_and_csv(flight_csv, tmp_path, capsys):
    path, _, windows = flight_csv
    text = ",".join(f"{t0 + 5:g}-{t1 - 5:g}" for t0, t1, _ in windows)
    out_json = tmp_path / "r.json"
    assert main(["legs", str(path), "--windows", text, "--json", str(out_json)]) == 0
    d = json.loads(out_json.read_text())
    assert d["detection"] == "windows" and len(d["points"]) == 4
    table = tmp_path / "windows.csv"
    table.write_text("start_s,end_s,point\n" + "".join(
        f"{t0 + 5:g},{t1 - 5:g},IAS{p}\n" for t0, t1, p in windows[:8]))
    assert main(["legs", str(path), "--windows", str(table), "--json", str(out_json)]) == 0
    d = json.loads(out_json.read_text())
    assert [p["point"] for p in d["points"]] == ["IAS1", "IAS2"]
    capsys.readouterr()


@pytest.mark.parametrize("extra, match", [
    (["--windows", "100-50"], "--windows: window 100-50: the end must come after the start"),
    (["--min-leg-s", "-5"], "--min-leg-s -5 must be > 0"),
    (["--windows", "missing.csv"], "--windows missing.csv: no such file"),
    (["--min-leg-s", "900"], "no steady segment of 900 s or more"),
])
def test_bad_options_one_line(flight_csv, extra, match, capsys):
    assert main(["legs", str(flight_csv[0]), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert match in err and "\n" not in err


def test_time_series_options_refused_for_a_leg_file(tmp_path, capsys):
    path = tmp_path / "legs.csv"
    path.write_text("point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg\n"
                    "1,120,3000,10,110.0,0\n1,120,3000,10,135.0,90\n1,120,3000,10,140.0,180\n")
    assert main(["legs", str(path), "--legs-out", str(tmp_path / "x.csv")]) == 2
    assert "--legs-out: only for a flight time series" in capsys.readouterr().err


def test_flight_without_static_pressure_exit_2(tmp_path, capsys):
    flight, _, _ = simulate_leg_flight(ias_kt=(80, 120), rate_hz=1.0, seed=1)
    from dataclasses import replace

    path = tmp_path / "f.csv"
    write_flight_csv(replace(flight, ps_pa=None, oat_k=None), path)
    assert main(["legs", str(path)]) == 2
    assert "no ps_pa: the leg methods need" in capsys.readouterr().err


def test_ulog_legs_detected(tmp_path, capsys):
    """A PX4 log goes through read_flight: the legs are found in it (the test log's static
    pressure is a constant 97 kPa, so only the detection is checked here)."""
    from logwriters import write_ulog

    flight, _, windows = simulate_leg_flight(ias_kt=(80, 120), rate_hz=5.0, seed=2)
    path = tmp_path / "legs.ulg"
    write_ulog(path, flight)
    out_json = tmp_path / "r.json"
    assert main(["legs", str(path), "--json", str(out_json)]) == 0
    d = json.loads(out_json.read_text())
    assert [s["point"] for s in d["segments"]] == [w[2] for w in windows]
    capsys.readouterr()


def test_start_end_window_the_flight(flight_csv, tmp_path, capsys):
    """--start-s/--end-s as identify's: only the legs inside the window are found."""
    path, _, windows = flight_csv
    out_json = tmp_path / "r.json"
    assert main(["legs", str(path), "--start-s", f"{windows[4][0] - 2:g}",
                 "--end-s", f"{windows[11][1] + 2:g}", "--json", str(out_json)]) == 0
    d = json.loads(out_json.read_text())
    assert len(d["segments"]) == 8 and len(d["points"]) == 2     # was 16 legs, 4 points
    for seg, (t0, t1, _) in zip(d["segments"], windows[4:12]):
        assert t0 - 2 <= seg["start_s"] < seg["end_s"] <= t1 + 2
    capsys.readouterr()


def test_oat_c_for_a_log(tmp_path, capsys):
    """--oat-c as identify's: the legs of a log get the OAT given (the leg CSV's oat_c)."""
    from logwriters import write_ulog

    flight, _, _ = simulate_leg_flight(ias_kt=(80, 120), rate_hz=5.0, seed=2)
    path = tmp_path / "legs.ulg"
    write_ulog(path, flight)
    out_legs = tmp_path / "legs.csv"
    assert main(["legs", str(path), "--oat-c", "-7.5", "--legs-out", str(out_legs)]) == 0
    assert np.allclose(read_legs(out_legs).oat_k, 273.15 - 7.5, atol=0.06)
    assert main(["legs", str(path), "--oat-c", "290"]) == 2
    assert "--oat-c 290: not an outside air temperature" in capsys.readouterr().err
