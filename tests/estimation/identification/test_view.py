"""Result presentation: JSON of INTERFACES §3, correction table, summary text, figure."""

import json

import numpy as np
import pytest
from pitotcal.estimation.identification.record import to_dict
from pitotcal.estimation.identification.view import correction_table, default_step_kt, flown_vi_kt
from pitotcal.estimation.identification.result import IdentificationResult
from synthetic import synthetic_flight

from pitotcal.core.units import RHO0_KGM3, kt_to_mps, mps_to_kt

K1, K1_STD = 0.02, 0.001


def hand_result(cov_extra=None, warnings=("a warning",), candidates=(), success=True):
    """A constant-model result built by hand: k1 = 0.02, wind 5 m/s from 270 deg (blowing east)."""
    vi_kt = np.linspace(70.0, 100.0, 301)
    qci = 0.5 * RHO0_KGM3 * kt_to_mps(vi_kt) ** 2
    cov_int = np.diag([K1_STD ** 2, 0.04 ** 2, 0.03 ** 2])
    params = np.array([K1, 5.0, 270.0])
    cov = np.diag([K1_STD ** 2, 0.03 ** 2, np.degrees(0.04 / 5.0) ** 2])
    if cov_extra is not None:
        cov = cov + cov_extra
    return IdentificationResult(
        model="constant", param_names=("k1", "wind_speed_mps", "wind_from_deg"), params=params,
        covariance=cov, covariance_plain=cov / 16.0, internal_params=np.array([K1, 0.0, 5.0]),
        internal_covariance=cov_int, internal_covariance_plain=cov_int / 16.0, success=success,
        message="Solve_Succeeded" if success else "Maximum_Iterations_Exceeded", iterations=7,
        n_samples=qci.size, noise_std_pa=0.5, gps_noise_std_mps=0.05,
        time_s=np.arange(qci.size) * 0.02, qci_pa=qci, rho_kgm3=np.full(qci.size, 1.2),
        residuals_pa=np.sin(np.arange(qci.size)), warnings=tuple(warnings),
        candidates=tuple(candidates), criterion="BIC" if candidates else None,
        timing_s={"build": 0.01, "solve": 0.02, "covariance": 0.01})


def test_to_dict_has_the_interface_keys_and_valid_json():
    d = to_dict(hand_result())
    for key in ("model", "parameters", "covariance", "n_samples", "converged", "warnings",
                "airspeed_correction"):
        assert key in d
    assert d["model"] == "constant" and d["n_samples"] == 301 and d["converged"] is True
    assert list(d["parameters"]) == ["k1", "wind_speed_mps", "wind_from_deg"]
    assert d["parameters"]["k1"] == {"value": K1, "std": pytest.approx(K1_STD),
                                     "std_plain": pytest.approx(K1_STD / 4), "unit": ""}
    assert d["covariance"]["names"] == ["k1", "wind_speed_mps", "wind_from_deg"]
    assert np.array(d["covariance"]["matrix"]).shape == (3, 3)
    assert d["warnings"] == ["a warning"]
    for key in ("noise_std_pa", "gps_noise_std_mps", "candidates", "criterion", "timing_s",
                "message", "iterations", "covariance_plain", "formula"):
        assert key in d
    assert set(d["airspeed_correction"][0]) >= {"vi_kt", "dv_kt", "dv_2sigma_kt"}
    assert json.loads(json.dumps(d, allow_nan=False)) == d


def test_nan_becomes_null():
    extra = np.zeros((3, 3))
    extra[0, 1] = extra[1, 0] = np.nan
    d = to_dict(hand_result(cov_extra=extra))
    text = json.dumps(d, allow_nan=False)
    assert d["covariance"]["matrix"][0][1] is None and "NaN" not in text


