"""Calibrations at the edges of the envelope: simulated compressible flights at 39,000 ft (above
the tropopause), one at 200-260 KCAS and one accelerating through Mach 1.05, identify without
refusal; the result's ΔV_pc, M_ic, ΔM_pc and ΔH_pc agree with an independent reduction
(tests/standard_air.py: the normal-shock pitot relations and ambiance's ICAO atmosphere) to
0.01 kt / 1e-4 / 1 ft, and with truth within their bands."""

import dataclasses

import numpy as np
import pytest
import standard_air as std
from pitotcal.estimation.identification.identify import identify
from pitotcal.maneuvers.fly.simulator import simulate
from plans import circle_plan

from pitotcal.core import units

FL390_M = 39000 * units.FT_TO_M
FL390 = std.isa(FL390_M)


def _cas_kt_of_mach(mach):
    qc = std.qc_of_mach(np.asarray(mach), FL390.pressure[0])
    return tuple(float(v) for v in std.cas_of_qc(qc) / units.KT_TO_MPS)


# (CAS range kt, ground-circle radius m: a bank of about 20 deg at the top speed)
FLIGHTS = {
    "200-260 KCAS, 39,000 ft": ((200.0, 260.0), 12000.0),
    "Mach 0.9-1.1, 39,000 ft": (_cas_kt_of_mach([0.9, 1.1]), 20000.0),
}


@pytest.fixture(scope="module", params=list(FLIGHTS))
def flown(request):
    cas, radius = FLIGHTS[request.param]
    plan = circle_plan(duration_s=360.0, cas_kt=cas, radius_m=radius, altitude_m=FL390_M,
                       wind_speed_mps=10.0, step_s=1.0)
    flight, truth = simulate(plan, seed=0, turbulence_mps=0.0, rate_hz=10.0,
                             air_data="compressible", keep_history=True)
    return request.param, flight, truth, identify(flight, model="inverse")


def _reduction(k, vi_kt, ps_ind_pa):
    """(ΔV_pc kt, M_ic, ΔM_pc, ΔH_pc ft) of dp/q_c = k1 + k2/q_ci at V_ic, independently."""
    qci = std.qc_of_cas(np.asarray(vi_kt) * units.KT_TO_MPS)
    qc = qci / (1.0 - (k[0] + k[1] / qci))
    dp = qc - qci                                   # all the error in the static source
    mach_i = std.mach_of_qc(qci, ps_ind_pa)
    dh_m = std.pressure_altitude_m(ps_ind_pa - dp) - std.pressure_altitude_m(ps_ind_pa)
    return (std.cas_of_qc(qc) / units.KT_TO_MPS - vi_kt, mach_i,
            std.mach_of_qc(qc, ps_ind_pa - dp) - mach_i, dh_m / units.FT_TO_M)


def _table(result):
    rows = result.correction_table()
    return {key: np.array([row[key] for row in rows], dtype=float)
            for key in ("vi_kt", "dv_kt", "dv_2sigma_kt", "mach_i", "dmach", "dmach_2sigma",
                        "dh_ft", "dh_2sigma_ft")}


def test_identified_without_refusal_within_3_sigma(flown):
    name, flight, truth, result = flown
    assert result.success and result.air_data == "compressible"
    assert np.median(flight.alt_m) > 11000.0 and np.min(flight.ps_pa) < 22632.0
    if "Mach" in name:                  # the flight passes through Mach 1.05
        mach = std.mach_of_qc(flight.qci_pa, flight.ps_pa)
        assert mach.min() < 0.95 and mach.max() > 1.05
    for key in ("k1", "k2", "wind_speed_mps", "wind_from_deg"):
        z = (result.value(key) - truth.parameters[key]) / result.stddev(key)
        assert abs(z) < 3.0, (key, z)
    assert not any("not computed" in w for w in result.warnings)


def test_corrections_match_an_independent_reduction(flown):
    _, flight, truth, result = flown
    table = _table(result)
    ps_ind = float(np.median(flight.ps_pa))
    dv, mach_i, dmach, dh_ft = _reduction(result.coefficients, table["vi_kt"], ps_ind)
    np.testing.assert_allclose(table["dv_kt"], dv, atol=0.01)
    np.testing.assert_allclose(table["mach_i"], mach_i, atol=1e-4)
    np.testing.assert_allclose(table["dmach"], dmach, atol=1e-4)
    np.testing.assert_allclose(table["dh_ft"], dh_ft, atol=1.0)
    # and the truth's corrections within the bands the result reports (plus those tolerances)
    dv, _, dmach, dh_ft = _reduction(truth.k, table["vi_kt"], ps_ind)
    assert np.all(np.abs(table["dv_kt"] - dv) < 0.01 + 1.5 * table["dv_2sigma_kt"])
    assert np.all(np.abs(table["dmach"] - dmach) < 1e-4 + 1.5 * table["dmach_2sigma"])
    assert np.all(np.abs(table["dh_ft"] - dh_ft) < 1.0 + 1.5 * table["dh_2sigma_ft"])


def test_altimeter_correction_is_what_the_static_port_shows(flown):
    """ΔH_pc against the truth the estimator never saw, sample by sample: ambiance's pressure
    altitude of the ISA pressure flown vs that of the static port's reading."""
    _, flight, truth, result = flown
    ps_true = std.isa(truth.history["alt_m"]).pressure
    dh_samples_ft = (std.pressure_altitude_m(ps_true)
                     - std.pressure_altitude_m(flight.ps_pa)) / units.FT_TO_M
    vic = std.cas_of_qc(flight.qci_pa) / units.KT_TO_MPS
    from pitotcal.estimation.identification.static_source import static_source_products
    got = static_source_products(result, vic)["dh_ft"]
    np.testing.assert_allclose(got, dh_samples_ft, rtol=0.01, atol=1.0)


def test_incompressible_fit_is_warned_about(flown):
    _, flight, _, result = flown
    assert not any("incompressible air data" in w for w in result.warnings)
    fitted = identify(flight, model="inverse", air="incompressible")
    note = next(w for w in fitted.warnings if "fitted with the incompressible air data" in w)
    # the true Mach's 99th percentile, from the true airspeed flown and the ISA's speed of sound
    _, _, truth, _ = flown
    top = np.percentile(truth.history["tas_mps"] / FL390.speed_of_sound[0], 99)
    said = float(note.split("up to Mach ")[1].split(":")[0])
    assert said == pytest.approx(top, abs=0.006)
    # and without a temperature: the Mach from the ISA temperature of the density
    rho_only = dataclasses.replace(flight, ps_pa=None, oat_k=None)
    assert any("fitted with the incompressible air data" in w
               for w in identify(rho_only, model="inverse").warnings)


def test_a_flight_at_25_km_is_not_gated_away():
    """The density gate compares with the ISA at the flight's altitude up to 32 km (it stopped
    at 20 km: every sample of this flight was dropped as implausible)."""
    plan = circle_plan(duration_s=300.0, cas_kt=(120.0, 160.0), radius_m=20000.0,
                       altitude_m=25000.0, wind_speed_mps=10.0, step_s=1.0)
    flight, truth = simulate(plan, seed=0, turbulence_mps=0.0, rate_hz=10.0,
                             air_data="compressible")
    result = identify(flight, model="inverse")
    assert result.success and result.n_samples == flight.n
    for key in ("k1", "k2", "wind_speed_mps", "wind_from_deg"):
        z = (result.value(key) - truth.parameters[key]) / result.stddev(key)
        assert abs(z) < 3.0, (key, z)
