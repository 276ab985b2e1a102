"""The `coverage-tails` study (issue 26, item 6): lean checks in CI, the full size marked slow."""

import json
import types

import numpy as np
import pytest
from pitotcal.core.models import delta_v_kt, get_model
from pitotcal.studies.accuracy.tails import joint_inside, task
from pitotcal.studies.catalog import run_study
from pitotcal.studies.engine.common import get_flight

UP_AND_DOWN = {"return_leg": True}


def _fake_result(cov, k=(0.02, -15.0)):
    return types.SimpleNamespace(model="inverse", params=np.array([*k, 5.0, 270.0]),
                                 covariance=np.asarray(cov, dtype=float),
                                 air_data="compressible")


def test_joint_inside_one_direction_is_one_row():
    """ΔV rows driven by k1 alone move together: all inside at once exactly when one is,
    0.9545 (4000 draws: ±0.007)."""
    cov = np.zeros((4, 4))
    cov[0, 0] = 0.01 ** 2
    p = joint_inside(_fake_result(cov), np.linspace(70.0, 100.0, 16), seed=3)
    assert p == pytest.approx(0.9545, abs=0.015)


def test_joint_inside_matches_direct_draws():
    """The expected 'every row inside ±2σ' chance of a real flight's covariance (seed 54 of
    the up-and-down plan, 0.5 m/s) against a direct Monte Carlo of the exact, nonlinear ΔV at
    coefficients drawn from that covariance; both below 0.9545, as the rows are not one."""
    from pitotcal.estimation import identify

    flight, _ = get_flight(UP_AND_DOWN, {"turbulence_mps": 0.5, "air_data": "compressible"}, 54)
    result = identify(flight)
    rows = result.correction_table()
    vi = np.array([r["vi_kt"] for r in rows])
    band = np.array([r["dv_2sigma_kt"] for r in rows])
    expected = joint_inside(result, vi, seed=1)
    model = get_model(result.model)
    rng = np.random.default_rng(7)
    k_hat = result.params[:2]
    draws = rng.multivariate_normal(k_hat, result.covariance[:2, :2], size=4000)
    dv_hat = delta_v_kt(model, k_hat, vi, result.air_data)
    inside = [np.all(np.abs(delta_v_kt(model, k, vi, result.air_data) - dv_hat) <= band)
              for k in draws]
    assert expected == pytest.approx(np.mean(inside), abs=0.02)
    assert 0.8 < expected < 0.94


def test_seed_54_scored_against_truth():
    """The campaign's worst flight, reproduced: `plan --return`, `simulate --seed 54`,
    `identify` put k1 3.8σ and k2 3.6σ from truth (4.1σ and 3.9σ before the noise model's
    slow terms got their floor: its σ was the cell's 0.7th percentile; a turbulence
    realisation: the same seed in calm air is within 1.3σ); the ΔV rows tilt about the
    middle, 5 of 17 inside ±2σ and 10 inside U, where exact bands would hold all 17 at once
    87 % of the time."""
    row = task(54, "up-and-down", 0.5)
    assert row["k1_z"] == pytest.approx(-3.76, abs=0.05)
    assert row["k2_z"] == pytest.approx(3.61, abs=0.05)
    assert (row["n_rows"], row["rows_in_2sigma"], row["rows_in_u"]) == (17, 5, 10)
    assert abs(row["row_z_mid"]) < 1.0 < 2.5 < abs(row["row_z_low"])
    assert row["joint_expected_2sigma"] == pytest.approx(0.87, abs=0.03)
    calm, _ = get_flight(UP_AND_DOWN, {"turbulence_mps": 0.0, "air_data": "compressible"}, 54)
    from pitotcal.estimation import identify

    res = identify(calm)
    z = (res.params[0] - 0.02) / np.sqrt(res.covariance[0, 0])
    assert abs(z) < 1.5


def test_coverage_tails_lean(tmp_path):
    """One flight through `pitotcal study`'s path: the table, the summary and the figure."""
    summary = run_study("coverage-tails", runs=1, out_dir=tmp_path, workers=0, quick=True)
    assert summary["n_rows"] == 1 and not summary["errors"]
    on_disk = json.loads((tmp_path / "coverage-tails.json").read_text())
    (cell,) = on_disk["cells"]
    assert (cell["plan"], cell["turbulence_mps"], cell["n_flights"]) == ("up-and-down", 0.5, 1)
    assert 0.0 <= cell["row_coverage_2sigma"] <= 1.0
    assert 0.5 < cell["all_rows_in_2sigma_expected"] < 0.9545
    assert set(cell["parameters"]) >= {"k1", "k2", "wind_speed_mps", "wind_speed_mps_process"}
    assert (tmp_path / "coverage-tails.png").exists()
    assert "rows inside 2σ" in summary["headline"]


@pytest.mark.slow
def test_coverage_tails_full_size(tmp_path):
    """150 flights per cell, 600 in all (11 min on 2 workers; docs/measured.md has the table):
    the rows' pointwise ±2σ hold truth 92-98 % of the time, U at least as often; the share of
    flights with every row inside agrees with what their own covariances predict (~87 %, not
    95 %) within 3 standard deviations; k1 and k2 rms z 0.85-1.2."""
    summary = run_study("coverage-tails", runs=150, out_dir=tmp_path, workers=2, seed=0)
    assert not summary["errors"] and len(summary["cells"]) == 4
    for c in summary["cells"]:
        name = (c["plan"], c["turbulence_mps"])
        assert 0.92 <= c["row_coverage_2sigma"] <= 0.98, name
        assert c["row_coverage_u"] >= c["row_coverage_2sigma"], name
        assert 0.80 <= c["all_rows_in_2sigma_expected"] <= 0.92, name
        assert abs(c["all_rows_in_2sigma_z"]) < 3.0, name
        for p in ("k1", "k2"):
            assert 0.85 <= c["parameters"][p]["rms_z"] <= 1.2, (name, p)
