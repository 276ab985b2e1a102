"""pitotcal.core.airdata: the standard relations against independent implementations and tables.

`ambiance` (ICAO 1993 standard atmosphere) checks the ISA pressure and temperature;
`flightcondition` checks the CAS / TAS / Mach / impact-pressure conversions; published table
values check both; CasADi MX must give the numbers numpy gives.
"""

import warnings

import casadi as ca
import numpy as np
import pytest
from ambiance import Atmosphere

with warnings.catch_warnings():                   # pint's deprecation, raised at import
    warnings.simplefilter("ignore", DeprecationWarning)
    from flightcondition import FlightCondition, unit

from pitotcal.core import airdata as ad
from pitotcal.core import units
from pitotcal.core.errors import PitotcalError

KT = units.KT_TO_MPS
FT = units.FT_TO_M

# A 0-10,000 ft by 50-300 KCAS grid, flattened.
ALT_FT, CAS_KT = (a.ravel() for a in np.meshgrid(np.linspace(0.0, 10000.0, 6),
                                                 np.linspace(50.0, 300.0, 11)))


def test_constants():
    assert ad.GAMMA == 1.4 and ad.P0_PA == 101325.0 and ad.T0_K == 288.15
    assert ad.A0_MPS == pytest.approx(340.294, abs=5e-4)
    assert ad.A0_MPS / KT == pytest.approx(661.48, abs=5e-3)     # NASA RP-1046
    assert ad.RHO0_KGM3 is units.RHO0_KGM3


def test_isa_against_ambiance():
    alt_m = np.linspace(-600.0, 11000.0, 30)                      # geopotential
    atm = Atmosphere(Atmosphere.geop2geom_height(alt_m))
    ps = ad.static_pressure_pa(alt_m)
    # rtol 1e-6: ambiance starts a layer at -5 km geopotential with a rounded base pressure
    np.testing.assert_allclose(ps, atm.pressure, rtol=1e-6)
    np.testing.assert_allclose(units.isa_temperature_k(alt_m), atm.temperature, rtol=1e-9)
    np.testing.assert_allclose(ad.pressure_altitude_m(atm.pressure), alt_m, atol=0.01)
    np.testing.assert_allclose(ad.pressure_altitude_m(ps), alt_m, atol=1e-8)
    np.testing.assert_allclose(ad.speed_of_sound_mps(atm.temperature), atm.speed_of_sound,
                               rtol=1e-9)


def test_conversions_against_flightcondition():
    fc = FlightCondition(h=ALT_FT * unit("ft"), CAS=CAS_KT * unit("knots"))
    ps, oat = fc.p.to("Pa").magnitude, fc.T.to("K").magnitude
    tas = fc.TAS.to("m/s").magnitude
    qc = fc.q_c.to("Pa").magnitude
    np.testing.assert_allclose(ad.qc_from_tas_pa(tas, ps, oat), qc, rtol=1e-6)
    np.testing.assert_allclose(ad.cas_from_qc_mps(qc) / KT, CAS_KT, rtol=1e-6)
    np.testing.assert_allclose(ad.qc_from_cas_pa(CAS_KT * KT), qc, rtol=1e-6)
    np.testing.assert_allclose(ad.mach_from_qc(qc, ps), fc.M.magnitude, rtol=1e-6)
    np.testing.assert_allclose(ad.mach_from_tas(tas, oat), fc.M.magnitude, rtol=1e-6)


@pytest.mark.parametrize("cas_kt, inh2o", [(50.0, 1.63), (70.0, 3.20), (90.0, 5.31)])
def test_impact_pressure_table(cas_kt, inh2o):
    # Horton's airspeed-indicator vs water-manometer table (inches of water at 20 °C,
    # p0 = 407.513 inH2O, from NASA RP-1046 tables A19/A27), given to 0.01 in.
    pa_per_inh2o = 101325.0 / 407.513
    assert ad.qc_from_cas_pa(cas_kt * KT) / pa_per_inh2o == pytest.approx(inh2o, abs=0.005)


