"""The global fit over every leg: simulated truth recovered within 3σ, its JSON form, the wind
groups and the refusal of too few legs."""

import numpy as np
import pytest
from pitotcal.estimation.legs.points import solve_points
from pitotcal.estimation.legs.global_fit import fit_legs, wind_groups
from pitotcal.maneuvers.fly.legs import LEGS_TRUE_K, simulate_legs

from pitotcal.core.errors import ObservabilityError, PitotcalError
from pitotcal.core.models import delta_v_kt, get_model


def _start(legs):
    sols, _ = solve_points(legs)
    return {s.point: (s.wind_n_mps, s.wind_e_mps) for s in sols}


@pytest.mark.parametrize("wind", ["per-band", "per-point"])
@pytest.mark.parametrize("state_sd", [True, False])
def test_global_fit_recovers_truth_within_3_sigma(wind, state_sd):
    legs, truth = simulate_legs(seed=21, leg_sd_kt=0.6, state_sd=state_sd)
    fit = fit_legs(legs, model="inverse", wind=wind, initial_winds=_start(legs))
    assert fit.converged and fit.noise_source == ("stated" if state_sd else "scatter")
    z = (fit.coefficients - np.array(LEGS_TRUE_K)) / np.sqrt(np.diag(fit.coef_cov))
    assert np.all(np.abs(z) < 3)
    dv, half = fit.delta_v_kt(truth.ias_kt)
    assert np.all(np.abs(dv - truth.dv_kt) <= 1.5 * half)          # 1.5 × 2σ
    winds = fit.winds_ne_mps
    assert np.all(np.abs(winds - [truth.wind_n_mps, truth.wind_e_mps]) < 1.0)


def test_global_band_narrower_than_the_per_point_bounds():
    """Same legs (same flying time): the global ΔV half-width beats every per-point one."""
    legs, _ = simulate_legs(seed=4, leg_sd_kt=0.6)
    sols, _ = solve_points(legs)
    fit = fit_legs(legs, initial_winds=_start(legs))
    _, half = fit.delta_v_kt([s.ias_kt for s in sols])
    assert np.all(half < [s.dv_half_kt for s in sols])


def test_compressible_delta_v_reduces_to_the_model():
    """ΔV by the CAS law: with k = 0 none; at 100 kt, Δp/q_c = 1 % gives ≈ +0.5 % of V_c."""
    model = get_model("constant")
    assert abs(delta_v_kt(model, [0.0], 100.0, "compressible")) < 1e-12
    assert delta_v_kt(model, [0.01], 100.0, "compressible") == pytest.approx(0.5, rel=0.02)


def test_to_dict_has_the_identify_form():
    legs, _ = simulate_legs(seed=2)
    d = fit_legs(legs, initial_winds=_start(legs)).to_dict()
    assert {"model", "parameters", "covariance", "n_samples", "converged", "warnings",
            "airspeed_correction"} <= set(d)
    assert set(d["parameters"]) == {"k1", "k2"}
    assert set(d["parameters"]["k1"]) >= {"value", "std"}
    assert d["n_samples"] == legs.n and d["air_data"] == "compressible"
    row = d["airspeed_correction"][0]
    assert {"vi_kt", "dv_kt", "dv_2sigma_kt"} <= set(row) and row["vi_kt"] == 70.0
    assert d["airspeed_correction"][-1]["vi_kt"] == 160.0
    assert len(d["winds"]) == 1 and d["winds"][0]["group"].endswith(" ft")


def test_wind_groups_by_band_and_point():
    legs, _ = simulate_legs(ias_kt=(80, 120), tracks_deg=(0, 120, 240))
    assert len(wind_groups(legs, "per-band")[1]) == 1
    group, labels = wind_groups(legs, "per-point")
    assert labels == ["point 1", "point 2"] and list(group) == [0, 0, 0, 1, 1, 1]


def test_too_few_legs_refused_with_counts():
    legs, _ = simulate_legs(ias_kt=(80, 120), tracks_deg=(0, 120, 240), state_sd=False)
    with pytest.raises(ObservabilityError, match=r"6 legs cannot determine 2 model coefficients "
                                                 r"and 2 winds \(per point\): 7 legs needed"):
        fit_legs(legs, wind="per-point")


def test_one_speed_cannot_separate_two_coefficients():
    legs, _ = simulate_legs(ias_kt=(100, 100, 100), tracks_deg=(0, 120, 240))
    with pytest.raises(ObservabilityError, match="1 indicated airspeed cannot determine the 2 "):
        fit_legs(legs, model="inverse")


@pytest.mark.parametrize("kwargs, match", [({"model": "cubic"}, "model 'cubic' is not one of"),
                                           ({"wind": "global"}, "wind 'global' is not one of")])
def test_bad_choices(kwargs, match):
    legs, _ = simulate_legs(seed=1)
    with pytest.raises(PitotcalError, match=match):
        fit_legs(legs, **kwargs)


def _join(a, b):
    """Two leg sets as one file (b's points relabelled)."""
    from dataclasses import replace
    return replace(a, point=a.point + tuple(f"b{p}" for p in b.point),
                   **{f: np.r_[getattr(a, f), getattr(b, f)]
                      for f in ("ias_kt", "qci_pa", "pressure_alt_m", "oat_k", "groundspeed_mps",
                                "track_deg", "duration_s", "groundspeed_sd_mps")})


def test_two_altitude_bands_two_winds_recovered():
    """Points at 3,000 and 8,000 ft in different winds: two bands, each wind within 3σ."""
    low, t_low = simulate_legs(ias_kt=(70, 100, 130, 160), pressure_alt_ft=3000.0,
                               wind_speed_kt=10.0, wind_from_deg=200.0, seed=31)
    high, t_high = simulate_legs(ias_kt=(80, 110, 140), pressure_alt_ft=8000.0,
                                 wind_speed_kt=25.0, wind_from_deg=290.0, seed=32)
    legs = _join(low, high)
    group, labels = wind_groups(legs, "per-band")
    assert len(labels) == 2 and list(group) == [0] * low.n + [1] * high.n
    fit = fit_legs(legs, initial_winds=_start(legs))
    for j, t in enumerate((t_low, t_high)):
        err = fit.winds_ne_mps[j] - [t.wind_n_mps, t.wind_e_mps]
        sd = np.sqrt(np.diag(fit.winds_cov)[2 * j:2 * j + 2])
        assert np.all(np.abs(err) < 3 * sd)
    z = (fit.coefficients - np.array(LEGS_TRUE_K)) / np.sqrt(np.diag(fit.coef_cov))
    assert np.all(np.abs(z) < 3)
