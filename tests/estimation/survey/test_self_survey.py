"""The self-survey recovers a known static position error from a simulated flight, within its
stated 2σ, and on the two real jet test points gives a rising Δp_p/p_s with its bounds."""

import dataclasses
import warnings

import numpy as np
import pytest
from jets import JMOSS_ATTITUDE_MAP, JMOSS_MAP
from plans import circle_plan

from pitotcal.core.airdata import mach_from_qc
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model, qc_from_qci_pa
from pitotcal.core.units import ISA_LAPSE_KPM, isa_pressure_pa, isa_temperature_k, mps_to_kt
from pitotcal.estimation.survey import hydrostatic_pressure_pa, self_survey
from pitotcal.maneuvers.fly.options import air_sensors
from pitotcal.maneuvers.fly.simulator import simulate

RECOVERY = 0.95


@pytest.fixture(scope="module", params=[0, 1])
def flown(request):
    """180-260 KCAS at 10,000 ft in 1 m/s turbulence, a 0.95-recovery total-temperature probe,
    all the pressure error (k1 0.02, k2 -15 Pa) in the static port."""
    plan = circle_plan(duration_s=240.0, cas_kt=(180.0, 260.0), radius_m=4500.0,
                       altitude_m=3048.0, wind_speed_mps=8.0, wind_from_deg=200.0)
    flight, truth = simulate(plan, seed=request.param, turbulence_mps=1.0, rate_hz=10.0,
                             air_data="compressible",
                             air_sensors=air_sensors(tat_recovery=RECOVERY))
    k = (truth.parameters["k1"], truth.parameters["k2"])
    dpp_true = (qc_from_qci_pa(get_model("inverse"), k, flight.qci_pa) - flight.qci_pa) \
        / flight.ps_pa
    return flight, truth, dpp_true, self_survey(flight)


def test_the_curve_is_within_its_2_sigma_of_truth(flown):
    flight, _, dpp_true, result = flown
    assert result.success and len(result.spe) >= 5
    mach = mach_from_qc(flight.qci_pa / flight.ps_pa, 1.0)
    order = np.argsort(mach)
    for row in result.spe:
        truth = np.interp(row["mach_ic"], mach[order], dpp_true[order])
        assert abs(row["dpp_ps"] - truth) < row["dpp_ps_2sigma"], row
    # measured 2σ 0.0015-0.0026 on seeds 0-3 (the reference pressure and the recovery share
    # the slow part of the airspeed in turbulence): the bound must stay below 0.003
    assert max(r["dpp_ps_2sigma"] for r in result.spe) < 0.003


def test_wind_and_recovery_within_2_sigma(flown):
    _, truth, _, result = flown
    wn = -truth.parameters["wind_speed_mps"] * np.cos(np.radians(truth.parameters["wind_from_deg"]))
    we = -truth.parameters["wind_speed_mps"] * np.sin(np.radians(truth.parameters["wind_from_deg"]))
    # 1 m/s turbulence: the truth is the mean wind, the fit sees the wind flown through
    assert abs(result.wind_n_mps - wn) < 2 * result.std("wind_n_mps") + 0.3
    assert abs(result.wind_e_mps - we) < 2 * result.std("wind_e_mps") + 0.3
    assert abs(result.recovery - RECOVERY) < 2 * result.std("recovery") + 0.01


def test_hydrostatic_pressure_is_the_standard_atmosphere_on_its_profile():
    h = np.array([2500.0, 3000.0, 3500.0])
    p = hydrostatic_pressure_pa(h, 3000.0, isa_pressure_pa(3000.0), isa_temperature_k(3000.0),
                                ISA_LAPSE_KPM)
    np.testing.assert_allclose(p, isa_pressure_pa(h), rtol=1e-12)
    iso = hydrostatic_pressure_pa(3010.0, 3000.0, 7e4, 260.0, 0.0)
    assert iso == pytest.approx(7e4 * np.exp(-9.80665 * 10.0 / (287.05287 * 260.0)))


def test_a_flight_without_gps_height_is_refused(flown):
    flight = dataclasses.replace(flown[0], alt_m=None)
    with pytest.raises(PitotcalError, match="`flight` has no alt_m"):
        self_survey(flight)




@pytest.mark.parametrize("point", ["CLASS55", "CLASS65"])
def test_real_jet_points(point, shared_file, tmp_path):
    """Measured (docs/measured.md, 2026-11-26): Δp_p/p_s rises with M_ic from about 0.006-0.011
    at M_ic 0.55 to 0.03-0.05 near 0.95; the wind is within 7 kt of the radiosonde."""
    from pitotcal.io.mapped_csv import read_mapped_csv
    from pitotcal.io.radiosonde import read_sounding

    path = shared_file(f"jmoss/{point}.csv")
    mapping = tmp_path / "jmoss.toml"
    mapping.write_text(JMOSS_MAP)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = self_survey(read_mapped_csv(path, mapping, mach_ic_max=1.0))
    curve = [r for r in result.spe if 0.55 <= r["mach_ic"] <= 0.9]
    values = [r["dpp_ps"] for r in curve]
    assert len(curve) >= 12 and np.all(np.diff(values) > 0)
    assert 0.004 < values[0] < 0.014 and 0.02 < values[-1] < 0.035
    assert all(r["dpp_ps_2sigma"] < 0.006 for r in curve)
    sonde = read_sounding(shared_file("jmoss/WB.txt")).at(result.h_ref_m)
    miss = np.hypot(result.wind_n_mps - sonde["wind_n_mps"],
                    result.wind_e_mps - sonde["wind_e_mps"])
    assert mps_to_kt(miss) < 7.0
    assert abs(result.oat_k - sonde["temp_k"]) < 4.0


def test_real_jet_vector_airspeed(shared_file, tmp_path):
    """Pointing the airspeed with attitude and the sideslip vane (as JMOSS does) moves the
    CLASS65 wind from 6.4 to 2.9 kt of the radiosonde (JMOSS: 2.8), with the wide bound the
    vector fit's larger residuals give (docs/measured.md, 2026-11-26)."""
    from pitotcal.io.mapped_csv import read_attitude, read_mapped_csv
    from pitotcal.io.radiosonde import read_sounding

    path = shared_file("jmoss/CLASS65.csv")
    mapping = tmp_path / "jmoss.toml"
    mapping.write_text(JMOSS_ATTITUDE_MAP)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        flight = read_mapped_csv(path, mapping, mach_ic_max=1.0)
    attitude = read_attitude(path, mapping)
    result = self_survey(flight, attitude=attitude)
    assert result.airspeed_model == "vector" and result.to_dict()["wind_d_mps"] < 0.0
    sonde = read_sounding(shared_file("jmoss/WB.txt")).at(result.h_ref_m)
    miss = np.hypot(result.wind_n_mps - sonde["wind_n_mps"],
                    result.wind_e_mps - sonde["wind_e_mps"])
    assert mps_to_kt(miss) < 4.0
    with pytest.raises(PitotcalError, match="`attitude` has no sample at the flight's time"):
        self_survey(flight, attitude={**attitude, "time_s": attitude["time_s"] + 0.01})


@pytest.mark.parametrize("bounds", [(1.0, 0.9), (0.0, 1.0), "x", (0.5, 2.0)])
def test_recovery_bounds_are_checked(flown, bounds):
    with pytest.raises(PitotcalError, match="`recovery_bounds`"):
        self_survey(flown[0], recovery_bounds=bounds)
