"""The uncertainty budget (estimation.identification.budget): each term against a finite-difference re-solve
and against its first-order formula; the combination and the JSON list."""

import dataclasses

import numpy as np
import pytest
from pitotcal.estimation.identification import budget as bd
from pitotcal.estimation import identify
from synthetic import synthetic_flight

from pitotcal.core.errors import PitotcalError


@pytest.fixture(scope="module")
def fitted():
    flight, _ = synthetic_flight(seed=4, n=6000, gps_rate_hz=5.0, gps_noise_mps=0.05,
                                 qc_noise_pa=0.5, turbulence_mps=0.3, vertical=True)
    flight = dataclasses.replace(flight, oat_k=np.full(flight.n, 290.0),
                                 ps_pa=flight.rho_kgm3 * 287.05287 * 290.0)
    return flight, identify(flight)


INPUTS = bd.BudgetInputs(u_oat_k=1.0, u_rh_pct=30.0, u_gps_velocity_mps=0.1,
                         u_gps_latency_s=0.1, u_probe_arm_m=1.0, u_qc_scale=0.002,
                         u_qc_offset_pa=2.0, u_ps_pa=200.0)


@pytest.fixture(scope="module")
def budget(fitted):
    flight, result = fitted
    return bd.uncertainty_budget(flight, result, INPUTS)


@pytest.mark.parametrize("name, field, unit", [s for s in bd.SOURCES
                                               if s[0] != "gps_velocity_bias"])
def test_term_against_half_step_resolves(fitted, budget, name, field, unit):
    """u_j at ±u agrees with re-solves at ±u/2 carried to ±u by d(h) = a h + b h²."""
    flight, result = fitted
    u = getattr(INPUTS, field)
    vi = budget.vi_kt
    kw = {"model": result.model, "gps_noise_std_mps": result.gps_noise_std_mps}
    base = identify(flight, **kw).delta_v_kt(vi)[0]
    d_up, d_dn = (identify(bd.PERTURBATIONS[name](flight, result, h), **kw).delta_v_kt(vi)[0]
                  - base for h in (u / 2, -u / 2))
    a, b = (d_up - d_dn) / u, 2 * (d_up + d_dn) / u ** 2       # d(±u/2) = ±a u/2 + b u²/4
    predicted = np.sqrt(((a * u + b * u * u) ** 2 + (-a * u + b * u * u) ** 2) / 2)
    assert budget.terms_kt[name] == pytest.approx(predicted, rel=0.05, abs=2e-4)
    assert np.max(budget.terms_kt[name]) > 1e-3          # each term is a real number here


def test_terms_against_first_order_formulas(fitted, budget):
    _, result = fitted
    vc = budget.vi_kt + result.delta_v_kt(budget.vi_kt)[0]
    # density δ = u/T enters V_c as sqrt(ρ): ΔV moves by V_c δ / 2
    assert budget.terms_kt["oat"] == pytest.approx(vc * 1.0 / (2 * 291.0), rel=0.03)
    # a transducer scale s moves V_i by s V_i / 2 at the same truth: ΔV at a fixed V_i by
    # (s/2) V_i (1 + dΔV/dV_i)
    slope = np.gradient(result.delta_v_kt(budget.vi_kt)[0], budget.vi_kt)
    assert budget.terms_kt["qc_scale"] == pytest.approx(budget.vi_kt * 0.001 * (1 + slope),
                                                        rel=0.03)
    # a horizontal GPS bias is the wind's: what is left comes from the vertical channel only
    assert np.max(budget.terms_kt["gps_velocity_bias"]) < 0.01


@pytest.mark.parametrize("channel", ["gps_vn_mps", "gps_ve_mps"])
def test_horizontal_gps_bias_goes_to_the_wind(fitted, channel):
    """The budget skips the horizontal GPS bias: a re-solve shows ΔV does not move."""
    flight, result = fitted
    vi = np.array([75.0, 95.0])
    kw = {"model": result.model, "gps_noise_std_mps": result.gps_noise_std_mps}
    moved = identify(bd.gps_bias(flight, channel, 0.3), **kw)
    assert moved.delta_v_kt(vi)[0] == pytest.approx(result.delta_v_kt(vi)[0], abs=1e-6)
    assert moved.value("wind_speed_mps") != pytest.approx(result.value("wind_speed_mps"),
                                                          abs=1e-3)


def test_combination_and_list(budget):
    uc = np.sqrt(budget.statistical_kt ** 2 + sum(t ** 2 for t in budget.terms_kt.values()))
    assert budget.expanded_kt == pytest.approx(2 * uc)
    rows = budget.to_list()
    assert rows[0] == {"source": "statistical", "u_dv_kt": float(np.max(budget.statistical_kt))}
    assert [r["source"] for r in rows[1:]] == [s[0] for s in bd.SOURCES]
    assert all(r["u_dv_kt"] >= 0 for r in rows)


