"""`pitotcal convert` (INTERFACES §8): log -> flight CSV, exit statuses, one-line errors."""

import json

import numpy as np
import pytest
from logwriters import write_dataflash_bin, write_ulog
from synthetic import synthetic_flight

from pitotcal.cli import main
from pitotcal.io import read_flight_csv


@pytest.fixture(scope="module")
def flight():
    return synthetic_flight(seed=2, n=2000, rate_hz=10.0, model="constant", k=(0.03,))[0]


def test_convert_writes_flight_csv_with_provenance(tmp_path, flight, capsys):
    log = write_dataflash_bin(tmp_path / "f.bin", flight, gps_invalid=(50.0, 60.0))
    out = tmp_path / "f.csv"
    before = log.read_bytes()
    assert main(["convert", str(log), "-o", str(out), "--oat-c", "20"]) == 0
    cap = capsys.readouterr()
    assert "f.bin (ArduPlane V4.1.0 (test), ArduPilot DataFlash binary) -> " in cap.out
    assert cap.err == ""                      # --oat-c given: no sensor-temperature warning
    assert log.read_bytes() == before         # the input is never modified
    got = read_flight_csv(out)
    assert got.n > 1800 and not np.any((got.time_s > 50.0) & (got.time_s < 60.0))
    np.testing.assert_allclose(got.rho_kgm3, 97000.0 / (287.05287 * 293.15), rtol=1e-6)
    meta = got.meta
    assert meta["source"] == "f.bin" and meta["autopilot"] == "ArduPlane V4.1.0 (test)"
    assert meta["temperature_source"] == "oat_k=293.15 K given by the user"
    assert meta["excluded"].startswith("no valid GPS fix: ")
    assert meta["autopilot_ARSPD_RATIO"] == "2" and meta["converted_by"] == "pitotcal convert"