def test_correction_table_matches_the_constant_model_by_hand():
    rows = correction_table(hand_result())
    lo, hi = flown_vi_kt(hand_result())
    assert (lo, hi) == pytest.approx((70.0, 100.0))
    assert rows[0]["vi_kt"] == pytest.approx(70.0) and rows[-1]["vi_kt"] == pytest.approx(100.0)
    assert [r["vi_kt"] for r in rows] == pytest.approx(np.arange(70.0, 100.1, 2.0))
    vi = np.array([r["vi_kt"] for r in rows])
    # constant model: q_c = q_ci / (1 - k1)  =>  V_c = V_i / sqrt(1 - k1)
    np.testing.assert_allclose([r["dv_kt"] for r in rows], vi * (1 / np.sqrt(1 - K1) - 1),
                               rtol=1e-9)
    dband = 2 * K1_STD * vi * 0.5 * (1 - K1) ** -1.5          # delta method, 2 sigma
    np.testing.assert_allclose([r["dv_2sigma_kt"] for r in rows], dband, rtol=1e-5)
    np.testing.assert_allclose([r["dv_2sigma_plain_kt"] for r in rows], dband / 4, rtol=1e-5)
    np.testing.assert_allclose([r["vc_kt"] for r in rows], vi / np.sqrt(1 - K1), rtol=1e-9)


@pytest.mark.parametrize("step, first_rows", [(5.0, [70.0, 75.0, 80.0]), (3.0, [70.0, 72.0, 75.0])])
def test_correction_table_step(step, first_rows):
    rows = correction_table(hand_result(), step_kt=step)
    assert [r["vi_kt"] for r in rows[:3]] == pytest.approx(first_rows)
    assert rows[-1]["vi_kt"] == pytest.approx(100.0)


@pytest.mark.parametrize("step", [0.0, -1.0, float("nan"), "2"])
def test_correction_table_rejects_bad_step(step):
    with pytest.raises(ValueError, match="step_kt=.* must be a positive number of knots"):
        correction_table(hand_result(), step_kt=step)


@pytest.mark.parametrize("span, step", [(10, 1.0), (30, 2.0), (100, 5.0), (200, 10.0)])
def test_default_step(span, step):
    assert default_step_kt(span) == step


def test_summary_golden_lines():
    cands = ({"model": "constant", "bic": 10.0, "params": {"k1": 0.02}},
             {"model": "inverse", "bic": 12.5})
    text = hand_result(candidates=cands).summary()
    lines = text.splitlines()
    assert lines[0] == "Pressure-error model: constant   dp/qc = k1"
    assert "301 samples, solver converged in 7 iterations (Solve_Succeeded)" in lines[1]
    k1_line = next(line for line in lines if line.strip().startswith("k1"))
    assert k1_line.split() == ["k1", "0.02", "±0.002", "(±0.0005)"]
    wind = next(line for line in lines if "wind speed" in line)
    assert f"{mps_to_kt(5.0):.4g} kt" in wind and "= 5 m/s" in wind
    assert "270.0°" in next(line for line in lines if "wind from" in line)
    assert "KIAS" in text and "KCAS" in text and "ΔV kt" in text
    table = [line for line in lines if line[:9].strip().replace(".", "").isdigit()]
    assert len(table) == 16 and table[0].split()[0] == "70.0"
    assert "* constant" in text and "bic=10" in text and "params" not in text
    assert lines[-2:] == ["Warnings:", "  - a warning"]


def test_summary_says_when_the_solver_failed():
    text = hand_result(success=False).summary()
    assert "DID NOT CONVERGE" in text and "Maximum_Iterations_Exceeded" in text


def test_plot_writes_a_readable_png(tmp_path):
    path = tmp_path / "fig.png"
    fig = hand_result().plot(path)
    assert path.stat().st_size > 20_000
    assert len(fig.axes) >= 4
    assert f"wind {mps_to_kt(5.0):.1f}" in fig._suptitle.get_text()
    assert "from 270°" in fig._suptitle.get_text()


def test_real_identification_round_trips_through_json(tmp_path):
    from pitotcal.estimation import identify

    flight, truth = synthetic_flight(seed=4, n=4000, turbulence_mps=0.3, gps_rate_hz=5.0,
                                     gps_noise_mps=0.05)
    result = identify(flight, model="inverse")
    d = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    assert d["model"] == "inverse" and d["n_samples"] == 4000
    assert list(d["parameters"]) == ["k1", "k2", "wind_speed_mps", "wind_from_deg"]
    for name, true in truth["parameters"].items():
        p = d["parameters"][name]
        assert abs(p["value"] - true) < 3 * p["std"] + 1e-9, name
        assert p["std"] >= p["std_plain"] > 0
    vi = [row["vi_kt"] for row in d["airspeed_correction"]]
    assert 69.5 < vi[0] < 71 and 99 < vi[-1] < 100.5
    result.plot(tmp_path / "real.png")
    assert (tmp_path / "real.png").stat().st_size > 20_000
