"""A column in the wrong unit is named with its likely unit and the factor to SI: the demo's
flight with one column converted (the input file is never modified)."""

import hashlib

import numpy as np
import pytest

from pitotcal.cli import main
from pitotcal.core.errors import FlightDataError
from pitotcal.io import read_flight
from pitotcal.io.flight_csv import write_flight_csv
from pitotcal.maneuvers.plan.planner import plan_maneuver
from pitotcal.core.scenario import T2_PLAN
from pitotcal.studies.demo import DEMO_SIM

PA = {"hPa": 100.0, "kPa": 1000.0, "psi": 6894.757, "inH2O": 249.089, "mmH2O": 9.80665,
      "inHg": 3386.389, "mmHg": 133.3224}
MPS = {"kt": 1852.0 / 3600.0, "km/h": 1.0 / 3.6, "mph": 0.44704}


@pytest.fixture(scope="module")
def demo_columns():
    """The demo flight's columns (T-2 plan, the demo's simulation settings, 240 s)."""
    from pitotcal.maneuvers.fly.simulator import simulate

    flight, _ = simulate(plan_maneuver(**{**T2_PLAN, "duration_s": 240.0}), seed=0, **DEMO_SIM)
    cols = {"time_s": flight.time_s, "qc_pa": flight.qci_pa, "gps_vn_mps": flight.gps_vn_mps,
            "gps_ve_mps": flight.gps_ve_mps, "rho_kgm3": flight.rho_kgm3,
            "gps_vd_mps": flight.gps_vd_mps, "alt_m": flight.alt_m, "ps_pa": flight.ps_pa,
            "oat_k": flight.oat_k}
    return {k: np.asarray(v, dtype=float) for k, v in cols.items()}


def _converted(columns, column, unit):
    cols = dict(columns)
    if column == "gps":
        for c in ("gps_vn_mps", "gps_ve_mps"):
            cols[c] = cols[c] / MPS[unit]
    elif column == "time_s":
        cols["time_s"] = cols["time_s"] * {"min": 1 / 60.0, "ms": 1e3}[unit]
    elif column == "oat_k":
        c = cols["oat_k"] - 273.15
        cols["oat_k"] = c if unit == "degC" else c * 1.8 + 32.0
    else:
        cols[column] = cols[column] / PA[unit]
    return cols


def _write(cols, path):
    header = ",".join(cols)
    np.savetxt(path, np.column_stack(list(cols.values())), delimiter=",", header=header,
               comments="", fmt="%.9g")
    return path


CASES = [
    ("qc_pa", "mmH2O", r"column qc_pa: median .* looks like mmH2O \(x 9.80665 to Pa\)"),
    ("qc_pa", "inH2O", r"column qc_pa: median .* looks like inH2O \(x 249.089 to Pa\)"),
    ("qc_pa", "hPa", r"column qc_pa: median .* looks like hPa \(mbar\) \(x 100 to Pa\)"),
    ("qc_pa", "kPa", r"column qc_pa: median .* looks like kPa \(x 1000 to Pa\)"),
    ("qc_pa", "psi", r"column qc_pa: median .* looks like psi \(x 6894.76 to Pa\)"),
    ("qc_pa", "inHg", r"column qc_pa: median .* looks like inHg \(x 3386.39 to Pa\)"),
    ("ps_pa", "hPa", r"column ps_pa: median .* looks like hPa \(mbar\) \(x 100 to Pa"),
    ("ps_pa", "kPa", r"column ps_pa: median .* looks like kPa \(x 1000 to Pa"),
    ("ps_pa", "psi", r"column ps_pa: median .* looks like psi \(x 6894.76 to Pa"),
    ("ps_pa", "inHg", r"column ps_pa: median .* looks like inHg \(x 3386.39 to Pa"),
    ("ps_pa", "mmHg", r"column ps_pa: median .* looks like mmHg \(x 133.322 to Pa"),
    ("time_s", "min", r"column time_s: median step .* looks like minutes \(50 Hz\); expected "
                      r"seconds \(time_s = value x 60\)"),
    ("time_s", "ms", r"column time_s: median step 20 looks like milliseconds \(50 Hz\)"),
    ("gps", "kt", r"columns gps_vn_mps/gps_ve_mps: median ground speed .* looks like knots "
                  r"\(x 0.5144 to m/s\)"),
    ("gps", "km/h", r"columns gps_vn_mps/gps_ve_mps: .* looks like km/h .*\(x 0.2778 to m/s\)"),
    ("gps", "mph", r"columns gps_vn_mps/gps_ve_mps: .* looks like mph \(x 0.447 to m/s\)"),
    ("oat_k", "degC", r"column oat_k: median .* looks like degrees Celsius; expected kelvin "
                      r"\(K = degC \+ 273.15\)"),
    ("oat_k", "degF", r"column oat_k: median .* looks like degrees Fahrenheit; expected kelvin "
                      r"\(K = \(degF - 32\) / 1.8 \+ 273.15\)"),
]


