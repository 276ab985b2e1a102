"""pitotcal.core.measurement: the same numbers on numpy arrays and on CasADi MX; the air-data
types against an independent library; every user of the measurement model predicting the same
q_ci for the same state."""

import warnings

import casadi as ca
import numpy as np
import pytest

from pitotcal.core import airdata as ad
from pitotcal.core import units
from pitotcal.core.measurement import (
    AIR_DATA_MODES,
    DEFAULT_AIR_DATA,
    IncompressibleAir,
    StaticAir,
    TotalPressureAir,
    flight_air,
    impact_pressure_pa,
    isa_air,
    isa_air_of_density,
    predict_qci_pa,
    tas_squared,
)
from pitotcal.core.models import get_model


def test_hand_values():
    # 30 m/s north over the ground into a 5 m/s wind blowing north: 25 m/s through the air
    assert tas_squared(30.0, 0.0, 5.0, 0.0) == 625.0
    assert tas_squared(30.0, 0.0, 5.0, 0.0, 4.0 ** 2) == 641.0
    assert impact_pressure_pa(1.2, 625.0) == pytest.approx(375.0)


@pytest.mark.parametrize("has_vd", [False, True])
def test_numpy_and_casadi_agree(has_vd):
    rng = np.random.default_rng(0)
    n = 20
    vn, ve, rho = rng.uniform(-40, 40, n), rng.uniform(-40, 40, n), rng.uniform(1.0, 1.3, n)
    vd_sq = rng.uniform(0, 9, n) if has_vd else 0.0
    wind_n, wind_e = 3.0, -4.0
    want_v2 = tas_squared(vn, ve, wind_n, wind_e, vd_sq)
    want_qc = impact_pressure_pa(rho, want_v2)

    s_vn, s_ve, s_rho, s_vd = (ca.MX.sym(name, n) for name in ("vn", "ve", "rho", "vd_sq"))
    s_wind = ca.MX.sym("wind", 2)
    v2 = tas_squared(s_vn, s_ve, s_wind[0], s_wind[1], s_vd if has_vd else 0.0)
    fn = ca.Function("m", [s_vn, s_ve, s_wind, s_rho, s_vd], [v2, impact_pressure_pa(s_rho, v2)])
    got_v2, got_qc = fn(vn, ve, [wind_n, wind_e], rho, vd_sq if has_vd else np.zeros(n))
    np.testing.assert_allclose(np.asarray(got_v2).ravel(), want_v2, rtol=1e-15)
    np.testing.assert_allclose(np.asarray(got_qc).ravel(), want_qc, rtol=1e-15)


def _airs():
    """One of each air-data type at 0-3 km (ISA), for 20-150 m/s."""
    alt = np.linspace(0.0, 3000.0, 7)
    ps, oat = units.isa_pressure_pa(alt), units.isa_temperature_k(alt)
    return (IncompressibleAir(units.isa_density_kgm3(alt)), StaticAir(ps, oat),
            TotalPressureAir(ps + 4000.0, oat))


@pytest.mark.parametrize("kind", [0, 1, 2])
def test_inverse_and_derivatives_round_trip(kind):
    air = _airs()[kind]
    v2 = np.linspace(20.0, 150.0, 7) ** 2
    qc = air.qc_pa(v2)
    np.testing.assert_allclose(air.tas_sq(qc), v2, rtol=1e-12)
    h = 1e-4 * v2
    d1, d2 = air.derivatives(v2)
    np.testing.assert_allclose(d1, (air.qc_pa(v2 + h) - air.qc_pa(v2 - h)) / (2 * h), rtol=1e-7)
    num2 = (air.derivatives(v2 + h)[0] - air.derivatives(v2 - h)[0]) / (2 * h)
    np.testing.assert_allclose(d2, num2, rtol=1e-6, atol=1e-12)
    # CasADi MX: the same lines, the same numbers
    syms = [ca.MX.sym(f"c{i}", 7) for i in range(len(air))]
    s_v2 = ca.MX.sym("v2", 7)
    sym_air = type(air)(*syms)
    fn = ca.Function("a", [*syms, s_v2], [sym_air.qc_pa(s_v2), sym_air.derivatives(s_v2)[0],
                                          sym_air.tas_sq(sym_air.qc_pa(s_v2))])
    got = fn(*air, v2)
    for g, w in zip(got, (qc, d1, v2)):
        np.testing.assert_allclose(np.asarray(g).ravel(), w, rtol=1e-12)


def test_total_pressure_air_is_static_air_at_the_same_total_pressure():
    """p_T = p_s + q_c: the estimator's air (total pressure) predicts the truth's (static)."""
    _, static, _ = _airs()
    v2 = np.linspace(20.0, 150.0, 7) ** 2
    qc = static.qc_pa(v2)
    np.testing.assert_allclose(TotalPressureAir(static.ps + qc, static.oat).qc_pa(v2), qc,
                               rtol=1e-12)


