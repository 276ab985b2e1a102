"""Hostile inputs that gave a traceback or a confident answer: one line on stderr naming the
file and key or flag, exit 2, no traceback."""

import json

import pytest
from reportfixtures import setting

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
    cal = _edited(flown, tmp_path, setting(path, value))
    _refused(["monitor", flown[0], "--calibration", cal], capsys, key, "--calibration")


def test_monitor_udp_port_out_of_range(flown, capsys):
    _refused(["monitor", "udp:127.0.0.1:99999", "--calibration", flown[1]], capsys,
             "udp:127.0.0.1:99999", "1-65535")


def test_monitor_idle_s_nan_on_a_file(flown, capsys):
    _refused(["monitor", flown[0], "--calibration", flown[1], "--idle-s", "nan"], capsys,
             "--idle-s nan")


def test_plan_calibration_k1_099(flown, tmp_path, capsys):
    cal = _edited(flown, tmp_path, setting(("parameters", "k1", "value"), 0.99))
    _refused(["plan", "--calibration", cal, "-o", tmp_path / "p.csv"], capsys,
             "parameters.k1.value", "|dp/qc| reaches 0.98")


def test_plan_target_2sigma_nan(tmp_path, capsys):
    _refused(["plan", "--design", "optimal", "--target-2sigma-kt", "nan", "-o",
              tmp_path / "p.csv"], capsys, "--target-2sigma-kt nan")


def test_monitor_accepts_the_clean_calibration(flown, capsys):
    main(["monitor", str(flown[0]), "--calibration", str(flown[1])])
    assert "alarm" in capsys.readouterr().out


def test_legs_all_zero_groundspeed_sd_kt(tmp_path, capsys):
    legs = tmp_path / "legs.csv"
    legs.write_text("point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg,"
                    "groundspeed_sd_kt\n1,100,3000,10,100,0,0\n1,100,3000,10,110,120,0\n"
                    "1,100,3000,10,90,240,0\n")
    _refused(["legs", legs], capsys, "column groundspeed_sd_kt", "row 1", "0 is no accuracy")


def test_legs_smooth_s_1e9_is_capped_by_the_record(flown, capsys):
    import resource

    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    _refused(["legs", flown[0], "--smooth-s", "1e9"], capsys,
             "--smooth-s 1e+09 s is longer than the flight")
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 500_000   # kB


@pytest.mark.parametrize("argv", [
    ["identify", "{flight}", "--json", "-"],
    ["monitor", "{flight}", "--calibration", "{result}", "--json", "-"],
    ["report", "{result}", "-o", "-"],
])
def test_dash_as_an_output_is_refused_not_a_file_named_dash(argv, flown, tmp_path, capsys,
                                                          monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = [a.format(flight=flown[0], result=flown[1]) for a in argv]
    _refused(argv, capsys, " -: an output here is a file, not stdout")
    assert not (tmp_path / "-").exists()


def test_oat_cells_in_celsius_are_named_not_a_mach_error(flown, tmp_path, capsys):
    """2 % of oat_k cells in degC gave "mach 1.00463 is outside the subsonic range" naming
    nothing; 0.5 % are dropped as glitches with a warning."""
    lines = flown[0].read_text().splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("time_s"))
    j = lines[head].split(",").index("oat_k")
    for every, refused in ((50, True), (200, False)):
        rows = [line.split(",") for line in lines[head + 1:]]
        for row in rows[::every]:
            row[j] = f"{float(row[j]) - 273.15:.3f}"
        path = tmp_path / f"oat_c_every_{every}.csv"
        path.write_text("\n".join(lines[:head + 1] + [",".join(r) for r in rows]) + "\n")
        if refused:
            _refused(["identify", path], capsys, "column oat_k", "outside the plausible 150")
        else:
            assert main(["identify", str(path), "--no-budget"]) in (0, None)
            assert "dropped" in capsys.readouterr().err


@pytest.mark.parametrize("flag", ["--idle-s", "--target-2sigma-kt"])
def test_identify_live_options_nan_on_a_file(flag, flown, capsys):
    _refused(["identify", flown[0], flag, "nan", "--no-budget"], capsys, f"{flag} nan")


@pytest.mark.parametrize("connection", ["udp:127.0.0.1:0", "tcp:127.0.0.1:65536",
                                        "udp:localhost"])
def test_identify_live_connection_without_a_valid_port(connection, capsys):
    _refused(["identify", "--live", connection], capsys, connection, "1-65535")
