"""Flight CSV reader and validator: round trip, every bad-input case, drop-with-warning, speed."""

import hashlib
import warnings

import numpy as np
import pytest
from synthetic import synthetic_flight

from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.io import Flight, read_flight, read_flight_csv, write_flight_csv

N = 500


def columns(n=N, seed=3, **kw):
    """Plain data columns of a synthetic flight (SI), as a dict of float arrays."""
    f, _ = synthetic_flight(seed=seed, n=n, **kw)
    return {"time_s": f.time_s, "qc_pa": f.qci_pa, "gps_vn_mps": f.gps_vn_mps,
            "gps_ve_mps": f.gps_ve_mps, "rho_kgm3": f.rho_kgm3}


def write(path, cols, cells=None, comments=("aircraft: T-2",), extra_lines=()):
    """Write a CSV with `cells` {(row, column): text} replaced (row 0-based data row)."""
    names = list(cols)
    body = [[f"{v:.9g}" for v in row] for row in zip(*cols.values())]
    for (r, c), text in (cells or {}).items():
        body[r][names.index(c)] = text
    lines = [f"# {c}" for c in comments] + [",".join(names)] + [",".join(b) for b in body]
    lines += list(extra_lines)
    path.write_text("\n".join(lines) + "\n")
    return path


def sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


# --- good files ---------------------------------------------------------------------------

def test_round_trip_write_then_read(tmp_path):
    f, _ = synthetic_flight(seed=1, n=2000, vertical=True)
    f = Flight(**{**f.__dict__, "alt_m": np.linspace(240, 250, f.n), "meta": {"aircraft": "T-2"}})
    path = write_flight_csv(f, tmp_path / "f.csv", comments={"pilot": "A. B."})
    g = read_flight(path)
    assert g.n == f.n and g.n_dropped == 0
    for name in ("time_s", "qci_pa", "gps_vn_mps", "gps_ve_mps", "rho_kgm3", "gps_vd_mps", "alt_m"):
        np.testing.assert_allclose(getattr(g, name), getattr(f, name), rtol=1e-8, atol=1e-4)
    assert g.meta == {"aircraft": "T-2", "pilot": "A. B."}
    assert g.source == str(path)


def test_density_from_ps_and_oat_extra_columns_crlf_bom_blank_lines(tmp_path):
    cols = columns()
    rho = cols.pop("rho_kgm3")
    cols["oat_k"] = np.full(N, 280.0)
    cols["ps_pa"] = rho * 287.05287 * 280.0
    cols["mode"] = np.zeros(N)
    text = write(tmp_path / "a.csv", cols).read_text().replace("\n0,", "\n\n0,", 1)
    text = text.replace("mode\n", "mode\n\n")
    path = tmp_path / "b.csv"
    path.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    g = read_flight(path)
    assert g.n == N and g.gps_vd_mps is None and g.alt_m is None
    np.testing.assert_allclose(g.rho_kgm3, rho, rtol=1e-8)


def test_window_and_gaps(tmp_path):
    cols = columns()
    cols["time_s"] = cols["time_s"] + np.where(np.arange(N) >= 250, 30.0, 0.0)   # a 30 s gap
    path = write(tmp_path / "f.csv", cols)
    assert read_flight(path).n == N
    g = read_flight(path, start_s=2.0, end_s=36.0)
    assert g.time_s[0] >= 2.0 and g.time_s[-1] <= 36.0 and g.n == 201


def test_few_bad_rows_are_dropped_with_one_warning(tmp_path):
    cells = {(7, "qc_pa"): "nan", (9, "gps_vn_mps"): "abc", (11, "qc_pa"): "-3"}
    path = write(tmp_path / "f.csv", columns(), cells, extra_lines=["99.9,800,3"])  # truncated
    with pytest.warns(UserWarning) as record:
        g = read_flight(path)
    assert len(record) == 1
    msg = str(record[0].message)
    assert "dropped 4 of 501 rows" in msg and "column qc_pa, row 8 (line 10): NaN" in msg
    assert g.n == N - 3 and g.n_dropped == 4
    assert g.warnings == (msg,)                      # the warning travels with the data
    assert g.window(1.0, 5.0).warnings == (msg,)