def test_convert_window_and_warning_lines(tmp_path, flight, capsys):
    log = write_ulog(tmp_path / "f.ulg", flight)
    out = tmp_path / "w.csv"
    assert main(["convert", str(log), "-o", str(out), "--start-s", "20", "--end-s", "80"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    # the warning says how far the chip is from ISA, what that does, and both flags that fix it
    assert len(err) == 1
    assert err[0].startswith("warning: f.ulg: no outside air temperature in the log: density "
                             "uses differential_pressure.temperature (airspeed sensor), a sensor "
                             "temperature, not OAT: it reads 9.4 degC, -3.2 K from ISA")
    assert err[0].endswith("give the outside air temperature (--oat-c) or the ground "
                           "temperature at take-off (--oat-ground-c)")
    t = read_flight_csv(out).time_s
    assert t[0] >= 20.0 and t[-1] <= 80.0 and t.size == pytest.approx(600, abs=2)


def _errors(tmp, shared_file):
    """(path, message) of each unusable input, its shared log fetched only when used."""
    def truncated():
        trunc = tmp / "cut.bin"
        trunc.write_bytes(shared_file("ardupilot/arduplane_no_airspeed.bin").read_bytes()[:4000])
        return trunc

    return [
        (lambda: shared_file("ardupilot/arduplane_no_airspeed.bin"),
         "arduplane_no_airspeed.bin: no airspeed data (ARSP) in the log; ARSPD_ENABLE=0"),
        (lambda: shared_file("px4-ulog/sample_log_small.ulg"),
         "sample_log_small.ulg: too little usable airborne data (on the ground throughout?)"),
        (truncated, "cut.bin: no data messages in the log; truncated or corrupt file?"),
        (lambda: tmp / "flight.xyz", "flight.xyz: unknown log extension '.xyz'"),
    ]


@pytest.mark.parametrize("case", range(4))
def test_convert_errors_exit_2_with_one_line(case, tmp_path, shared_file, capsys):
    get_path, message = _errors(tmp_path, shared_file)[case]
    path = get_path()
    assert main(["convert", str(path), "-o", str(tmp_path / "out.csv")]) == 2
    err = [line for line in capsys.readouterr().err.splitlines()
           if not line.startswith("warning: ")]
    assert len(err) == 1 and err[0].startswith(f"pitotcal convert: {message}")
    assert "Traceback" not in err[0] and not (tmp_path / "out.csv").exists()


def test_convert_refuses_to_overwrite_its_input(tmp_path, flight, capsys):
    log = write_dataflash_bin(tmp_path / "f.bin", flight)
    assert main(["convert", str(log), "-o", str(log)]) == 2
    assert "would overwrite the input log" in capsys.readouterr().err


def test_identify_reads_the_sitl_log_directly(shared_file, tmp_path, capsys):
    """INTERFACES §8 done-when: the SITL DataFlash log, calm air, calibrated end to end."""
    out = tmp_path / "r.json"
    log = shared_file("ardupilot/arduplane_sitl.log")
    assert main(["identify", str(log), "--model", "constant", "--json", str(out)]) == 0
    result = json.loads(out.read_text())
    assert result["converged"] and result["parameters"]["wind_speed_mps"]["value"] < 1.0
    # the chip's 34.9 degC is 20 K above ISA: 7 % in density, 1.3 kt in dV at the median IAS
    warning = ("arduplane_sitl.log: no outside air temperature in the log: density uses "
               "BARO.Temp (baro sensor), a sensor temperature, not OAT: it reads 34.9 degC, "
               "+20.1 K from ISA at the flight's altitude; if the air was at ISA, the density is "
               "7.0 % low, which moves dV by 1.33 kt at the median 38 kt IAS and an airspeed "
               "ratio by 7.0 %; give the outside air temperature (`oat_k`) or the ground "
               "temperature at take-off (`oat_ground_k`)")
    cap = capsys.readouterr()
    # the record names the Python argument, the command line its flag
    flags = warning.replace("`oat_k`", "--oat-c").replace("`oat_ground_k`", "--oat-ground-c")
    assert cap.err == f"warning: {flags}\n"
    assert result["warnings"].count(warning) == 1
    # the take-off and landing rolls are cut: the table starts at the slowest flight (19 kt,
    # ARSPD_FBW_MIN = 10 m/s), not at the 11 kt of the ground roll
    assert 19.0 < result["airspeed_correction"][0]["vi_kt"] < 19.5
    # no window given: the steady, airborne flight is chosen from the log (the take-off climb
    # and the landing descent's ends go with the rolls; 17 s of turns beyond 50 deg bank and
    # 12 s of fast airspeed changes); it was 2048 samples, 15.5-220.2 s, 492 cut before
    assert "(1756 samples, 35.4-215.1 s, 784 samples cut)" in cap.out.splitlines()[0]
    assert cap.out.splitlines()[1].startswith("  window 1: 35.4-215.1 s, 1756 samples")
    assert result["windows"][0]["n_samples"] == 1756
    assert result["cut_s"]["steep turn (bank > 50 deg)"] == pytest.approx(16.7, abs=0.1)


def test_identify_on_a_log_takes_the_oat(tmp_path, flight, capsys):
    """--oat-c reaches the log reader (no sensor-temperature warning, density from it)."""
    log = write_dataflash_bin(tmp_path / "f.bin", flight, gps_invalid=(50.0, 60.0))
    out = tmp_path / "r.json"
    # the synthetic truth is q_c = rho V^2 / 2: fitted with that relation
    assert main(["identify", str(log), "--model", "constant", "--oat-c", "20",
                 "--air", "incompressible", "--json", str(out)]) == 0
    cap = capsys.readouterr()
    assert cap.err == "" and "samples cut)" in cap.out.splitlines()[0]
    d = json.loads(out.read_text())
    assert d["converged"] and d["model"] == "constant"
    rho = 97000.0 / (287.05287 * 293.15)         # the writer's static pressure at 20 degC
    k1_true = 1.0 - (1.0 - 0.03) * flight.rho_kgm3[0] / rho   # k1 absorbs the density
    k1 = d["parameters"]["k1"]
    assert abs(k1["value"] - k1_true) < 3 * k1["std"] + 1e-3


@pytest.mark.parametrize("args, match", [
    (["--oat-c", "288"], r"--oat-c 288: not an outside air temperature in degC .*looks like "
     "kelvin"),
    (["--oat-c", "-200"], r"--oat-c -200: not an outside air temperature in degC"),
    (["-o", "nodir/out.csv"], r"-o .*nodir/out\.csv: directory .*nodir does not exist"),
])
def test_convert_option_errors_exit_2_before_reading(tmp_path, flight, capsys, args, match):
    import re

    log = write_dataflash_bin(tmp_path / "f.bin", flight)
    args = [str(tmp_path / a) if a.endswith(".csv") else a for a in args]
    if "-o" not in args:
        args += ["-o", str(tmp_path / "out.csv")]
    assert main(["convert", str(log), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(match, err), err
    assert not (tmp_path / "out.csv").exists()


def test_identify_refuses_oat_c_for_a_csv_and_kelvin(tmp_path, flight, capsys):
    from pitotcal.io import write_flight_csv

    path = write_flight_csv(flight, tmp_path / "f.csv")
    assert main(["identify", str(path), "--oat-c", "15"]) == 2
    assert "--oat-c applies to .ulg/.bin/.log/.tlog logs only; f.csv is a flight CSV" in \
        capsys.readouterr().err
    log = write_dataflash_bin(tmp_path / "f.bin", flight)
    assert main(["identify", str(log), "--oat-c", "290"]) == 2
    assert "looks like kelvin" in capsys.readouterr().err


def test_convert_a_flight_csv_says_there_is_nothing_to_convert(tmp_path, flight, capsys):
    from pitotcal.io import write_flight_csv

    path = write_flight_csv(flight, tmp_path / "FLIGHT.csv")
    assert main(["convert", str(path), "-o", str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err
    assert err == ("pitotcal convert: FLIGHT.csv: already a flight CSV, nothing to convert: "
                   "read_flight and pitotcal identify read it as it is\n")
    assert not (tmp_path / "out.csv").exists()


def test_convert_a_plan_says_fly_or_simulate_it_first(tmp_path, capsys):
    from plans import circle_plan

    from pitotcal.io import write_plan

    path = write_plan(circle_plan(duration_s=20.0), tmp_path / "plan.csv")
    assert main(["convert", str(path), "-o", str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pitotcal convert: plan.csv: this is a plan") and err.count("\n") == 1
    assert "fly or simulate it first" in err


@pytest.mark.parametrize("args, match", [
    (["--start-s", "200", "--end-s", "100"], r"--start-s 200 must be before --end-s 100$"),
    (["--start-s", "1000"], (r"f\.bin: no airspeed samples in the window --start-s 1000; the "
                             r"log's airspeed spans 0\.0-199\.9 s since log start$")),
    (["--end-s", "inf"], r"--end-s inf must be a finite number$"),
])
def test_convert_window_errors_name_the_flags(tmp_path, flight, capsys, args, match):
    import re

    log = write_dataflash_bin(tmp_path / "f.bin", flight)
    assert main(["convert", str(log), "-o", str(tmp_path / "out.csv"), "--oat-c", "15",
                 *args]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and re.search(match, err[0]), err


@pytest.mark.parametrize("writer", [write_dataflash_bin, write_ulog])
def test_convert_help_lists_the_columns_it_writes(tmp_path, flight, capsys, writer):
    """`convert --help` lists the writer's columns of a log's flight: the 9 it writes."""
    log = writer(tmp_path / ("f.bin" if writer is write_dataflash_bin else "f.ulg"), flight)
    out = tmp_path / "f.csv"
    assert main(["convert", str(log), "-o", str(out), "--oat-c", "15"]) == 0
    header = next(line for line in out.read_text().splitlines() if not line.startswith("#"))
    written = header.split(",")
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["convert", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert len(written) == 9
    assert f"flight CSV ({', '.join(written)};" in text
