"""Hostile inputs that gave a traceback or a confident answer: one line on stderr naming the
file and key or flag, exit 2, no traceback."""

import json

import pytest

import pitotcal
from pitotcal.cli import main
from pitotcal.io.flight_csv import write_flight_csv


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    """(flight.csv, result.json) of a clean simulated flight (compressible, 0.5 m/s)."""
    root = tmp_path_factory.mktemp("flown")
    flight, _ = pitotcal.simulate(pitotcal.plan_maneuver(), seed=0, turbulence_mps=0.5,
                                  rate_hz=20)
    write_flight_csv(flight, root / "flight.csv")
    (root / "result.json").write_text(json.dumps(pitotcal.identify(flight).to_dict()))
    return root / "flight.csv", root / "result.json"


def _edited(flown, tmp_path, edit):
    doc = json.loads(flown[1].read_text())
    edit(doc)
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(doc))          # allow_nan: NaN as Python's parser reads it
    return path


def _refused(argv, capsys, *words):
    try:
        code = main([str(a) for a in argv])
    except SystemExit as stop:
        code = stop.code
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for word in words:
        assert word in err, err
    return err


def _set(path, value):
    def edit(doc):
        node = doc
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value
    return edit


def test_report_on_deeply_nested_json(tmp_path, capsys):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000)
    _refused(["report", deep, "-o", tmp_path / "r.html"], capsys, "nested too deeply")


def test_report_aircraft_binary_file(flown, tmp_path, capsys):
    _refused(["report", flown[1], "-o", tmp_path / "r.html", "--aircraft", "/bin/ls"],
             capsys, "--aircraft /bin/ls", "not valid TOML")


@pytest.mark.parametrize("case, path, value, key", [
    ("k1_nan", ("parameters", "k1", "value"), float("nan"), "parameters.k1.value"),
    ("noise_std_1e6", ("noise_model", "rel_std"), 1e6, "noise_model.rel_std"),
    ("noise_std_mps_1e6", ("noise_model", "std_mps"), 1e6, "noise_model.std_mps"),
    ("noise_zero", ("noise_model", "rel_std"), 0.0, "noise_model.rel_std"),
    ("noise_nan", ("noise_model", "innovation_rel_std"), float("nan"),
     "noise_model.innovation_rel_std"),
])
def test_monitor_refuses_a_garbage_calibration(case, path, value, key, flown, tmp_path,
                                              capsys):
    cal = _edited(flown, tmp_path, _set(path, value))
    _refused(["monitor", flown[0], "--calibration", cal], capsys, key, "--calibration")


def test_monitor_udp_port_out_of_range(flown, capsys):
    _refused(["monitor", "udp:127.0.0.1:99999", "--calibration", flown[1]], capsys,
             "udp:127.0.0.1:99999", "1-65535")


def test_monitor_idle_s_nan_on_a_file(flown, capsys):
    _refused(["monitor", flown[0], "--calibration", flown[1], "--idle-s", "nan"], capsys,
             "--idle-s nan")


def test_plan_calibration_k1_099(flown, tmp_path, capsys):
    cal = _edited(flown, tmp_path, _set(("parameters", "k1", "value"), 0.99))
    _refused(["plan", "--calibration", cal, "-o", tmp_path / "p.csv"], capsys,
             "parameters.k1.value", "|k1| < 0.5")


def test_plan_target_2sigma_nan(tmp_path, capsys):
    _refused(["plan", "--design", "optimal", "--target-2sigma-kt", "nan", "-o",
              tmp_path / "p.csv"], capsys, "--target-2sigma-kt nan")


def test_monitor_accepts_the_clean_calibration(flown, capsys):
    main(["monitor", str(flown[0]), "--calibration", str(flown[1])])
    assert "alarm" in capsys.readouterr().out