def test_bad_rows_outside_the_window_do_not_count(tmp_path):
    cells = {(r, "qc_pa"): "0" for r in range(100)}      # on the ground before the flight
    path = write(tmp_path / "f.csv", columns(), cells)
    with pytest.raises(FlightDataError, match="row 1 .*not positive"):
        read_flight(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert read_flight(path, start_s=2.0).n == N - 100


def test_input_file_unchanged_even_when_rejected(tmp_path):
    path = write(tmp_path / "f.csv", columns(), {(r, "qc_pa"): "x" for r in range(50)})
    before = sha(path)
    with pytest.raises(FlightDataError):
        read_flight(path)
    good = write(tmp_path / "g.csv", columns())
    before_good = sha(good)
    read_flight(good)
    assert sha(path) == before and sha(good) == before_good


# --- bad files: one table ---------------------------------------------------------------

def _many(col, text, start=4, count=10):
    return {(r, col): text for r in range(start, start + count)}


def _scaled(**factors):
    cols = columns()
    for c, k in factors.items():
        cols[c] = cols[c] * k
    return cols


def _without(*names):
    cols = columns()
    for c in names:
        cols.pop(c)
    return cols


def _ps_oat(ps_factor=1.0, oat_shift=0.0):
    cols = columns()
    rho = cols.pop("rho_kgm3")
    cols["ps_pa"] = rho * 287.05287 * 280.0 * ps_factor
    cols["oat_k"] = np.full(N, 280.0 + oat_shift)
    return cols


def _time(edit):
    cols = columns()
    t = cols["time_s"].copy()
    edit(t)
    cols["time_s"] = t
    return cols


def _dup(t):
    t[20] = t[19]


def _back(t):
    t[30] -= 1.0


BAD_CSV = [
    ("missing qc_pa", lambda: _without("qc_pa"), None, r"f\.csv: missing column qc_pa; required"),
    ("misspelled", lambda: {("qc_Pa" if k == "qc_pa" else k): v for k, v in columns().items()},
     None, r"missing column qc_pa \(found 'qc_Pa'\)"),
    ("two missing", lambda: _without("gps_vn_mps", "gps_ve_mps"), None,
     "missing columns gps_vn_mps, gps_ve_mps"),
    ("no density", lambda: _without("rho_kgm3"), None,
     "missing column for density: needs rho_kgm3, or both ps_pa and oat_k"),
    ("half density", lambda: {k: v for k, v in _ps_oat().items() if k != "oat_k"}, None,
     r"both ps_pa and oat_k \(found only ps_pa\)"),
    ("non-numeric", columns, _many("qc_pa", "abc"),
     r"column qc_pa, row 5 \(line 7\): non-numeric value 'abc' \(10 of 500 rows unusable"),
    ("empty cells", columns, _many("gps_ve_mps", ""), r"column gps_ve_mps, row 5 \(line 7\): empty"),
    ("NaN", columns, _many("rho_kgm3", "NaN"), r"column rho_kgm3, row 5 \(line 7\): NaN"),
    ("inf", columns, _many("gps_vn_mps", "-inf"), r"column gps_vn_mps, row 5 \(line 7\): -infinite"),
    ("q_ci <= 0", columns, _many("qc_pa", "-2"), r"column qc_pa, row 5 \(line 7\): q_ci = -2 Pa is"),
    ("whole column", columns, {(r, "qc_pa"): "n/a" for r in range(N)},
     r"column qc_pa: no usable value in any row \(first: row 1 \(line 3\): non-numeric"),
    ("duplicate time", lambda: _time(_dup), None,
     r"column time_s, row 21 \(line 23\): time 0\.38 s duplicates the previous"),
    ("time backwards", lambda: _time(_back), None,
     r"column time_s, row 31 \(line 33\): time -0\.4 s is before the previous row's 0\.58 s"),
    ("q_ci in hPa", lambda: _scaled(qc_pa=0.01), None, "column qc_pa: median .* looks like hPa"),
    ("q_ci in kPa", lambda: _scaled(qc_pa=0.001), None, "column qc_pa: median .* looks like kPa"),
    ("q_ci in psi", lambda: _scaled(qc_pa=1 / 6894.757), None, "looks like psi"),
    ("speeds in knots", lambda: _scaled(gps_vn_mps=1.9438, gps_ve_mps=1.9438), None,
     "gps_vn_mps/gps_ve_mps: median ground speed .* looks like knots"),
    ("hPa and knots", lambda: _scaled(qc_pa=0.01, gps_vn_mps=1.9438, gps_ve_mps=1.9438), None,
     "looks like hPa.*looks like knots"),
    ("speeds nonsense", lambda: _scaled(gps_vn_mps=6, gps_ve_mps=6), None,
     "disagree: median q_ci .* implies .* m/s true airspeed"),
    ("oat in Celsius", lambda: _ps_oat(oat_shift=-273.15), None,
     "column oat_k: median 6.85 looks like degrees Celsius"),
    ("ps in hPa", lambda: _ps_oat(ps_factor=0.01), None, "column ps_pa: median .* looks like hPa"),
    ("ps in kPa", lambda: _ps_oat(ps_factor=0.001), None, "column ps_pa: median .* looks like kPa"),
    ("rho in g/m3", lambda: _scaled(rho_kgm3=1000), None, r"rho_kgm3: .*looks like g/m\^3"),
    ("rho implausible", lambda: _scaled(rho_kgm3=10), None,
     "rho_kgm3: median 11.96 is not an air density"),
    ("not flying", lambda: _scaled(qc_pa=1e-3, gps_vn_mps=0.0316, gps_ve_mps=0.0316), None,
     "the aircraft is not flying"),
]


@pytest.mark.parametrize("case, make, cells, match", BAD_CSV, ids=[c[0] for c in BAD_CSV])
def test_bad_csv_is_rejected_naming_file_column_row(tmp_path, case, make, cells, match):
    path = write(tmp_path / "f.csv", make(), cells)
    with pytest.raises(FlightDataError, match=match) as info:
        read_flight(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))


