"""A CSV export read through a column mapping: units converted to SI, p_t − p_s as q_ci, every
mapping mistake refused in one line naming the key, the real jet exports loaded as they are."""

import json
import warnings

import numpy as np
import pytest
from jets import JMOSS_MAP
from plans import circle_plan

from pitotcal.cli import main
from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import FT_TO_M, KT_TO_MPS, PA_PER_UNIT
from pitotcal.io import read_flight
from pitotcal.io.mapped_csv import read_column_map, read_mapped_csv

MAP = """\
time              = { column = "t_ms",      unit = "ms" }
gps_vn            = { column = "vn_fps",    unit = "ft/s" }
gps_ve            = { column = "ve_kt",     unit = "kt" }
gps_vd            = { column = "vd_fps",    unit = "ft/s" }
total_pressure    = { column = "pt_psi",    unit = "psi" }
static_pressure   = { column = "ps_hpa",    unit = "hPa" }
total_temperature = { column = "tat_c",     unit = "degC" }
gps_height        = { column = "h_ft",      unit = "ft" }
"""


@pytest.fixture(scope="module")
def export(tmp_path_factory):
    """A simulated compressible flight written as a data-acquisition export in mixed units."""
    from pitotcal.maneuvers.fly.options import air_sensors
    from pitotcal.maneuvers.fly.simulator import simulate

    plan = circle_plan(duration_s=240.0, cas_kt=(90.0, 150.0), radius_m=1500.0,
                       altitude_m=2438.4, wind_speed_mps=5.0)
    flight, truth = simulate(plan, seed=0, turbulence_mps=0.0, rate_hz=10.0,
                             air_data="compressible", air_sensors=air_sensors(tat_recovery=1.0))
    folder = tmp_path_factory.mktemp("mapped")
    cols = {"t_ms": flight.time_s * 1e3, "extra": np.arange(flight.n),
            "vn_fps": flight.gps_vn_mps / FT_TO_M, "ve_kt": flight.gps_ve_mps / KT_TO_MPS,
            "vd_fps": flight.gps_vd_mps / FT_TO_M,
            "pt_psi": (flight.qci_pa + flight.ps_pa) / PA_PER_UNIT["psi"],
            "ps_hpa": flight.ps_pa / 100.0, "tat_c": flight.tat_k - 273.15,
            "h_ft": flight.alt_m / FT_TO_M}
    path = folder / "export.csv"
    np.savetxt(path, np.column_stack(list(cols.values())), delimiter=",",
               header=",".join(cols), comments="", fmt="%.12g")
    mapping = folder / "map.toml"
    mapping.write_text(MAP)
    return path, mapping, flight, truth


def test_units_are_converted_to_si(export):
    path, mapping, flight, _ = export
    got = read_flight(path, columns=mapping)
    assert got.n == flight.n and got.meta["alt_source"] == "gps_height"
    for name in ("time_s", "qci_pa", "gps_vn_mps", "gps_ve_mps", "gps_vd_mps", "ps_pa",
                 "tat_k", "alt_m"):
        np.testing.assert_allclose(getattr(got, name), getattr(flight, name), rtol=1e-9,
                                   atol=1e-6, err_msg=name)
    assert got.reading["columns"] == str(mapping)


def test_identify_reads_the_export_through_columns(export, tmp_path, capsys):
    path, mapping, _, truth = export
    out = tmp_path / "r.json"
    assert main(["identify", str(path), "--columns", str(mapping), "--json", str(out)]) == 0
    record = json.loads(out.read_text())
    values = {name: p["value"] for name, p in record["parameters"].items()}
    assert values["wind_speed_mps"] == pytest.approx(truth.parameters["wind_speed_mps"], abs=0.2)
    assert values["k1"] == pytest.approx(truth.parameters["k1"], abs=0.01)


def _map_with(tmp_path, text):
    path = tmp_path / "m.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("change, match", [
    (("static_pressure", "statc_pressure"), r"key statc_pressure: unknown \(did you mean "
                                            r"static_pressure\?\)"),
    (('unit = "psi"', 'unit = "PSI"'), r"key total_pressure: unit 'PSI' is not known; .*psi"),
    (('",    unit = "ft/s" }\ngps_ve', '" }\ngps_ve'), r"key gps_vn: no unit"),
    (("gps_ve            = { column = \"ve_kt\",     unit = \"kt\" }\n", ""),
     r"key gps_ve: missing"),
    (("total_pressure    = { column = \"pt_psi\",    unit = \"psi\" }",
      "impact_pressure = { column = \"pt_psi\", unit = \"psi\" }\n"
      "total_pressure = { column = \"pt_psi\", unit = \"psi\" }"),
     r"key impact_pressure: both total_pressure and impact_pressure"),
    (('column = "h_ft"', 'column = "height"'), r"key gps_height: .*has no column 'height'"),
    (('time              = {', 'time = "t_ms"\nx = {'), r"key time: expected \{ column"),
    (("time ", "time = = "), r"not valid TOML"),
])
def test_mapping_mistakes_name_the_key(export, tmp_path, change, match):
    path, _, _, _ = export
    mapping = _map_with(tmp_path, MAP.replace(*change, 1))
    with pytest.raises(PitotcalError, match=match) as info:
        read_mapped_csv(path, mapping)
    assert info.value.param == "columns" and "\n" not in str(info.value)