def test_isentropic_relation_against_flightcondition():
    """StaticAir's q_c and inverse against flightcondition's (independent) q_c and TAS."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        from flightcondition import FlightCondition, unit
    alt_ft, cas_kt = (a.ravel() for a in np.meshgrid(np.linspace(0.0, 10000.0, 5),
                                                     np.linspace(50.0, 300.0, 6)))
    fc = FlightCondition(h=alt_ft * unit("ft"), CAS=cas_kt * unit("knots"))
    air = StaticAir(fc.p.to("Pa").magnitude, fc.T.to("K").magnitude)
    tas = fc.TAS.to("m/s").magnitude
    qc = fc.q_c.to("Pa").magnitude
    np.testing.assert_allclose(air.qc_pa(tas ** 2), qc, rtol=1e-6)
    np.testing.assert_allclose(np.sqrt(air.tas_sq(qc)), tas, rtol=1e-6)


def test_isa_air_of_a_density_is_the_isa_state_against_ambiance():
    from ambiance import Atmosphere

    alt = np.linspace(-500.0, 10000.0, 12)
    atm = Atmosphere(Atmosphere.geop2geom_height(alt))
    air = isa_air_of_density(atm.density, "compressible")
    np.testing.assert_allclose(air.oat, atm.temperature, rtol=1e-6)
    np.testing.assert_allclose(air.ps, atm.pressure, rtol=1e-5)
    np.testing.assert_allclose(isa_air(alt).ps, air.ps, rtol=1e-5)
    assert isinstance(isa_air_of_density(1.2, "incompressible"), IncompressibleAir)


def test_flight_air_names_the_missing_column():
    from pitotcal.core.errors import FlightDataError
    from pitotcal.core.flight import Flight

    one = np.ones(3)
    flight = Flight(time_s=np.arange(3.0), qci_pa=one, gps_vn_mps=one, gps_ve_mps=one,
                    rho_kgm3=one, source="f.csv")
    assert isinstance(flight_air(flight, "incompressible"), IncompressibleAir)
    with pytest.raises(FlightDataError, match="f.csv: no column ps_pa"):
        flight_air(flight, "compressible")
    with pytest.raises(FlightDataError, match="f.csv: no column ps_ref_pa"):
        flight_air(flight, "reference")


@pytest.fixture(scope="module", params=AIR_DATA_MODES)
def calm_flight(request):
    """A noise-free flight in calm air, GPS every sample: the sensor chain's q_ci is the
    measurement model's at the true state."""
    from plans import circle_plan

    from pitotcal.maneuvers import simulate

    flight, truth = simulate(circle_plan(duration_s=60.0), seed=2, rate_hz=10.0,
                             turbulence_mps=0.0, gps_noise_mps=0.0, qc_noise_pa=0.0,
                             gps_rate_hz=0.0, air_data=request.param, keep_history=True)
    return request.param, flight, truth


def test_every_user_predicts_the_sensor_chains_qci(calm_flight):
    """The simulator's sensors, the OE residual, the monitor and the design's information
    model give the same q_ci for the same state (true wind, true coefficients), in both modes."""
    from pitotcal.estimation.identification.residual import flight_channels, residual_terms
    from pitotcal.estimation.monitor.model import Calibration, air_inputs
    from pitotcal.estimation.monitor.model import predict_qci_pa as monitor_predict

    from pitotcal.core.information import predicted_qci_pa

    mode, flight, truth = calm_flight
    h = truth.history
    model, k = get_model(truth.model), np.asarray(truth.k)
    wn, we = float(h["wind_n_mps"][0]), float(h["wind_e_mps"][0])
    # the simulator's airspeed is horizontal: the true horizontal ground velocity
    vn, ve = h["gps_true_mps"][:, 0], h["gps_true_mps"][:, 1]
    sensors = flight.qci_pa
    theta = np.r_[k, wn, we]

    ch = flight_channels(flight, 0.0, mode)
    oe = sensors - residual_terms(model, theta, ch.qci, vn, ve, ch.air)[0]
    cal = Calibration(truth.model, tuple(k), wn, we, mode, {})
    monitor = monitor_predict(cal, vn, ve, None, flight.rho_kgm3,
                              air_inputs(flight) if mode == "compressible" else None)
    design = predicted_qci_pa(theta, vn, ve, isa_air(h["alt_m"], mode), model)
    design_rho = predicted_qci_pa(theta, vn, ve, flight.rho_kgm3, model, mode)
    core = predict_qci_pa(model, k, vn, ve, wn, we, flight_air(flight, mode))
    for name, got in (("oe", oe), ("monitor", monitor), ("design", design),
                      ("design from rho", design_rho), ("core", core)):
        np.testing.assert_allclose(got, sensors, rtol=1e-9, err_msg=name)
    if mode == "compressible":      # and it is not the incompressible prediction
        plain = predict_qci_pa(model, k, vn, ve, wn, we, IncompressibleAir(flight.rho_kgm3))
        assert np.median(sensors / plain - 1) > 1e-3


def test_default_air_data_is_the_standard_relation():
    assert DEFAULT_AIR_DATA == "compressible" and DEFAULT_AIR_DATA in AIR_DATA_MODES
    assert ad.qc_from_tas_pa(50.0, 101325.0, 288.15) == pytest.approx(
        StaticAir(101325.0, 288.15).qc_pa(2500.0), rel=1e-15)


@pytest.mark.parametrize("air", [StaticAir(101325.0, 288.15), TotalPressureAir(103325.0, 288.15)])
def test_numeric_air_takes_a_symbolic_speed(air):
    """Numbers in the air data and a CasADi symbol for V_t² build the same q_c as numpy."""
    import casadi as ca

    v2 = ca.MX.sym("v2")
    f = ca.Function("f", [v2], [air.qc_pa(v2), air.derivatives(v2)[0]])
    qc, slope = (float(x) for x in f(2500.0))
    assert qc == pytest.approx(float(air.qc_pa(2500.0)), rel=1e-12)
    assert slope == pytest.approx(float(air.derivatives(2500.0)[0]), rel=1e-12)