BAD_TEXT = [
    ("empty", b"", "empty file"),
    ("whitespace", b"\n \n", "empty file"),
    ("ulog", b"ULog\x01\x12\x35\x01\x00\x00\x00", r"PX4 ULog file \(name it \.ulg"),
    ("dataflash", b"\xa3\x95\x80\x80\x00\x00", "ArduPilot DataFlash log"),
    ("binary", bytes(range(256)) * 4, "binary file, not a flight CSV"),
    ("comments only", b"# aircraft: T-2\n# date: today\n", "only comment lines"),
    ("header only", b"# a: b\ntime_s,qc_pa,gps_vn_mps,gps_ve_mps,rho_kgm3\n", "header only"),
    ("no commas", b"hello world\nthis is text\n", r"line 1: not a CSV header \(no commas\)"),
    ("semicolons", b"time_s;qc_pa;gps_vn_mps\n0;1;2\n", "separated by semicolons"),
    ("tabs", b"time_s\tqc_pa\tgps_vn_mps\n0\t1\t2\n", "separated by tabs"),
    ("json", b'{"time_s": [1, 2]}\n', "not a CSV header"),
    ("no header", b"0,800,30,1,1.2\n0.02,801,30,1,1.2\n", r"line 1: no header row"),
    ("duplicate column", b"time_s,qc_pa,qc_pa,gps_vn_mps,gps_ve_mps,rho_kgm3\n0,1,1,1,1,1\n",
     "column qc_pa appears 2 times"),
    ("too few rows", b"time_s,qc_pa,gps_vn_mps,gps_ve_mps,rho_kgm3\n0,800,36,1,1.2\n1,800,36,1,1.2\n",
     "only 2 usable data rows, at least 10"),
]


@pytest.mark.parametrize("case, content, match", BAD_TEXT, ids=[c[0] for c in BAD_TEXT])
def test_not_a_flight_csv(tmp_path, case, content, match):
    path = tmp_path / "f.csv"
    path.write_bytes(content)
    with pytest.raises(FlightDataError, match=match):
        read_flight(path)
    assert path.read_bytes() == content


def test_short_rows_in_bulk_are_rejected(tmp_path):
    path = write(tmp_path / "f.csv", columns(n=20), extra_lines=["9,800"] * 3)
    with pytest.raises(FlightDataError, match=r"row 21 \(line 23\): short row \(2 fields"):
        read_flight(path)


@pytest.mark.parametrize("start, end, error, match", [
    (5.0, 1.0, PitotcalError, "start_s 5 must be before end_s 1"),
    ("abc", None, PitotcalError, "start_s must be a number, got 'abc'"),
    (float("nan"), None, PitotcalError, "start_s nan must be a finite number"),
    (100.0, None, FlightDataError,
     r"f\.csv: column time_s: no rows in the window start_s=100 \(the file spans 0 to 9.98 s\)"),
])
def test_bad_window(tmp_path, start, end, error, match):
    path = write(tmp_path / "f.csv", columns())
    with pytest.raises(error, match=match) as info:
        read_flight(path, start_s=start, end_s=end)
    if error is PitotcalError:          # an argument error names the parameter for the CLI
        assert info.value.param == "start_s"