@pytest.mark.parametrize("column, unit, words", CASES, ids=[f"{c}-{u}" for c, u, _ in CASES])
def test_a_column_in_another_unit_is_named_with_its_unit(demo_columns, tmp_path, column, unit,
                                                          words):
    path = _write(_converted(demo_columns, column, unit), tmp_path / "flight.csv")
    with pytest.raises(FlightDataError, match=words):
        read_flight(path)


@pytest.mark.parametrize("column, unit", [("qc_pa", "mmH2O"), ("ps_pa", "inHg"),
                                          ("time_s", "min")])
def test_the_cli_says_it_in_one_line_and_exits_2(demo_columns, tmp_path, capsys, column, unit):
    path = _write(_converted(demo_columns, column, unit), tmp_path / "flight.csv")
    before = hashlib.sha256(path.read_bytes()).hexdigest()
    code = main(["identify", str(path), "--json", str(tmp_path / "r.json")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    words = {"mmH2O": "looks like mmH2O", "inHg": "looks like inHg", "min": "looks like minutes"}
    assert f"column {column}" in err and words[unit] in err, err
    assert hashlib.sha256(path.read_bytes()).hexdigest() == before
    assert not (tmp_path / "r.json").exists()


def test_minutes_at_10_hz_are_told_by_the_climb(demo_columns, tmp_path):
    """Above 1 ms a step in minutes is a plausible step in seconds; a climb of 1 m/s then
    makes the altitude change 60 m per metre of integrated vertical speed."""
    cols = {k: v[::5].copy() for k, v in demo_columns.items()}          # 10 Hz
    cols["gps_vd_mps"] = np.full(cols["time_s"].size, -1.0)
    cols["alt_m"] = 300.0 + (cols["time_s"] - cols["time_s"][0])
    read_flight(_write(dict(cols), tmp_path / "seconds.csv"))           # in seconds: fine
    cols["time_s"] = cols["time_s"] / 60.0
    with pytest.raises(FlightDataError, match=r"column time_s looks like minutes \(the altitude "
                                              r"changes 60 m per metre"):
        read_flight(_write(cols, tmp_path / "flight.csv"))


def test_static_pressure_without_a_density_column_names_every_unit_that_fits(demo_columns,
                                                                              tmp_path):
    cols = _converted(demo_columns, "ps_pa", "psi")
    del cols["rho_kgm3"], cols["alt_m"]
    with pytest.raises(FlightDataError, match=r"looks like psi \(x 6894.76 to Pa; or .*kPa"):
        read_flight(_write(cols, tmp_path / "flight.csv"))


def test_the_demo_flight_in_si_is_read(demo_columns, tmp_path):
    flight = read_flight(_write(dict(demo_columns), tmp_path / "flight.csv"))
    assert flight.n == demo_columns["time_s"].size and flight.n_dropped == 0
    write_flight_csv(flight, tmp_path / "again.csv")


def test_a_1200_hz_log_in_seconds_is_read(tmp_path):
    """A step of 0.83 ms is a fast log in seconds, not minutes (minutes at 50 Hz step 0.33 ms)."""
    import pitotcal

    flight, _ = pitotcal.simulate(pitotcal.plan_maneuver(), seed=1, rate_hz=1200.0)
    path = pitotcal.write_flight_csv(flight, tmp_path / "fast.csv")
    assert pitotcal.read_flight(path).n == flight.n


@pytest.mark.parametrize("rate_hz", [1.0, 5.0, 10.0, 16.0])
def test_minutes_in_level_flight_without_a_climb_are_told_by_the_acceleration(demo_columns,
                                                                              tmp_path, rate_hz):
    """Level flight, no alt_m or gps_vd_mps, 1-16 Hz: in minutes the step (1-17 ms) is a
    plausible step in seconds, and only the GPS velocity's change rate (a turn at 6-7 g)
    tells; the same flight in seconds is read."""
    every = int(round(50.0 / rate_hz))
    cols = {k: v[::every].copy() for k, v in demo_columns.items()
            if k not in ("alt_m", "gps_vd_mps")}
    assert read_flight(_write(dict(cols), tmp_path / "seconds.csv")).n == cols["time_s"].size
    cols["time_s"] = cols["time_s"] / 60.0
    with pytest.raises(FlightDataError, match=r"column time_s looks like minutes: with it in "
                                              r"seconds the GPS velocity .* changes at "):
        read_flight(_write(cols, tmp_path / "minutes.csv"))
