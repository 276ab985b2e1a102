"""The leg CSV reader: columns, alternatives, comments, one-line errors naming file/column/row."""

import numpy as np
import pytest
from pitotcal.maneuvers.fly.legs import simulate_legs

from pitotcal.core import airdata
from pitotcal.core.errors import FlightDataError
from pitotcal.core.units import KT_TO_MPS
from pitotcal.io.legs_csv import read_legs, write_legs

GOOD = """# a comment before the header
point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg,extra
# and one between rows
A,100,3000,10,95.0,0,x
A,100,3000,10,110.0,90,x

A,100,3000,10,105.0,180,x
"""


def _write(tmp_path, text, name="legs.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_reads_the_hand_entered_columns(tmp_path):
    legs = read_legs(_write(tmp_path, GOOD))
    assert legs.point == ("A", "A", "A") and legs.lines == (4, 5, 7)
    np.testing.assert_allclose(legs.groundspeed_mps, np.array([95, 110, 105]) * KT_TO_MPS)
    np.testing.assert_allclose(legs.oat_k, 283.15)
    # q_ci from V_ic by the standard CAS law (100 kt: 1,695.8 Pa by the isentropic formula)
    np.testing.assert_allclose(legs.qci_pa, airdata.qc_from_cas_pa(100 * KT_TO_MPS))
    assert np.all(np.isnan(legs.groundspeed_sd_mps)) and np.all(np.isnan(legs.duration_s))


def test_alternative_columns_qc_and_kelvin(tmp_path):
    qc = float(airdata.qc_from_cas_pa(100 * KT_TO_MPS))
    text = ("point,qc_pa,pressure_alt_ft,oat_k,groundspeed_kt,track_deg,groundspeed_sd_kt,"
            f"duration_s\n1,{qc},3000,283.15,95,0,0.5,60\n1,{qc},3000,283.15,110,90,0.5,60\n")
    legs = read_legs(_write(tmp_path, text))
    np.testing.assert_allclose(legs.ias_kt, 100.0, rtol=1e-9)
    np.testing.assert_allclose(legs.groundspeed_sd_mps, 0.5 * KT_TO_MPS)
    np.testing.assert_allclose(legs.duration_s, 60.0)


@pytest.mark.parametrize("column, offset", [("tat_c", 0.0), ("tat_k", 273.15)])
@pytest.mark.parametrize("recovery", [1.0, 0.8])
def test_indicated_total_temperature_column(tmp_path, column, offset, recovery):
    """A leg file giving the indicated total temperature: T_s = T_t / (1 + r 0.2 M²), M the
    indicated Mach at the leg's pressure altitude (200 KIAS at 10,000 ft: M 0.363, a ram rise
    of 7.1 K at r = 1); the LegData says which column and factor."""
    static_k, alt_ft, ias = 268.0, 10000.0, 200.0
    mach = float(airdata.mach_from_qc(airdata.qc_from_cas_pa(ias * KT_TO_MPS),
                                      airdata.static_pressure_pa(alt_ft * 0.3048)))
    assert mach == pytest.approx(0.363, abs=0.001)
    total = static_k * (1 + recovery * 0.2 * mach ** 2) - 273.15 + offset
    text = (f"point,ias_kt,pressure_alt_ft,{column},groundspeed_kt,track_deg\n"
            + "".join(f"1,{ias},{alt_ft},{total:.4f},{gs},{tk}\n"
                      for gs, tk in ((220, 0), (240, 120), (230, 240))))
    legs = read_legs(_write(tmp_path, text), temp_recovery=recovery)
    np.testing.assert_allclose(legs.oat_k, static_k, atol=1e-3)
    assert legs.temperature == f"{column}, recovery factor {recovery:g}"


def test_round_trip_of_simulated_legs(tmp_path):
    legs, _ = simulate_legs(seed=3)
    write_legs(legs, tmp_path / "sim.csv", comments=["simulated"])
    back = read_legs(tmp_path / "sim.csv")
    assert back.point == legs.point
    np.testing.assert_allclose(back.groundspeed_mps, legs.groundspeed_mps, atol=1e-3)
    np.testing.assert_allclose(back.track_deg, legs.track_deg, atol=0.01)
    np.testing.assert_allclose(back.groundspeed_sd_mps, legs.groundspeed_sd_mps, atol=1e-3)


HEADER = "point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg\n"


@pytest.mark.parametrize("text, match", [
    ("", "no header line"),
    (HEADER, "header only, no legs"),
    ("point,ias_kt,oat_c,groundspeed_kt\n1,2,3,4\n",
     "missing column pressure_alt_ft, track_deg"),
    ("point,pressure_alt_ft,groundspeed_kt,track_deg\n1,2,3,4\n",
     r"missing column ias_kt \(or qc_pa\), oat_c \(or oat_k or tat_c or tat_k\)"),
    (HEADER + "1,100,3000,10,95,0\n1,abc,3000,10,95,90\n",
     r"legs.csv: column ias_kt, row 2 \(line 3\): 'abc' is not a number"),
    (HEADER + "1,100,3000,,95,0\n", r"column oat_c, row 1 \(line 2\): empty"),
    (HEADER + "1,100,3000,290,95,0\n", "looks like kelvin"),
    (HEADER + "1,100,3000,10,95,400\n", r"column track_deg, row 1 \(line 2\): 400 is outside"),
    (HEADER + "1,100,3000,10,nan,0\n", "not a finite number"),
    (HEADER + "1,100,110000,10,95,0\n", r"the ISA, -2,000 ft to 32 km"),
    (HEADER + ",100,3000,10,95,0\n", r"column point, row 1 \(line 2\): empty"),
    (HEADER + "1,100,3000,10,190,0\n1,100,3000,10,200,90\n", "in km/h"),
    (HEADER + "1,100,3000,10,50,0\n1,100,3000,10,55,90\n", "in m/s"),
    ("point,qc_pa,pressure_alt_ft,oat_c,groundspeed_kt,track_deg\n1,17,3000,10,95,0\n",
     "hPa or kPa"),
])
def test_bad_files_one_line_naming_column_and_row(tmp_path, text, match):
    with pytest.raises(FlightDataError, match=match) as err:
        read_legs(_write(tmp_path, text))
    assert "\n" not in str(err.value) and "legs.csv" in str(err.value)


def test_binary_file_refused(tmp_path):
    path = tmp_path / "legs.csv"
    path.write_bytes(b"\x00\xff\xfe\x01" * 20)
    with pytest.raises(FlightDataError, match="binary"):
        read_legs(path)
