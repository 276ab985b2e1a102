"""Air data to the edges of the envelope: the ISA to 32 km against ambiance (ICAO 1993) and the
pitot relation above Mach 1 (Rayleigh) against the tests' own normal-shock code
(tests/standard_air.py); the two pitot laws join smoothly at Mach 1; CasADi agrees."""

import casadi as ca
import numpy as np
import pytest
import standard_air as std

from pitotcal.core import airdata as ad
from pitotcal.core import units
from pitotcal.core.measurement import StaticAir, TotalPressureAir, isa_air_of_density
from pitotcal.core.plan import ALTITUDE_RANGE_M
from pitotcal.core.speeds import cas_from_tas_mps, tas_from_cas_mps

KT = units.KT_TO_MPS
ALT_M = np.linspace(-600.0, 32000.0, 301)                 # geopotential, every ~110 m
MACH = np.r_[np.linspace(0.05, 0.99, 40), 1.0, np.linspace(1.01, 3.0, 60)]


def test_isa_to_32_km_against_ambiance():
    atm = std.isa(ALT_M)
    np.testing.assert_allclose(units.isa_temperature_k(ALT_M), atm.temperature, rtol=1e-12)
    # ambiance starts each layer from the ICAO table's base pressure rounded to 6 digits
    # (22,632.0 Pa at 11 km; the layer law gives 22,632.04): pressure and density agree to
    # that rounding (2.0e-6), and to 1e-6 once each layer is started from ambiance's own base
    ps, rho = units.isa_pressure_pa(ALT_M), units.isa_density_kgm3(ALT_M)
    np.testing.assert_allclose(ps, atm.pressure, rtol=2.1e-6)
    np.testing.assert_allclose(rho, atm.density, rtol=2.1e-6)
    for h_b, _, p_b, _ in units.ISA_LAYER_BASES:
        top = h_b + (11000.0 if h_b == 0.0 else 9000.0 if h_b == 11000.0 else 12000.0)
        inside = (ALT_M >= max(h_b, 0.0)) & (ALT_M <= top)
        p_amb_base = float(std.isa(h_b + 1e-9).pressure[0])
        np.testing.assert_allclose(ps[inside] / p_b, atm.pressure[inside] / p_amb_base,
                                   rtol=1e-6)
        assert p_b == pytest.approx(p_amb_base, rel=2.1e-6)
    np.testing.assert_allclose(ad.speed_of_sound_mps(atm.temperature), atm.speed_of_sound,
                               rtol=1e-9)
    # the inverse: through pitotcal's own law to rounding, through ambiance's to 1 cm
    np.testing.assert_allclose(ad.pressure_altitude_m(ps), ALT_M, atol=1e-7)
    # (ambiance's 32 km pressure is below the range's 868.016 Pa by its rounding)
    np.testing.assert_allclose(ad.pressure_altitude_m(atm.pressure[:-1]), ALT_M[:-1], atol=0.02)
    np.testing.assert_allclose(std.pressure_altitude_m(ps), ALT_M, atol=0.02)


def test_isa_table_values_above_the_tropopause():
    # ICAO Doc 7488 (1993): 11 km 216.65 K 22,632 Pa; 20 km 5,474.9 Pa; 32 km 228.65 K 868.02 Pa
    assert float(units.isa_pressure_pa(11000.0)) == pytest.approx(22632.1, abs=0.1)
    assert float(units.isa_pressure_pa(20000.0)) == pytest.approx(5474.89, abs=0.02)
    assert float(units.isa_pressure_pa(32000.0)) == pytest.approx(868.02, abs=0.01)
    assert float(units.isa_temperature_k(32000.0)) == pytest.approx(228.65, abs=1e-9)
    # 39,000 ft (FL390): 19,677 Pa, 216.65 K
    assert float(ad.static_pressure_pa(39000 * units.FT_TO_M)) == pytest.approx(19677, abs=1)
    assert ALTITUDE_RANGE_M[1] == units.ISA_TOP_M == ad.PRESSURE_ALTITUDE_MAX_M


def test_isa_numpy_and_casadi_agree_with_a_smooth_pressure():
    h, p = ca.MX.sym("h"), ca.MX.sym("p")
    fn = ca.Function("isa", [h, p], [units.isa_pressure_pa(h, ca), units.isa_temperature_k(h, ca),
                                     units.isa_altitude_m(p, ca),
                                     ca.jacobian(units.isa_pressure_pa(h, ca), h)])
    ps = units.isa_pressure_pa(ALT_M)
    got = [np.asarray(v).ravel() for v in fn.map(ALT_M.size)(ALT_M[None, :], ps[None, :])]
    np.testing.assert_allclose(got[0], ps, rtol=1e-14)
    np.testing.assert_allclose(got[1], units.isa_temperature_k(ALT_M), rtol=1e-14)
    np.testing.assert_allclose(got[2], ALT_M, atol=1e-8)
    # dp/dH = −ρ g₀ on both sides of each layer base: the pressure is smooth for IPOPT
    np.testing.assert_allclose(got[3], -units.isa_density_kgm3(ALT_M) * units.G0_MPS2,
                               rtol=1e-12)
    rho = units.isa_density_kgm3(ALT_M)
    air = isa_air_of_density(rho, "compressible")
    np.testing.assert_allclose(air.ps, ps, rtol=1e-12)
    np.testing.assert_allclose(air.oat, units.isa_temperature_k(ALT_M), rtol=1e-12)


