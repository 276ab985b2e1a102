"""The altimeter verdict on a simulated flight at 180-262 KCAS and 10,000 ft: ΔH_pc judged at
sea level in a standard atmosphere (checked against `ambiance`'s ISA from the true
coefficients), on its own expanded uncertainty with the Type B terms."""

import numpy as np
import pytest
from ambiance import Atmosphere
from pitotcal.estimation.identification import budget as bd
from pitotcal.estimation.identification.identify import identify
from pitotcal.estimation.identification.record import with_budget
from pitotcal.estimation.reporting.compliance import assess
from pitotcal.maneuvers.fly.simulator import simulate
from plans import circle_plan

from pitotcal.core import airdata as ad
from pitotcal.core import units
from pitotcal.core.models import get_model, qc_from_qci_pa


@pytest.fixture(scope="module")
def flown():
    plan = circle_plan(duration_s=240.0, cas_kt=(180.0, 262.0), radius_m=4500.0,
                       altitude_m=3048.0, wind_speed_mps=5.0)
    flight, truth = simulate(plan, seed=0, turbulence_mps=0.0, rate_hz=10.0,
                             air_data="compressible")
    result = identify(flight, model="inverse")
    plain = result.to_dict()
    return truth, plain, with_budget(plain, bd.uncertainty_budget(flight, result))


def _top(block):
    return block["altimeter"]["rows"][-1]


def test_sea_level_value_is_the_true_static_error_at_sea_level(flown):
    truth, plain, _ = flown
    top = _top(assess(plain, "23.1323"))
    vi = plain["airspeed_correction"][-1]["vi_kt"]
    qci = ad.qc_from_cas_pa(units.kt_to_mps(vi))
    dp = qc_from_qci_pa(get_model(truth.model), truth.k, qci) - qci
    # ambiance: the pressure altitude of p0 - dp (geometric and geopotential differ by 0.002 ft
    # at 20 ft)
    dh_true_ft = units.m_to_ft(float(Atmosphere.from_pressure(101325.0 - dp).h[0]))
    assert top["dh_ft"] == pytest.approx(dh_true_ft, abs=0.5)
    # the test-altitude value is kept beside it: the 80.0 ft against 78.6 ft
    assert top["dh_test_altitude_ft"] == pytest.approx(80.0, abs=0.3)
    assert top["dh_ft"] == pytest.approx(59.2, abs=0.3)


def test_flips_to_complies_at_sea_level_on_the_statistical_band(flown):
    _, plain, _ = flown
    top = _top(assess(plain, "23.1323"))
    assert top["u_kind"] == "statistical" and top["verdict"] == "complies"
    # at the test altitude the same numbers do not comply
    assert abs(top["dh_test_altitude_ft"]) - top["u_ft"] > top["limit_ft"]


def test_expanded_uncertainty_carries_the_type_b_terms(flown):
    _, plain, budgeted = flown
    block = assess(budgeted, "23.1323")
    rows = [r for r in block["altimeter"]["rows"] if r["verdict"] != "not judged"]
    assert all(r["u_kind"] == "expanded" for r in rows)
    assert block["uncertainty"] == "expanded"
    top, row = rows[-1], budgeted["airspeed_correction"][-1]
    # 1 K of OAT at 10,000 ft is 14-15 ft of ΔH (u, test altitude): U is Type B dominated
    assert 12.0 < row["u_dh_by_source_ft"]["oat"] < 17.0
    assert row["dh_U_ft"] > 20 * row["dh_2sigma_ft"]
    # U reduced to sea level with ΔH (ρ(H_ic)/ρ0 = 0.74)
    assert top["u_ft"] == pytest.approx(0.739 * row["dh_U_ft"], rel=0.01)
    # complies needs |ΔH| + U <= limit: 59.2 + 23.5 > 78.6, and 59.2 - 23.5 < 78.6
    for r in rows:
        inside = abs(r["dh_ft"]) + r["u_ft"] <= r["limit_ft"]
        outside = abs(r["dh_ft"]) - r["u_ft"] > r["limit_ft"]
        expected = "complies" if inside else "does not comply" if outside else \
            "not demonstrated"
        assert r["verdict"] == expected
    assert top["verdict"] == "not demonstrated"
    assert np.isfinite(row["dmach_U"]) and row["dmach_U"] > 0


def test_sitl_log_low_speeds_comply_under_the_30_ft_floor(shared_file, tmp_path):
    """The ArduPlane SITL log with --oat-c 15 (185 ft): ΔH 17-26 ft at 46-57 KCAS was judged
    against 14-17 ft (0.3 ft/kt) and did not comply; the paragraph's floor is 30 ft."""
    import json

    from pitotcal.cli import main

    log = shared_file("ardupilot/arduplane_sitl.log")
    out = tmp_path / "sitl.json"
    assert main(["identify", str(log), "--oat-c", "15", "--no-budget", "--json", str(out)]) == 0
    block = assess(json.loads(out.read_text()), "23.1323")
    rows = [r for r in block["altimeter"]["rows"] if 46.0 <= r["vc_kt"] <= 58.0]
    assert len(rows) >= 5 and min(r["dh_ft"] for r in rows) > 16.0
    assert max(r["dh_ft"] for r in rows) > 25.0
    assert all(r["limit_ft"] == 30.0 and r["verdict"] == "complies" for r in rows)
