"""The KCAS of a plan, its pilot card, its auto-throttle check and the simulator's tracking
statistics is calibrated airspeed by the standard law, checked against flightcondition at
10,000 ft, where equivalent airspeed (the old law) differs by 2.2 kt."""

import re

import numpy as np
import pytest
from pitotcal.maneuvers.fly.simulator import simulate
from pitotcal.maneuvers.plan.autothrottle import check_autothrottle
from pitotcal.maneuvers.plan.outputs import pilot_card_text
from pitotcal.maneuvers.plan.planner import plan_maneuver
from standard_air import reference

from pitotcal.core.airdata import qc_from_cas_pa
from pitotcal.core.units import FT_TO_M, mps_to_kt

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")   # pint, in flightcondition

ALT_M = 10000.0 * FT_TO_M


@pytest.fixture(scope="module")
def high_plan():
    return plan_maneuver("continuous", cas_min_kt=200.0, cas_max_kt=260.0, altitude_m=ALT_M,
                         radius_m=5000.0, duration_s=900.0, wind_speed_mps=5.0)


def test_plan_columns_are_cas_tas_and_isentropic_qc(high_plan):
    ref = reference(ALT_M, TAS=mps_to_kt(high_plan.tas_mps))
    np.testing.assert_allclose(mps_to_kt(high_plan.cas_mps), ref.CAS.to("knots").magnitude,
                               atol=0.01)
    np.testing.assert_allclose(high_plan.qc_pa, qc_from_cas_pa(high_plan.cas_mps), rtol=1e-12)
    assert mps_to_kt(high_plan.cas_mps[-1]) == pytest.approx(260.0, abs=1e-9)


def test_card_at_10000_ft_and_260_kt_is_the_standard_cas(high_plan):
    text = pilot_card_text(high_plan)
    assert "200-260 KCAS" in text
    rows = re.findall(r"^\s*(\d+):(\d\d)\s+([\d.]+)±5", text, flags=re.M)
    assert len(rows) > 10
    t = np.array([60 * int(m) + int(s) for m, s, _ in rows], dtype=float)
    card_kt = np.array([float(v) for _, _, v in rows])
    tas_kt = mps_to_kt(np.interp(t, high_plan.time_s, high_plan.tas_mps))
    true_kcas = reference(ALT_M, TAS=tas_kt).CAS.to("knots").magnitude
    np.testing.assert_allclose(card_kt, true_kcas, atol=0.1)
    assert card_kt[-1] == 260.0 and true_kcas[-1] == pytest.approx(260.0, abs=0.1)


def test_autothrottle_check_reports_standard_cas(high_plan):
    check = check_autothrottle(high_plan)
    true_kcas = reference(ALT_M, TAS=mps_to_kt(np.interp(
        check.time_s, high_plan.time_s, high_plan.tas_mps))).CAS.to("knots").magnitude
    np.testing.assert_allclose(mps_to_kt(check.cas_cmd_mps), true_kcas, atol=0.01)


def test_simulator_tracking_statistics_use_the_standard_law(high_plan):
    _, truth = simulate(high_plan, seed=2, rate_hz=5.0, turbulence_mps=0.0, keep_history=True)
    h = truth.history
    flown_kt = reference(ALT_M, TAS=mps_to_kt(h["tas_mps"])).CAS.to("knots").magnitude
    # altitude held to within centimetres here: the law at the plan altitude is the reference
    assert np.max(np.abs(h["alt_m"] - ALT_M)) < 0.5
    error_kt = flown_kt - mps_to_kt(np.interp(h["time_s"], high_plan.time_s,
                                              high_plan.cas_mps))
    tr = truth.tracking
    assert tr.max_cas_error_kt == pytest.approx(np.max(np.abs(error_kt)), abs=0.01)
    assert tr.rms_cas_error_kt == pytest.approx(np.sqrt(np.mean(error_kt ** 2)), abs=0.01)
    np.testing.assert_allclose(mps_to_kt(h["cas_mps"]), flown_kt, atol=0.01)
    # the auto-throttle holds the card's KCAS, not its equivalent airspeed (2.2 kt apart)
    assert tr.rms_cas_error_kt < 0.5 and abs(np.mean(error_kt)) < 0.1


def _eas_law_plan(plan):
    """The plan as the equivalent-airspeed law wrote it: same TAS, KCAS = sqrt(rho/rho0) TAS,
    qc_pa = ½ rho0 KCAS²."""
    import dataclasses

    from pitotcal.core.units import RHO0_KGM3, isa_density_kgm3

    eas = plan.tas_mps * np.sqrt(isa_density_kgm3(plan.alt_m) / RHO0_KGM3)
    return dataclasses.replace(plan, cas_mps=eas, qc_pa=0.5 * RHO0_KGM3 * eas ** 2)


def test_an_eas_law_plan_is_flown_at_its_kcas_as_cas_with_a_warning(high_plan):
    from pitotcal.maneuvers.fly.simulator import references

    from pitotcal.core.speeds import tas_from_cas_mps

    old = _eas_law_plan(high_plan)
    with pytest.warns(UserWarning, match=r"tas_mps differs by up to 2\.\d\d kt .* flying "
                                         r"cas_mps as calibrated airspeed"):
        refs = references(old, 5.0)
    expected = np.interp(refs.time_s, old.time_s, tas_from_cas_mps(old.cas_mps, old.alt_m))
    np.testing.assert_allclose(refs.tas_mps, expected, rtol=1e-12)
    # 260 KEAS there is 262.2 KCAS: the old card's 260 flies 0.8 % slower in TAS now
    assert refs.tas_mps[-1] / old.tas_mps[-1] == pytest.approx(0.9918, abs=0.0005)


def test_an_eas_law_plan_at_t2_altitude_flies_without_a_warning():
    import warnings

    from pitotcal.maneuvers.fly.simulator import references

    old = _eas_law_plan(plan_maneuver())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        refs = references(old, 5.0)
    # EAS and CAS differ by 0.008 kt at 800 ft and 100 kt
    np.testing.assert_allclose(refs.tas_mps, np.interp(refs.time_s, old.time_s, old.tas_mps),
                               rtol=2e-4)