def test_pitot_relation_against_the_normal_shock():
    ps = 19677.0
    qc = ad.qc_from_mach_pa(MACH, ps)
    np.testing.assert_allclose(qc, std.qc_of_mach(MACH, ps), rtol=1e-12)
    np.testing.assert_allclose(ad.mach_from_qc(qc, ps), MACH, rtol=1e-12)
    # NACA Report 1135 normal-shock table: p_t2/p_1 = 3.413 at M 1.5, 5.640 at M 2
    assert float(ad.pitot_pressure_ratio(2.25)[0]) == pytest.approx(3.4133, abs=5e-5)
    assert float(ad.pitot_pressure_ratio(4.0)[0]) == pytest.approx(5.6404, abs=5e-5)
    # calibrated airspeed above a0 (661.5 kt): the Rayleigh law at p0
    cas = np.array([600.0, 661.48, 700.0, 900.0, 1200.0]) * KT
    np.testing.assert_allclose(ad.qc_from_cas_pa(cas), std.qc_of_cas(cas), rtol=1e-12)
    np.testing.assert_allclose(ad.cas_from_qc_mps(std.qc_of_cas(cas)), cas, rtol=1e-12)
    # true airspeed at 39,000 ft through Mach 1
    alt = 39000 * units.FT_TO_M
    tas = MACH * ad.speed_of_sound_mps(units.isa_temperature_k(alt))
    atm = std.isa(alt)
    cas_std = std.cas_of_qc(std.qc_of_mach(tas / atm.speed_of_sound, atm.pressure))
    np.testing.assert_allclose(cas_from_tas_mps(tas, alt), cas_std, rtol=3e-6)
    np.testing.assert_allclose(tas_from_cas_mps(cas_from_tas_mps(tas, alt), alt), tas,
                               rtol=1e-12)


def test_the_two_laws_join_smoothly_at_mach_1():
    """Value and first derivative (in M and M²; the second in M² too) agree at Mach 1."""
    eps = 1e-7
    below, above = ad.pitot_pressure_ratio(np.array([1.0 - eps, 1.0 + eps]))[0]
    r1, d1, d2 = (float(v) for v in ad.pitot_pressure_ratio(1.0))
    assert r1 == pytest.approx(1.2 ** 3.5, rel=1e-15)
    assert abs(above - below) < 3 * d1 * eps
    for side in (-1.0, 1.0):        # one-sided differences on each law, away from M 1
        x = 1.0 + side * np.array([1e-4, 2e-4])
        r = ad.pitot_pressure_ratio(x)[0]
        slope = side * (r[1] - r[0]) / 1e-4
        assert slope == pytest.approx(d1, rel=1e-3)
        assert float(ad.pitot_pressure_ratio(x[0])[2]) == pytest.approx(d2, rel=2e-3)
    assert d1 == pytest.approx(0.7 * 1.2 ** 2.5, rel=1e-15)     # the isentropic slope
    # and in M: dq_c/dM from both sides, by the independent normal-shock code
    m = np.array([1.0 - 1e-5, 1.0, 1.0 + 1e-5])
    q = std.qc_of_mach(m, 1.0)
    assert (q[1] - q[0]) / 1e-5 == pytest.approx((q[2] - q[1]) / 1e-5, rel=1e-4)


def test_supersonic_relations_numpy_and_casadi_agree():
    x, p, t = (ca.MX.sym(n) for n in "xpt")
    oat = 216.65
    tas_sq = (MACH * ad.speed_of_sound_mps(oat)) ** 2
    ps = np.full(MACH.size, 19677.0)
    qc = ad.qc_from_tas_sq_pa(tas_sq, ps, oat)
    exprs = [ad.qc_from_tas_sq_pa(x, p, t, ca), *ad.qc_from_tas_sq_derivatives(x, p, t, ca),
             ad.qc_from_total_pa(x, p, t, ca), *ad.qc_from_total_derivatives(x, p, t, ca),
             ad.mach_from_qc(x, p, ca), ad.cas_from_qc_mps(x, ca) + 0 * p * t]
    fn = ca.Function("f", [x, p, t], exprs).map(MACH.size)
    got = [np.asarray(v).ravel() for v in fn(tas_sq[None, :], ps[None, :], oat)]
    pt = ps + qc
    want = [qc, *ad.qc_from_tas_sq_derivatives(tas_sq, ps, oat)]
    np.testing.assert_allclose(np.vstack(got[:3]), np.vstack(want), rtol=1e-12)
    got = [np.asarray(v).ravel() for v in fn(tas_sq[None, :], pt[None, :], oat)]
    np.testing.assert_allclose(got[3], qc, rtol=1e-12)
    np.testing.assert_allclose(np.vstack(got[4:6]),
                               np.vstack(ad.qc_from_total_derivatives(tas_sq, pt, oat)), rtol=1e-12)
    got = [np.asarray(v).ravel() for v in fn(qc[None, :], ps[None, :], oat)]
    np.testing.assert_allclose(got[6], MACH, rtol=1e-12)
    np.testing.assert_allclose(got[7], ad.cas_from_qc_mps(qc), rtol=1e-12)
    # the derivatives are the derivatives, through Mach 1 and above
    h = 1e-3 * tas_sq
    tas_sq, ps, pt, h = (v[MACH < 2.9] for v in (tas_sq, ps, pt, h))
    for air in (StaticAir(ps, oat), TotalPressureAir(pt, oat)):
        up, dn = air.qc_pa(tas_sq + h), air.qc_pa(tas_sq - h)
        np.testing.assert_allclose(air.derivatives(tas_sq)[0], (up - dn) / (2 * h), rtol=1e-5)
        np.testing.assert_allclose(air.tas_sq(air.qc_pa(tas_sq)), tas_sq, rtol=1e-12)
