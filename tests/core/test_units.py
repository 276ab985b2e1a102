"""pitotcal.core.units: conversions and the standard atmosphere against reference values."""

import numpy as np
import pytest

from pitotcal.core import units


@pytest.mark.parametrize("fn, value, expected", [
    (units.kt_to_mps, 1.0, 1852.0 / 3600.0),
    (units.mps_to_kt, 1852.0 / 3600.0, 1.0),
    (units.ft_to_m, 1000.0, 304.8),
    (units.m_to_ft, 304.8, 1000.0),
    (units.density_kgm3, (101325.0, 288.15), 1.2250),
    (units.isa_temperature_k, 1000.0, 281.65),
    (units.isa_pressure_pa, 0.0, 101325.0),
    (units.isa_pressure_pa, 1000.0, 89874.6),       # ICAO standard atmosphere table
    (units.isa_density_kgm3, 1000.0, 1.11164),
    (units.isa_altitude_m, 89874.6, 1000.0),
    (units.incompressible_qc_pa, 50.0, 1531.25),          # rho0 / 2 * 50^2
    (units.incompressible_cas_mps, 1531.25, 50.0),
    (units.incompressible_cas_mps, -1531.25, -50.0),       # sign kept: a curve continuous through 0
])
def test_conversions(fn, value, expected):
    args = value if isinstance(value, tuple) else (value,)
    assert float(fn(*args)) == pytest.approx(expected, rel=1e-5)


@pytest.mark.parametrize("from_deg, north, east", [
    (0.0, -5.0, 0.0), (90.0, 0.0, -5.0), (180.0, 5.0, 0.0), (270.0, 0.0, 5.0),
])
def test_wind_vector_is_where_the_air_goes(from_deg, north, east):
    wn, we = units.wind_vector_mps(5.0, from_deg)
    assert (float(wn), float(we)) == pytest.approx((north, east), abs=1e-12)
    speed, back = units.wind_polar(wn, we)
    assert float(speed) == pytest.approx(5.0)
    assert float(back) == pytest.approx(from_deg, abs=1e-9)


def test_wind_polar_stays_below_360():
    _, from_deg = units.wind_polar(-5.0, 1e-16)
    assert 0.0 <= from_deg < 360.0
    _, many = units.wind_polar(np.array([-5.0, 5.0]), np.array([0.0, 0.0]))
    np.testing.assert_allclose(many, [0.0, 180.0])


def test_isa_is_one_formula():
    """airdata's checked relations are the units formula itself (the ICAO table's 89874.6 Pa at
    1000 m above), its inverse to rounding; unchecked beyond the troposphere, as the simulator
    may need."""
    from pitotcal.core import airdata
    alt_m = np.linspace(-600.0, 11000.0, 13)
    np.testing.assert_array_equal(airdata.static_pressure_pa(alt_m), units.isa_pressure_pa(alt_m))
    ps = units.isa_pressure_pa(alt_m)
    np.testing.assert_array_equal(airdata.pressure_altitude_m(ps), units.isa_altitude_m(ps))
    np.testing.assert_allclose(units.isa_altitude_m(ps), alt_m, atol=1e-8)
    assert np.isfinite(units.isa_pressure_pa(12000.0))
