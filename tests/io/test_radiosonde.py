"""The radiosonde text format: the Edwards sounding of the jet test points read in SI, and a file
that is not a sounding refused with its name."""

import numpy as np
import pytest

from pitotcal.core.errors import FlightDataError
from pitotcal.core.units import FT_TO_M, KT_TO_MPS
from pitotcal.io.radiosonde import read_sounding

SOUNDING = """\
EDWARDS AFB, CA
2132Z  12 SEP 17

  ALT  DIR   SPD  SHR  TEMP  DPT   PRESS   RH
GEOMFT DEG   KTS /SEC DEG C DEG C   MBS   PCT

  1000 270  10.0 .000  20.0  11.2  900.00  24
  2000  90  20.0 .151  10.0  10.8  800.00  24
TERMINATION       25794 GEOPFT   7862 GEOPM  383.0 MBS
MANDATORY LEVELS
  3000 999 99.9 1.0 1.0 100.0
"""


def test_a_small_sounding_in_si(tmp_path):
    path = tmp_path / "s.txt"
    path.write_text(SOUNDING)
    s = read_sounding(path)
    np.testing.assert_allclose(s.alt_m, [1000 * FT_TO_M, 2000 * FT_TO_M])
    # from 270 deg: the air moves east; from 90 deg: west
    np.testing.assert_allclose(s.wind_e_mps, [10 * KT_TO_MPS, -20 * KT_TO_MPS], atol=1e-12)
    np.testing.assert_allclose(s.wind_n_mps, [0.0, 0.0], atol=1e-12)
    at = s.at(1500 * FT_TO_M)
    assert at["temp_k"] == pytest.approx(288.15)
    assert at["ps_pa"] == pytest.approx(np.sqrt(900e2 * 800e2))     # log-linear
    with pytest.raises(FlightDataError, match="outside the sounding"):
        s.at(3000 * FT_TO_M)


def test_the_wind_spread_within_a_layer(tmp_path):
    """At 1500 ft the wind is 5 kt from 90°; the levels 500 ft away blow 10 kt east and 20 kt
    west: 15 kt from it at most; none within 100 ft: 0."""
    path = tmp_path / "s.txt"
    path.write_text(SOUNDING)
    s = read_sounding(path)
    spread = s.wind_spread_mps(1500 * FT_TO_M, 500 * FT_TO_M) / KT_TO_MPS
    assert spread == pytest.approx(15.0)
    assert s.wind_spread_mps(1500 * FT_TO_M, 100 * FT_TO_M) == 0.0


def test_not_a_sounding(tmp_path):
    path = tmp_path / "x.txt"
    path.write_text("time_s,qc_pa\n1,2\n")
    with pytest.raises(FlightDataError, match=r"x.txt: no sounding header"):
        read_sounding(path)


def test_the_edwards_sounding(shared_file):
    s = read_sounding(shared_file("jmoss/WB.txt"))
    assert s.alt_m.size == 236 and "EDWARDS AFB" in s.title
    assert s.alt_m[0] == pytest.approx(2372 * FT_TO_M) and s.ps_pa[0] == pytest.approx(92840.0)
    at = s.at(19500 * FT_TO_M)          # CLASS55's test altitude
    speed_kt = np.hypot(at["wind_n_mps"], at["wind_e_mps"]) / KT_TO_MPS
    assert 24 < speed_kt < 30 and 260 < at["temp_k"] < 266 and 490e2 < at["ps_pa"] < 500e2