@pytest.mark.parametrize("mach, p_over_pt", [(0.3, 0.93947), (0.5, 0.84302), (0.8, 0.65602)])
def test_isentropic_table(mach, p_over_pt):
    # NACA Report 1135, isentropic flow table (γ = 1.4): p/p_t at M
    ps = 69681.7                                                  # 10,000 ft pressure altitude
    qc = ad.qc_from_mach_pa(mach, ps)
    assert ps / (ps + qc) == pytest.approx(p_over_pt, abs=1e-5)
    assert ad.mach_from_qc(qc, ps) == pytest.approx(mach, rel=1e-12)


def test_mach_half_at_10000_ft():
    # ICAO table: 10,000 ft: p = 69,681.7 Pa, T = 268.338 K, a = 638.3 kt
    h = 10000.0 * FT
    assert ad.static_pressure_pa(h) == pytest.approx(69681.7, abs=0.5)
    oat = units.isa_temperature_k(h)
    assert ad.speed_of_sound_mps(oat) / KT == pytest.approx(638.3, abs=0.05)
    tas = 0.5 * ad.speed_of_sound_mps(oat)
    qc = ad.qc_from_tas_pa(tas, ad.static_pressure_pa(h), oat)
    assert ad.mach_from_qc(qc, ad.static_pressure_pa(h)) == pytest.approx(0.5, rel=1e-12)
    h_geometric = Atmosphere.geop2geom_height(h)                 # flightcondition's h
    fc = FlightCondition(h=h_geometric * unit("m"), M=0.5)
    assert ad.cas_from_qc_mps(qc) / KT == pytest.approx(fc.CAS.to("knots").magnitude, rel=1e-6)
    assert ad.cas_from_qc_mps(qc) / KT == pytest.approx(276.83, abs=0.005)


@pytest.mark.parametrize("ps_pa, alt_ft", [(50000.0, 18289.0), (70000.0, 9882.0)])
def test_pressure_altitude_table(ps_pa, alt_ft):
    # NOAA/NWS pressure-altitude values: 500 hPa = 18,289 ft, 700 hPa = 9,882 ft
    assert ad.pressure_altitude_m(ps_pa) / FT == pytest.approx(alt_ft, abs=1.0)


def test_altimeter_correction():
    h_ic = np.array([0.0, 5000.0, 10000.0]) * FT
    dp = np.array([50.0, -100.0, 200.0])
    dh = ad.altimeter_correction_m(dp, h_ic)
    rho = units.isa_density_kgm3(h_ic)
    # first order: +Δp/(ρ g0); the exact value differs by a few parts in 10⁴ for these Δp
    np.testing.assert_allclose(dh, dp / (rho * units.G0_MPS2), rtol=2e-3)
    assert dh[0] == pytest.approx(4.163, abs=1e-3)                # 50 Pa at sea level
    np.testing.assert_allclose(ad.altimeter_correction_m(0.0, h_ic), 0.0, atol=1e-9)


