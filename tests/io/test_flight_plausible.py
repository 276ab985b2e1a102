"""Issue 15, the reader: implausible cells (1e200 in a GPS column, 1e160 in qc_pa), the unit
of the time column (ms, µs, Unix time) and of gps_vd_mps (cm/s), UTF-16 files."""

import re

import numpy as np
import pytest
from synthetic import synthetic_flight

from pitotcal.core.errors import FlightDataError
from pitotcal.io import read_flight

N = 500


def columns(n=N, seed=3, **kw):
    f, _ = synthetic_flight(seed=seed, n=n, **kw)
    cols = {"time_s": f.time_s, "qc_pa": f.qci_pa, "gps_vn_mps": f.gps_vn_mps,
            "gps_ve_mps": f.gps_ve_mps, "rho_kgm3": f.rho_kgm3}
    if f.gps_vd_mps is not None:
        cols["gps_vd_mps"] = f.gps_vd_mps
    return cols


def write(path, cols, cells=None):
    names = list(cols)
    body = [[f"{v:.15g}" for v in row] for row in zip(*cols.values())]
    for (r, c), text in (cells or {}).items():
        body[r][names.index(c)] = text
    path.write_text("\n".join([",".join(names)] + [",".join(b) for b in body]) + "\n")
    return path


@pytest.mark.parametrize("column, text", [("gps_vn_mps", "1e200"), ("gps_ve_mps", "-1e200"),
                                          ("qc_pa", "1e160"), ("rho_kgm3", "1e6")])
def test_one_extreme_cell_is_dropped_with_a_warning_naming_it(tmp_path, column, text):
    path = write(tmp_path / "f.csv", columns(), {(41, column): text})
    with pytest.warns(UserWarning, match=rf"dropped 1 of {N} rows .*column {column}, row 42 "
                                         rf"\(line 43\): {re.escape(f'{float(text):g}')} is outside "
                                         "the plausible"):
        flight = read_flight(path)
    assert flight.n == N - 1 and flight.n_dropped == 1
    assert np.all(np.abs(flight.gps_vn_mps) < 200) and flight.qci_pa.max() < 1e4


def test_many_extreme_cells_are_one_error_naming_the_first(tmp_path):
    cells = {(r, "gps_vn_mps"): "1e200" for r in range(100, 120)}
    path = write(tmp_path / "f.csv", columns(), cells)
    with pytest.raises(FlightDataError, match=r"column gps_vn_mps, row 101 \(line 102\): 1e\+200 "
                                              r"is outside the plausible -515 to 515 \(20 of 500"):
        read_flight(path)


