"""Issue 9's "done when": the compressible calibration recovers compressible truth.

Simulated flights with isentropic truth and all the pressure error in the static source (the
static port logs p_s + Δp_p), at 70-100 KCAS / 3,000 ft, 90-150 KCAS / 8,000 ft and
180-260 KCAS / 10,000 ft: k1, k2, the wind, ΔV_pc and ΔH_pc within 3σ of truth; the same
flights fitted with air="incompressible" miss ΔV_pc by what the README quotes.
"""

import dataclasses

import numpy as np
import pytest
from pitotcal.estimation.identification.identify import identify
from pitotcal.estimation.identification.static_source import static_source_products
from pitotcal.maneuvers.fly.simulator import simulate
from plans import circle_plan

from pitotcal.core import airdata as ad
from pitotcal.core import units
from pitotcal.core.models import delta_v_kt, get_model, qc_from_qci_pa

# (CAS range kt, altitude m, ground-circle radius m: bank <= 30 deg at the top speed)
RANGES = {
    "70-100 kt, 3,000 ft": ((70.0, 100.0), 914.4, 600.0),
    "90-150 kt, 8,000 ft": ((90.0, 150.0), 2438.4, 1500.0),
    "180-260 kt, 10,000 ft": ((180.0, 260.0), 3048.0, 4500.0),
}
# What the incompressible fit misses ΔV_pc by at the lowest and highest V_ic flown, kt
# (measured, seed 0, calm air; README "Air data"): about −V (V/a0)^2 / 8 plus the altitude's
# V_e/V_c difference.
INCOMPRESSIBLE_MISS_KT = {
    "70-100 kt, 3,000 ft": (-0.09, -0.30),
    "90-150 kt, 8,000 ft": (-0.12, -1.19),
    "180-260 kt, 10,000 ft": (-1.81, -6.48),
}


@pytest.fixture(scope="module", params=list(RANGES))
def flown(request):
    cas, alt, radius = RANGES[request.param]
    plan = circle_plan(duration_s=240.0, cas_kt=cas, radius_m=radius, altitude_m=alt,
                       wind_speed_mps=5.0)
    flight, truth = simulate(plan, seed=0, turbulence_mps=0.0, rate_hz=10.0,
                             air_data="compressible", keep_history=True)
    return request.param, flight, truth, identify(flight, model="inverse")


def _vi_grid(result):
    table = result.correction_table()
    return np.linspace(table[0]["vi_kt"], table[-1]["vi_kt"], 5)


def test_parameters_within_3_sigma(flown):
    _, _, truth, result = flown
    assert result.air_data == "compressible" and result.success
    for name in ("k1", "k2", "wind_speed_mps", "wind_from_deg"):
        z = (result.value(name) - truth.parameters[name]) / result.stddev(name)
        assert abs(z) < 3.0, (name, z)


def test_position_error_corrections_within_3_sigma(flown):
    _, flight, truth, result = flown
    vi = _vi_grid(result)
    model = get_model(truth.model)
    dv, band = result.delta_v_kt(vi)
    assert np.all(np.abs(dv - delta_v_kt(model, truth.k, vi, "compressible")) < 1.5 * band)
    # ΔH_pc at the flight's median indicated pressure altitude, from the true coefficients
    ps_ind = float(np.median(flight.ps_pa))
    qci = ad.qc_from_cas_pa(units.kt_to_mps(vi))
    dp_true = qc_from_qci_pa(model, truth.k, qci) - qci
    h_ic = ad.pressure_altitude_m(ps_ind)
    dh_true_ft = units.m_to_ft(ad.pressure_altitude_m(ps_ind - dp_true) - h_ic)
    got = static_source_products(result, vi)
    assert np.all(np.abs(got["dh_ft"] - dh_true_ft) < 1.5 * got["dh_2sigma_ft"])
    rows = result.to_dict()["airspeed_correction"]
    assert {"mach_i", "dmach", "dh_ft", "dh_2sigma_ft"} <= set(rows[0])