def test_numpy_and_casadi_agree():
    tas = CAS_KT * KT * 1.1
    ps = ad.static_pressure_pa(ALT_FT * FT)
    oat = units.isa_temperature_k(ALT_FT * FT)
    qc = ad.qc_from_tas_pa(tas, ps, oat)
    x, y, z = (ca.MX.sym(n) for n in "xyz")
    cases = [
        (ad.qc_from_tas_pa(x, y, z, ca), (tas, ps, oat)),
        (ad.qc_from_tas_sq_pa(x, y, z, ca), (tas ** 2, ps, oat)),
        (ad.mach_from_tas(x, z, ca) + 0 * y, (tas, ps, oat)),
        (ad.qc_from_mach_pa(x, y, ca) + 0 * z, (tas / 340.0, ps, oat)),
        (ad.mach_from_qc(x, y, ca) + 0 * z, (qc, ps, oat)),
        (ad.cas_from_qc_mps(x, ca) + 0 * y * z, (qc, ps, oat)),
        (ad.cas_from_qc_mps(x, ca) + 0 * y * z, (-qc, ps, oat)),
        (ad.qc_from_cas_pa(x, ca) + 0 * y * z, (tas, ps, oat)),
        (ad.pressure_altitude_m(y, ca) + 0 * x * z, (tas, ps, oat)),
        (ad.static_pressure_pa(x, ca) + 0 * y * z, (ALT_FT * FT, ps, oat)),
        (ad.altimeter_correction_m(x, y, ca) + 0 * z, (qc / 100, ALT_FT * FT, oat)),
    ]
    numpy_fns = [
        lambda a, b, c: ad.qc_from_tas_pa(a, b, c),
        lambda a, b, c: ad.qc_from_tas_sq_pa(a, b, c),
        lambda a, b, c: ad.mach_from_tas(a, c),
        lambda a, b, c: ad.qc_from_mach_pa(a, b),
        lambda a, b, c: ad.mach_from_qc(a, b),
        lambda a, b, c: ad.cas_from_qc_mps(a),
        lambda a, b, c: ad.cas_from_qc_mps(a),
        lambda a, b, c: ad.qc_from_cas_pa(a),
        lambda a, b, c: ad.pressure_altitude_m(b),
        lambda a, b, c: ad.static_pressure_pa(a),
        lambda a, b, c: ad.altimeter_correction_m(a, b),
    ]
    for (expr, args), fn in zip(cases, numpy_fns):
        f = ca.Function("f", [x, y, z], [expr])
        got = np.asarray(f.map(len(args[0]))(*(a[None, :] for a in args))).ravel()
        np.testing.assert_allclose(got, fn(*args), rtol=1e-12, atol=1e-9)
    assert np.all(ad.cas_from_qc_mps(-qc) == -ad.cas_from_qc_mps(qc))
    # numpy also takes lists and plain numbers
    np.testing.assert_array_equal(ad.qc_from_tas_pa(list(tas[:3]), list(ps[:3]), list(oat[:3])),
                                  qc[:3])
    assert ad.pressure_altitude_m(101325) == 0.0 and ad.mach_from_qc([0.0], [1e5]) == [0.0]


@pytest.mark.parametrize("call, match", [
    # the ranges grew (ISA to 32 km, Mach to 3 with the Rayleigh pitot law): the refusals
    # moved to just outside them
    (lambda: ad.pressure_altitude_m(800.0), r"ps_pa 800 is outside the ISA \(-2,000 ft to 32"),
    (lambda: ad.pressure_altitude_m(np.array([9e4, 1.1e5])), r"ps_pa 110000 is outside"),
    (lambda: ad.static_pressure_pa(33000.0), r"pressure_altitude_m 33000 is outside"),
    (lambda: ad.static_pressure_pa(-1000.0), r"pressure_altitude_m -1000 is outside"),
    (lambda: ad.qc_from_mach_pa(3.2, 1e5), r"mach 3.2 is outside the Mach range .* \[0, 3\]"),
    (lambda: ad.qc_from_tas_pa(1100.0, 1e5, 288.15), r"mach 3.23\d* is outside the Mach"),
    (lambda: ad.cas_from_qc_mps(2e6), r"qc_pa 2e\+06 is outside the Mach range"),
    (lambda: ad.mach_from_qc(2e6, 1e5), r"qc_pa / ps_pa 20 is outside the Mach range"),
    (lambda: ad.pressure_altitude_m(np.nan), r"ps_pa nan is outside"),
])
def test_validity_range_refused(call, match):
    with pytest.raises(PitotcalError, match=match):
        call()


def incompressible_bias_kt(cas_kt, alt_ft):
    """ΔV today's convention reports for a perfect pitot-static system, kt.

    The estimator predicts q_c = ½ρV_t² (the paper's eq. 2), so its V_c = sqrt(2 q/ρ₀) is the
    equivalent airspeed; a perfect indicator reads the isentropic q_c, which it turns into
    V_i = sqrt(2 q_c/ρ₀). ΔV = V_e − V_i, where the standard relations give ΔV = 0.
    """
    h = np.asarray(alt_ft) * FT
    ps, oat = ad.static_pressure_pa(h), units.isa_temperature_k(h)
    qc = ad.qc_from_cas_pa(np.asarray(cas_kt) * KT)
    tas = ad.mach_from_qc(qc, ps) * ad.speed_of_sound_mps(oat)
    eas = tas * np.sqrt(units.density_kgm3(ps, oat) / units.RHO0_KGM3)
    return (eas - units.incompressible_cas_mps(qc)) / KT, tas / KT