def test_identify_with_a_glitch_cell_gives_the_truth_and_the_warning(tmp_path, capsys):
    import json

    from pitotcal.cli import main

    f, truth = synthetic_flight(seed=4, n=3000, turbulence_mps=0.3)
    cols = {"time_s": f.time_s, "qc_pa": f.qci_pa, "gps_vn_mps": f.gps_vn_mps,
            "gps_ve_mps": f.gps_ve_mps, "rho_kgm3": f.rho_kgm3}
    path = write(tmp_path / "f.csv", cols, {(1500, "gps_ve_mps"): "1e200",
                                            (2000, "qc_pa"): "1e160"})
    out = tmp_path / "r.json"
    assert main(["identify", str(path), "--air", "incompressible", "--json", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "row 1501 (line 1502): 1e+200 is outside" in err
    d = json.loads(out.read_text())
    assert d["n_samples"] == 2998 and any("1e+200" in w for w in d["warnings"])
    for name, true in truth["parameters"].items():
        assert abs(d["parameters"][name]["value"] - true) < 3 * d["parameters"][name]["std"]


@pytest.mark.parametrize("scale, offset, match", [
    (1e3, 0.0, (r"median step 20 looks like milliseconds \(50 Hz\); expected seconds "
                r"\(time_s = value / 1000\)")),
    (1e6, 0.0, r"median step 20000 looks like microseconds \(50 Hz\)"),
    (1e3, 1.7e12, r"median step 20 looks like milliseconds \(Unix time\) \(50 Hz\)"),
    (1.0, 0.0, None),
])
def test_time_in_ms_or_us_is_refused_naming_the_unit(tmp_path, scale, offset, match):
    cols = columns()
    cols["time_s"] = cols["time_s"] * scale + offset
    path = write(tmp_path / "f.csv", cols)
    if match is None:
        assert read_flight(path).n == N
        return
    with pytest.raises(FlightDataError, match="column time_s: " + match):
        read_flight(path)


def test_unix_time_in_seconds_is_used_with_a_warning_naming_it(tmp_path):
    cols = columns()
    cols["time_s"] = cols["time_s"] + 1.7e9
    path = write(tmp_path / "f.csv", cols)
    with pytest.warns(UserWarning, match=r"looks like Unix time in seconds \(starts 2023-11-14 "
                                         r"22:13:20 UTC\)"):
        flight = read_flight(path)
    assert flight.n == N and any("Unix time" in w for w in flight.warnings)
    np.testing.assert_allclose(np.diff(flight.time_s), 0.02, atol=1e-6)


def test_vertical_speed_in_cm_per_s_is_refused(tmp_path):
    cols = columns(vertical=True)
    assert read_flight(write(tmp_path / "ok.csv", cols)).gps_vd_mps is not None
    cols["gps_vd_mps"] = cols["gps_vd_mps"] * 100.0
    with pytest.raises(FlightDataError, match=r"column gps_vd_mps looks like cm/s \(median \|vd\|"
                                              r" .* against a median ground speed"):
        read_flight(write(tmp_path / "cm.csv", cols))


def test_vertical_speed_checked_against_the_altitude(tmp_path):
    cols = columns()
    t = cols["time_s"]
    cols["gps_vd_mps"] = np.full(N, -3.0)          # a steady 3 m/s climb
    cols["alt_m"] = 240.0 + 3.0 * t
    assert read_flight(write(tmp_path / "ok.csv", cols)).n == N
    small = {**cols, "gps_vd_mps": cols["gps_vd_mps"] * 100.0}
    with pytest.raises(FlightDataError, match=r"gps_vd_mps looks like cm/s \(the altitude "
                                              r"changes 0.01 m per unit of its integral\)"):
        read_flight(write(tmp_path / "cm.csv", small))
    up = {**cols, "gps_vd_mps": -cols["gps_vd_mps"]}
    with pytest.raises(FlightDataError, match="is not the vertical speed .* positive down"):
        read_flight(write(tmp_path / "up.csv", up))


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be"])
def test_a_utf16_csv_is_named_utf16(tmp_path, encoding):
    text = write(tmp_path / "a.csv", columns(n=50)).read_text()
    path = tmp_path / "w.csv"
    path.write_bytes(text.encode(encoding))
    with pytest.raises(FlightDataError, match="UTF-16 text \\(save it as UTF-8"):
        read_flight(path)


def test_utf16_leg_and_plan_files_are_named_utf16(tmp_path):
    from plans import circle_plan

    from pitotcal.core.errors import PitotcalError
    from pitotcal.io.legs_csv import read_legs
    from pitotcal.io.plan_csv import read_plan, write_plan

    legs = tmp_path / "legs.csv"
    legs.write_bytes("point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg\n"
                     "A,80,3000,10,85,0\n".encode("utf-16"))
    with pytest.raises(FlightDataError, match="UTF-16 text"):
        read_legs(legs)
    plan = write_plan(circle_plan(duration_s=20.0), tmp_path / "plan.csv")
    plan.write_bytes(plan.read_text().encode("utf-16"))
    with pytest.raises(PitotcalError, match="cannot read plan: UTF-16 text"):
        read_plan(plan)


def test_refusal_of_1e200_cells_is_the_only_stderr_line(tmp_path):
    """No numpy overflow line before the refusal: stderr of a real `pitotcal identify` run
    (default warning filters, not pytest's) is exactly the one refusal line."""
    import subprocess
    import sys

    cells = {(r, "gps_vn_mps"): "1e200" for r in range(100, 120)}
    path = write(tmp_path / "f.csv", columns(), cells)
    done = subprocess.run([sys.executable, "-m", "pitotcal", "identify", str(path), "--air",
                           "incompressible"], capture_output=True, text=True, timeout=120,
                          check=False)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1, done.stderr
    assert "column gps_vn_mps, row 101 (line 102): 1e+200 is outside the plausible" in done.stderr
    assert "overflow" not in done.stderr