def test_the_command_line_names_the_key_in_one_line(export, tmp_path, capsys):
    path, _, _, _ = export
    mapping = _map_with(tmp_path, MAP.replace('unit = "hPa"', 'unit = "bar"'))
    assert main(["identify", str(path), "--columns", str(mapping)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "key static_pressure: unit 'bar' is not known" in err[0]


def test_a_log_with_columns_is_refused(tmp_path):
    with pytest.raises(PitotcalError, match="columns applies to CSV exports only"):
        read_flight(tmp_path / "x.bin", columns=tmp_path / "m.toml")


def test_the_mapping_is_returned_key_by_key(tmp_path):
    got = read_column_map(_map_with(tmp_path, MAP))
    assert got["total_pressure"] == ("pt_psi", "psi") and len(got) == 8


@pytest.mark.parametrize("point, n, above_1", [("CLASS55", 8885, 77), ("CLASS65", 8178, 128)])
def test_real_jet_exports_load_as_they_are(point, n, above_1, shared_file, tmp_path):
    """The USAF TPS exports (ft/s, psi, K, ft) load without a converter, every row through
    Mach 1 (the Rayleigh pitot relation holds above it); `mach_ic_max` still cuts on request."""
    from pitotcal.core.airdata import mach_from_qc
    from pitotcal.io.mapped_csv import read_mapped_csv

    path = shared_file(f"jmoss/{point}.csv")
    mapping = _map_with(tmp_path, JMOSS_MAP)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        flight = read_flight(path, columns=mapping)
    assert flight.n == n and flight.meta["excluded_supersonic"] == 0
    assert not any("above M_ic" in str(w.message) for w in caught)
    assert np.count_nonzero(mach_from_qc(flight.qci_pa, flight.ps_pa) > 1.0) == above_1
    with pytest.warns(UserWarning, match="above M_ic 0.95"):
        cut = read_mapped_csv(path, mapping, mach_ic_max=0.95)
    assert cut.n < n and cut.meta["excluded_supersonic"] == n - cut.n
    assert 5900 < np.median(flight.alt_m) < 6600 and 4e4 < np.median(flight.ps_pa) < 5.5e4


def test_attitude_needs_roll_pitch_and_heading(export, tmp_path):
    from pitotcal.io.mapped_csv import read_attitude

    path, _, _, _ = export
    mapping = _map_with(tmp_path, MAP + 'roll = { column = "vn_fps", unit = "deg" }\n')
    with pytest.raises(PitotcalError, match="key pitch: missing"):
        read_attitude(path, mapping)
    full = _map_with(tmp_path, MAP + 'roll = { column = "vn_fps", unit = "deg" }\n'
                     'pitch = { column = "ve_kt", unit = "rad" }\n'
                     'true_heading = { column = "vd_fps", unit = "deg" }\n')
    got = read_attitude(path, full)
    flight = read_flight(path, columns=full)          # angles are not flight columns
    assert got["roll_rad"] == pytest.approx(np.radians(flight.gps_vn_mps / FT_TO_M), rel=1e-9)
    assert got["time_s"] == pytest.approx(flight.time_s) and "sideslip_rad" not in got


def test_a_bad_row_is_named_as_the_export_numbers_it(export, tmp_path):
    """Rows left out above M_ic 0.95 do not shift the row a message names."""
    path, mapping, _, _ = export
    lines = path.read_text().splitlines()
    header, rows = lines[0], [line.split(",") for line in lines[1:]]
    pt = header.split(",").index("pt_psi")
    for r in rows[:30]:
        r[pt] = "30"                      # p_t 30 psi over p_s ~ 11 psi: M_ic above 1
    for r in rows[40:100]:
        r[pt] = "nan"
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join([header, *(",".join(r) for r in rows)]) + "\n")
    with pytest.raises(PitotcalError, match=r"column qc_pa, row 41 \(line 42\): NaN .*"
                                            r"\[qc_pa is pt_psi - ps_hpa via "):
        read_flight(bad, columns=mapping)


@pytest.mark.parametrize("bad", [0.0, 3.5, float("nan"), "fast", None])
def test_a_bad_mach_ic_max_is_refused_by_name(bad, tmp_path):
    from pitotcal.io.mapped_csv import read_mapped_csv

    with pytest.raises(PitotcalError, match="`mach_ic_max`"):
        read_mapped_csv(tmp_path / "none.csv", tmp_path / "none.toml", mach_ic_max=bad)