def test_altimeter_correction_is_what_the_static_port_shows(flown):
    """The reported ΔH_pc against the truth the estimator never saw: the ISA static pressure
    at the altitude flown vs the static port's reading, sample by sample."""
    _, flight, truth, result = flown
    ps_true = units.isa_pressure_pa(truth.history["alt_m"])
    dh_samples_ft = units.m_to_ft(ad.pressure_altitude_m(ps_true)
                                  - ad.pressure_altitude_m(flight.ps_pa))
    vic = units.mps_to_kt(ad.cas_from_qc_mps(flight.qci_pa))
    got = static_source_products(result, vic)["dh_ft"]
    # the altitude wanders by a few metres about the median, which moves ΔH by < 0.1 %
    np.testing.assert_allclose(got, dh_samples_ft, rtol=0.01, atol=0.2)


def test_incompressible_fit_shows_the_bias(flown):
    name, flight, truth, result = flown
    vi = _vi_grid(result)
    # the formula's bias under a constant wind: with the speed swept once in time, a drifting
    # wind ("auto" chooses it on this misfit) takes up a part of it (-1.91, -6.52 kt here)
    incompressible = identify(flight, model="inverse", air="incompressible", wind="constant")
    assert incompressible.air_data == "incompressible"
    dv, band = incompressible.delta_v_kt(vi)
    miss = dv - delta_v_kt(get_model(truth.model), truth.k, vi, "compressible")
    np.testing.assert_allclose(miss[[0, -1]], INCOMPRESSIBLE_MISS_KT[name], atol=0.02)
    # outside its own band; the multiscale noise model (issue 11) counts the misfit's slow
    # structure in the residuals as colored noise, so the band of a misspecified fit is wider
    # than the correctly specified one's (x15 here), no longer 3x below the miss
    assert np.all(np.abs(miss[1:]) > band[1:])


def test_rho_only_flight_is_fitted_incompressible_with_a_warning(flown):
    _, flight, _, _ = flown
    rho_only = dataclasses.replace(flight, ps_pa=None, oat_k=None)
    result = identify(rho_only, model="inverse")
    plain = identify(flight, model="inverse", air="incompressible")
    assert result.air_data == "incompressible"
    assert any("no static pressure and temperature (ps_pa, oat_k)" in w for w in result.warnings)
    np.testing.assert_array_equal(result.params, plain.params)
    assert "static_source" not in result.to_dict() and result.to_dict()["air_data"] == \
        "incompressible"


@pytest.mark.slow
def test_coverage_of_the_2_sigma_bands_in_turbulence():
    """50 compressible flights at 90-150 KCAS / 8,000 ft in 0.5 m/s Dryden turbulence: the 2σ
    bands hold k1, k2, ΔV_pc and ΔH_pc about 95% of the time (measured 96, 94, 93, 93 %; the
    other ranges in docs/measured.md)."""
    cas, alt, radius = RANGES["90-150 kt, 8,000 ft"]
    plan = circle_plan(duration_s=240.0, cas_kt=cas, radius_m=radius, altitude_m=alt,
                       wind_speed_mps=5.0)
    model = get_model("inverse")
    inside = {"k1": [], "k2": [], "dv": [], "dh": []}
    for seed in range(50):
        flight, truth = simulate(plan, seed=seed, turbulence_mps=0.5, rate_hz=10.0,
                                 air_data="compressible")
        result = identify(flight, model="inverse")
        for name in ("k1", "k2"):
            inside[name].append(abs(result.value(name) - truth.k[0 if name == "k1" else 1])
                                <= 2 * result.stddev(name))
        rows = result.correction_table()
        vi = np.array([row["vi_kt"] for row in rows])
        true_dv = delta_v_kt(model, truth.k, vi, "compressible")
        inside["dv"] += [abs(row["dv_kt"] - t) <= row["dv_2sigma_kt"] for row, t in zip(rows, true_dv)]
        ps_ind = float(np.median(flight.ps_pa))
        qci = ad.qc_from_cas_pa(units.kt_to_mps(vi))
        dp = qc_from_qci_pa(model, truth.k, qci) - qci
        true_dh = units.m_to_ft(ad.pressure_altitude_m(ps_ind - dp) - ad.pressure_altitude_m(ps_ind))
        inside["dh"] += [abs(row["dh_ft"] - t) <= row["dh_2sigma_ft"] for row, t in zip(rows, true_dh)]
    coverage = {name: float(np.mean(v)) for name, v in inside.items()}
    assert all(0.85 <= c <= 1.0 for c in coverage.values()), coverage


