"""The ALFA reader (pitotcal.io.alfa): the real Carbon-Z flight as a Flight, its density choices,
errors, and where it looks for the data."""

import numpy as np
import pytest

from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.io.alfa import ALFA_DATA_ENV, find_alfa_data, read_alfa_csv, read_alfa_flight


def test_reader_builds_powered_segment(shared_file):
    f = read_alfa_flight(shared_file("alfa-carbonz"))
    t_fail = float(f.meta["failure_time_s"])
    assert t_fail == pytest.approx(116.25, abs=0.1)
    assert f.time_s[-1] < t_fail
    assert f.n > 1000 and np.all(np.diff(f.time_s) > 0)
    # 10 Hz pressure, ~130 Pa (≈ 15 m/s), ground speed ~ 18 m/s, density of a warm 970 hPa day
    assert 50 < np.median(f.qci_pa) < 250
    assert 10 < np.median(np.hypot(f.gps_vn_mps, f.gps_ve_mps)) < 25
    assert 1.05 < np.median(f.rho_kgm3) < 1.2
    assert f.gps_vd_mps is not None


def test_reader_density_choices(shared_file):
    d = shared_file("alfa-carbonz")
    isa = read_alfa_flight(d, oat="isa")
    hot = read_alfa_flight(d, oat=310.0)
    assert np.median(isa.rho_kgm3) > np.median(hot.rho_kgm3)


@pytest.mark.parametrize("kwargs, match", [
    ({"oat": "chip"}, "oat must be 'autopilot', 'isa' or a temperature"),
    ({"oat": 25.0}, "oat must be a temperature in K"),
    ({"margin_s": -1}, "margin_s must be >= 0"),
])
def test_reader_errors(shared_file, kwargs, match):
    with pytest.raises(PitotcalError, match=match):
        read_alfa_flight(shared_file("alfa-carbonz"), **kwargs)


def test_reader_missing_dir(tmp_path):
    with pytest.raises(FlightDataError, match="not found"):
        read_alfa_flight(tmp_path / "nowhere")


def _fake_alfa(folder):
    """A folder that find_alfa_data accepts (it looks for scaled_pressure.csv only)."""
    folder.mkdir(parents=True)
    (folder / "scaled_pressure.csv").write_text("ros_time_s,press_diff,press_abs\n1,1,970\n")
    return folder


def test_find_data_given_folder_or_its_parent(tmp_path):
    data = _fake_alfa(tmp_path / "shared" / "alfa-carbonz")
    assert find_alfa_data(data) == data
    assert find_alfa_data(tmp_path / "shared") == data


def test_find_data_environment_then_current_folder(tmp_path, monkeypatch):
    from_env = _fake_alfa(tmp_path / "env")
    in_cwd = _fake_alfa(tmp_path / "work" / "alfa-carbonz")
    monkeypatch.chdir(tmp_path / "work")
    monkeypatch.setenv(ALFA_DATA_ENV, str(from_env))
    assert find_alfa_data() == from_env
    monkeypatch.delenv(ALFA_DATA_ENV)
    assert find_alfa_data().resolve() == in_cwd.resolve()


def test_find_data_absent_names_every_place(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(ALFA_DATA_ENV, str(tmp_path / "env"))
    with pytest.raises(FlightDataError) as err:
        find_alfa_data()
    message = str(err.value)
    assert "\n" not in message and err.value.param == "data_dir"
    for place in (tmp_path / "env", tmp_path / "env" / "alfa-carbonz",
                  tmp_path / "alfa-carbonz"):
        assert str(place) in message
    assert f"${ALFA_DATA_ENV}" in message and "current folder" in message
    # a folder given explicitly is the only place looked at
    with pytest.raises(FlightDataError, match=r"looked in .*/given, .*/given/alfa-carbonz "
                                              r"\(data_dir\)$"):
        find_alfa_data(tmp_path / "given")


def test_read_csv_time_columns_and_errors(tmp_path):
    (tmp_path / "a.csv").write_text("%time,x\n2000000000,1.5\n3000000000,oops\n")
    table = read_alfa_csv(tmp_path / "a.csv")
    assert table["time_unix_s"].tolist() == [2.0, 3.0]
    assert table["x"][0] == 1.5 and np.isnan(table["x"][1])
    (tmp_path / "b.csv").write_text("t,x\n1,2\n")
    with pytest.raises(FlightDataError, match=r"b.csv: no time column \(ros_time_s or %time\)"):
        read_alfa_csv(tmp_path / "b.csv")
    (tmp_path / "c.csv").write_text("ros_time_s,x\n")
    with pytest.raises(FlightDataError, match="c.csv: no data rows"):
        read_alfa_csv(tmp_path / "c.csv")