def test_defaults_and_refusals(fitted):
    flight, result = fitted
    # the default u(OAT) is the flight-test class's probe value for a flight with an oat_k
    resolved, _ = bd.resolve(bd.BudgetInputs(), flight)
    assert resolved.u_oat_k == 1.0 and resolved.oat_source == "probe"
    with pytest.raises(PitotcalError, match="u_oat_k"):
        bd.inputs_from_options(u_oat_k=-1.0)
    with pytest.raises(PitotcalError, match="unknown budget input"):
        bd.inputs_from_options(u_oat=1.0)
    zero = bd.BudgetInputs(u_oat_k=0, u_rh_pct=0, u_gps_velocity_mps=0, u_gps_latency_s=0,
                           u_qc_scale=0, u_qc_offset_pa=0, u_ps_pa=0)
    b = bd.uncertainty_budget(flight, result, zero)
    assert b.expanded_kt == pytest.approx(2 * b.statistical_kt)


def test_resolves_are_identify_without_the_bounds(fitted):
    """The budget re-solves with `estimate`: identify's parameters to the last bit (gates and
    outlier trimming included: spikes put in here), only the bounds and checks skipped."""
    from pitotcal.estimation.identification.identify import estimate

    flight, _ = fitted
    qci = flight.qci_pa.copy()
    qci[[500, 2500, 4500]] += 300.0
    spiked = dataclasses.replace(flight, qci_pa=qci)
    full, quick = identify(spiked), estimate(spiked)
    assert any("trimmed as outliers" in w for w in full.warnings)
    np.testing.assert_array_equal(quick.params, full.params)
    np.testing.assert_array_equal(quick.residuals_pa, full.residuals_pa)
    np.testing.assert_array_equal(quick.covariance, full.covariance_plain)
    assert quick.consistency == {} and full.consistency


def test_a_term_not_computed_prints_n_a(fitted, budget):
    """A term whose re-solve was refused is NaN in the budget: its text table says n/a, never
    nan."""
    from pitotcal.estimation.reporting.budget_tables import budget_summary

    name = next(iter(budget.terms_kt))
    terms = {**budget.terms_kt, name: np.full_like(budget.terms_kt[name], np.nan)}
    spoiled = dataclasses.replace(budget, terms_kt=terms)     # u_c and U then NaN too
    text = budget_summary(fitted[1], spoiled)
    assert "nan" not in text and "n/a" in text


def test_altimeter_and_mach_terms_follow_the_airspeed_terms(fitted, budget):
    """Each Type B term carried to ΔH_pc and ΔM_pc: at a fixed V_ic the re-solve moves the
    static error by δΔp = (dq_c/dV_c) δΔV, so ΔH by δΔp / (ρ_ISA(H_ic) g0) and ΔM by
    (∂M/∂q_c) δΔp (first order, independent of the budget's products)."""
    from pitotcal.core import airdata
    from pitotcal.core.units import G0_MPS2, isa_density_kgm3, kt_to_mps, m_to_ft
    from pitotcal.estimation.identification.static_source import pressure_altitude_ic_m

    _, result = fitted
    vc = budget.vi_kt + result.delta_v_kt(budget.vi_kt)[0]
    dqc_dvc = (airdata.qc_from_cas_pa(kt_to_mps(vc + 0.01))
               - airdata.qc_from_cas_pa(kt_to_mps(vc - 0.01))) / kt_to_mps(0.02)
    h_ic = pressure_altitude_ic_m(result)
    ps = float(np.median(result.ps_pa))
    qc = airdata.qc_from_cas_pa(kt_to_mps(vc))
    dm_dqc = (airdata.mach_from_qc(qc + 1.0, ps) - airdata.mach_from_qc(qc - 1.0, ps)) / 2.0
    for name in ("oat", "humidity", "qc_scale", "qc_offset", "probe_lever_arm"):
        dp = dqc_dvc * kt_to_mps(budget.terms_kt[name])
        dh = m_to_ft(dp / (isa_density_kgm3(h_ic) * G0_MPS2))
        assert budget.products["dh_ft"][name] == pytest.approx(dh, rel=0.03), name
        assert budget.products["dmach"][name] == pytest.approx(dm_dqc * dp, rel=0.05), name
    # the combination is the same GUM sum, and the JSON row carries it
    u = budget.products["dh_ft"]
    assert budget.product_expanded("dh_ft") == pytest.approx(
        2 * np.sqrt(sum(t ** 2 for t in u.values())))
    row = budget.product_row(0)
    assert row["dh_U_ft"] == pytest.approx(budget.product_expanded("dh_ft")[0])
    assert set(row["u_dh_by_source_ft"]) == {"statistical", *budget.terms_kt}
    # 1 K of OAT at ~150 ft: about 0.76 ft of ΔH at 70 kt (ΔV 0.12 kt)
    assert 0.5 < u["oat"][0] < 1.0