def test_incompressible_bias_of_a_perfect_system():
    # The README's table ("Air data: what pitotcal assumes today").
    dv, tas_kt = incompressible_bias_kt(CAS_KT, ALT_FT)
    mach = tas_kt * KT / ad.speed_of_sound_mps(units.isa_temperature_k(ALT_FT * FT))
    eas_kt = tas_kt * np.sqrt(units.isa_density_kgm3(ALT_FT * FT) / units.RHO0_KGM3)
    np.testing.assert_allclose(dv, -eas_kt * mach ** 2 / 8, rtol=0.02)   # ≈ −V M²/8
    table = {(70, 0): -0.098, (100, 0): -0.286, (150, 0): -0.966, (100, 10000): -0.414,
             (130, 8000): -0.842, (200, 0): -2.293, (260, 10000): -7.181, (300, 10000): -10.978}
    for (cas, alt), expected in table.items():
        assert incompressible_bias_kt(cas, alt)[0] == pytest.approx(expected, abs=0.006)
    # a UAV at 20 m/s at sea level: −0.017 kt, negligible
    assert incompressible_bias_kt(20.0 / KT, 0.0)[0] == pytest.approx(-0.0168, abs=1e-4)


def test_qc_from_total_pressure_is_the_isentropic_relation():
    """q_c from V_t and the total pressure p_T = p_s + q_c (the calibration's prediction)
    equals q_c from V_t and p_s; its derivatives match central differences; CasADi agrees."""
    tas = np.array([30.0, 100.0, 200.0])
    ps, oat = np.array([101325.0, 75000.0, 50000.0]), np.array([288.15, 268.0, 250.0])
    qc = ad.qc_from_tas_pa(tas, ps, oat)
    np.testing.assert_allclose(ad.qc_from_total_pa(tas ** 2, ps + qc, oat), qc, rtol=1e-12)
    d1, d2 = ad.qc_from_total_derivatives(tas ** 2, ps + qc, oat)
    h = 1.0
    up, dn = (ad.qc_from_total_pa(tas ** 2 + s, ps + qc, oat) for s in (h, -h))
    np.testing.assert_allclose(d1, (up - dn) / (2 * h), rtol=1e-7)
    up, dn = (ad.qc_from_total_derivatives(tas ** 2 + s, ps + qc, oat)[0] for s in (h, -h))
    np.testing.assert_allclose(d2, (up - dn) / (2 * h), rtol=1e-6)
    s1, s2 = ad.qc_from_tas_sq_derivatives(tas ** 2, ps, oat)      # at fixed p_s instead
    up, dn = (ad.qc_from_tas_sq_pa(tas ** 2 + s, ps, oat) for s in (h, -h))
    np.testing.assert_allclose(s1, (up - dn) / (2 * h), rtol=1e-7)
    up, dn = (ad.qc_from_tas_sq_derivatives(tas ** 2 + s, ps, oat)[0] for s in (h, -h))
    np.testing.assert_allclose(s2, (up - dn) / (2 * h), rtol=1e-6)
    # the low-speed limit is the paper's eq. 2 with rho = p_T / (R T_s), less 0.9 M^2
    mach = ad.mach_from_tas(tas[0], oat[0])
    rho_t = (ps[0] + qc[0]) / (units.R_AIR_JKGK * oat[0])
    assert d1[0] == pytest.approx(0.5 * rho_t * (1 - 0.9 * mach ** 2), rel=1e-4)
    x, p, t = ca.SX.sym("x"), ca.SX.sym("p"), ca.SX.sym("t")
    fn = ca.Function("q", [x, p, t], [ad.qc_from_total_pa(x, p, t, ca),
                                      *ad.qc_from_total_derivatives(x, p, t, ca)])
    for i in range(tas.size):
        got = [float(v) for v in fn(tas[i] ** 2, ps[i] + qc[i], oat[i])]
        np.testing.assert_allclose(got, [qc[i], d1[i], d2[i]], rtol=1e-12)