@pytest.fixture(scope="module")
def split_flight():
    """A compressible flight whose pressure error is 60 % static, 40 % total, with a reference
    static pressure: the static port reads p_s + 0.6 Δp, the pitot p_T − 0.4 Δp (q_ci as before)."""
    cas, alt, radius = RANGES["90-150 kt, 8,000 ft"]
    plan = circle_plan(duration_s=240.0, cas_kt=cas, radius_m=radius, altitude_m=alt,
                       wind_speed_mps=5.0)
    flight, truth = simulate(plan, seed=0, turbulence_mps=0.0, rate_hz=10.0,
                             air_data="compressible", keep_history=True)
    ps = units.isa_pressure_pa(truth.history["alt_m"])
    split = dataclasses.replace(flight, ps_pa=ps + 0.6 * (flight.ps_pa - ps))
    return split, dataclasses.replace(split, ps_ref_pa=ps), truth


def test_reference_static_pressure_separates_static_and_total_error(split_flight):
    assumed, measured, truth = split_flight
    result = identify(measured, model="inverse")
    assert result.air_data == "compressible" and result.ps_ref_pa is not None
    for name in ("k1", "k2"):                      # the total error, from the reference p_s
        assert abs(result.value(name) - truth.parameters[name]) < 3 * result.stddev(name)
    d = result.to_dict()
    assert d["static_source"]["assumed"].startswith("static-source error measured against")
    k_static = d["static_source"]["k_static"]
    assert k_static["k1"]["value"] == pytest.approx(0.6 * 0.02, rel=2e-3)
    assert k_static["k2"]["value"] == pytest.approx(0.6 * -15.0, rel=2e-3)
    rows = d["airspeed_correction"]
    vi = np.array([row["vi_kt"] for row in rows])
    model = get_model(truth.model)
    qci = ad.qc_from_cas_pa(units.kt_to_mps(vi))
    dp_total = qc_from_qci_pa(model, truth.k, qci) - qci
    dpt = np.array([row["dpt_qcic"] for row in rows])
    band = np.array([row["dpt_qcic_2sigma"] for row in rows])
    assert np.all(np.abs(dpt - (-0.4 * dp_total / qci)) < 1.5 * band + 1e-5)
    # ΔH_pc from the static part only: 0.6 of the all-static value
    ps_ind = float(np.median(measured.ps_pa))
    dh_true = units.m_to_ft(ad.pressure_altitude_m(ps_ind - 0.6 * dp_total)
                            - ad.pressure_altitude_m(ps_ind))
    np.testing.assert_allclose([row["dh_ft"] for row in rows], dh_true, rtol=0.01)
    assert "Measured: static-source error measured against" in result.summary()
    # without the reference the all-static assumption is wrong here, and k1 shows it
    wrong = identify(assumed, model="inverse")
    assert abs(wrong.value("k1") - 0.02) > 3 * wrong.stddev("k1")


@pytest.mark.parametrize("column, value, match", [
    ("oat_k", np.nan, "oat_k, row 5: not finite"),
    ("oat_k", -3.0, "oat_k, row 5: not positive"),
    ("ps_pa", 0.0, "ps_pa, row 5: not positive"),
])
def test_bad_static_channels_are_refused(flown, column, value, match):
    from pitotcal.core.errors import FlightDataError

    _, flight, _, _ = flown
    values = getattr(flight, column).copy()
    values[4] = value
    with pytest.raises(FlightDataError, match=match):
        identify(dataclasses.replace(flight, **{column: values}))
    # the incompressible fit does not use them
    identify(dataclasses.replace(flight, **{column: values}), air="incompressible")


def test_unknown_air_mode_is_refused(flown):
    from pitotcal.core.errors import PitotcalError

    with pytest.raises(PitotcalError, match="air 'isentropic' is not one of incompressible, "
                                            "compressible") as err:
        identify(flown[1], air="isentropic")
    assert err.value.param == "air"