def test_a_plan_csv_is_named_as_a_plan(tmp_path):
    from plans import circle_plan

    from pitotcal.io import write_plan
    from pitotcal.io.flight_csv import csv_kind

    path = write_plan(circle_plan(duration_s=20.0), tmp_path / "plan.csv")
    with pytest.raises(FlightDataError, match=r"plan\.csv: this is a plan \(the columns of "
                       r"pitotcal plan\), not a flight: fly or simulate it first \(pitotcal "
                       r"simulate PLAN\.csv -o FLIGHT\.csv\)$"):
        read_flight(path)
    flight = write(tmp_path / "f.csv", columns())
    assert [csv_kind(p) for p in (path, flight)] == ["plan", "flight"]
    (tmp_path / "x.csv").write_text("a,b\n1,2\n")
    (tmp_path / "b.csv").write_bytes(b"ULog\x00\x01")
    assert csv_kind(tmp_path / "x.csv") is None and csv_kind(tmp_path / "b.csv") is None


def test_oat_k_is_for_logs_only(tmp_path):
    path = write(tmp_path / "f.csv", columns())
    with pytest.raises(PitotcalError, match=r"^oat_k applies to \.ulg/\.bin/\.log/\.tlog logs "
                       r"only; f\.csv is a flight CSV") as info:
        read_flight(path, oat_k=288.15)
    assert info.value.param == "oat_k"


def test_missing_file_is_an_oserror(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_flight(tmp_path / "nope.csv")


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_logs_dispatch_to_estimation_logs(shared_file):
    logs = pytest.importorskip("pitotcal.io.logs")
    path = shared_file("px4-ulog/sample_log_small.ulg")
    try:
        read_flight(path)
    except FlightDataError as exc:     # 6.5 s on the ground: a clear refusal is right too
        assert str(path.name) in str(exc)
    assert hasattr(logs, "read_log")


def test_reads_a_million_rows_quickly(tmp_path):
    import time
    f, _ = synthetic_flight(seed=2, n=200_000)
    path = write_flight_csv(f, tmp_path / "big.csv")
    t0 = time.perf_counter()
    g = read_flight_csv(path)
    elapsed = time.perf_counter() - t0
    assert g.n == 200_000
    assert elapsed < 3.0, f"{elapsed:.2f} s for 2e5 rows (measured ~0.2 s on an idle machine)"


def test_bad_altitude_cells_keep_the_row(tmp_path):
    """alt_m is informative only: empty/NaN/text altitude is NaN, never a dropped row."""
    cols = columns()
    cols["alt_m"] = np.full(N, 244.0)
    cells = {(r, "alt_m"): ("" if r % 3 == 0 else "nan" if r % 3 == 1 else "n/a")
             for r in range(0, N, 7)}
    cells[(10, "qc_pa")] = "nan"                          # a real bad row is still dropped
    path = write(tmp_path / "f.csv", cols, cells)
    with pytest.warns(UserWarning, match=r"dropped 1 of 500 rows .*column qc_pa, row 11"):
        g = read_flight(path)
    assert g.n == N - 1 and g.n_dropped == 1
    assert np.isnan(g.alt_m).sum() == len(range(0, N, 7))
    empty = write(tmp_path / "e.csv", cols, {(r, "alt_m"): "" for r in range(N)})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = read_flight(empty)
    assert g.n == N and np.isnan(g.alt_m).all()


# --- issue 9: total air temperature and humidity columns ------------------------------------

def test_total_temperature_and_humidity_columns(tmp_path):
    from pitotcal.core.airdata import mach_from_qc
    from pitotcal.core.moist_air import moist_density_kgm3

    cols = columns()
    del cols["rho_kgm3"]
    ps = np.full(N, 85000.0)
    ts = np.full(N, 278.0)
    tat = ts * (1 + 0.2 * mach_from_qc(cols["qc_pa"], ps) ** 2)
    path = write(tmp_path / "tat.csv", {**cols, "ps_pa": ps, "tat_k": tat,
                                        "rh_pct": np.full(N, 80.0)})
    flight = read_flight(path)
    # oat_k is the virtual temperature (humid): the density's and the speed of sound's
    from pitotcal.core.moist_air import virtual_temperature_k
    assert flight.oat_k == pytest.approx(virtual_temperature_k(ts, ps, 80.0), rel=1e-8)
    assert flight.rho_kgm3 == pytest.approx(moist_density_kgm3(ps, ts, 80.0), rel=1e-8)
    assert flight.meta["oat_k_source"].startswith("tat_k") and "oat_k_is" in flight.meta
    # a file with ps_pa and oat_k keeps its density as before, and its channels
    plain = write(tmp_path / "oat.csv", {**cols, "ps_pa": ps, "oat_k": ts})
    flight = read_flight(plain)
    assert flight.rho_kgm3 == pytest.approx(ps / (287.05287 * ts), rel=1e-8)
    assert flight.tat_k is None and flight.oat_k == pytest.approx(ts)
