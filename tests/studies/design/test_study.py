"""The `design` study at full size (slow): coverage of the flown designs, the prediction
against what identify reports, and the gain against the information bound."""

import pytest
from pitotcal.studies.catalog import run_study


@pytest.mark.slow
def test_design_study_full_size(tmp_path):
    summary = run_study("design", out_dir=tmp_path)       # 20 seeds per case
    assert summary["n_failed"] == 0, summary["errors"]
    for design, entries in summary["by_design"].items():
        at_240 = entries["240"]
        assert 0.88 <= at_240["coverage"] <= 1.0, (design, at_240)
        # identify's median reported bound against the design's prediction (measured 0.94-1.18
        # at 20 seeds, 0.91-1.08 at 60) and against identify's own covariance on drawn
        # residuals (0.89-0.99 at 20 seeds)
        assert 0.8 < at_240["dv_2sigma_range_kt"] / at_240["predicted_kt"] < 1.3, design
        assert 0.75 < at_240["dv_2sigma_range_kt"] / at_240["emulated_kt"] < 1.25, design
    bound = summary["information_bound"]
    # the target (15% below two-speed at 240 s, or its value in 75% of the time) lies
    # beyond the information bound at the T-2 acceleration limit: 5.4%, 219 s
    assert bound["bound_gain_at_240s"] < 0.15
    assert bound["bound_time_to_reference_s"] > 0.75 * 240.0
    for design in ("optimal", "optimal-2-level"):
        assert summary["by_design"][design]["240"]["predicted_kt"] >= bound["bound_kt"]["240"]
        # flown, no design beats the bound by more than the paired ratio's 20-seed scatter
        assert summary[f"{design}_gain_at_240s"] < bound["bound_gain_at_240s"] + 0.1, design


def test_information_bound_caps_the_gain_at_the_acceleration_limit():
    """Under the design's noise model no two-level schedule (up to 12 alternating dwells, any
    share) at the T-2 acceleration limit of 1 m/s² comes within the issue's 15% of two-speed at
    240 s; with speed changes at once (no ramps) many alternations would."""
    from pitotcal.studies.design.study import information_bound_kt, predicted_kt

    reference = predicted_kt("two-speed", 240.0)
    bound, _, _ = information_bound_kt(240.0)
    assert 0.0 < 1.0 - bound / reference < 0.15
    no_ramps, order, _ = information_bound_kt(240.0, 1e3)
    assert 1.0 - no_ramps / reference >= 0.15 and order.count("-") >= 7
    # the default design (at most five dwells) is no better than the bound
    assert bound <= predicted_kt("optimal-2-level", 240.0) <= 1.02 * reference


def test_emulated_bound_is_the_plain_covariance_for_white_noise():
    """With (almost) no turbulence the residuals are white and identify's covariance is the
    plain s^2 (J^T J)^-1, s^2 the mean of the white variances (transducer and GPS noise through
    the wind sensitivities) on the emulator's 0.2-s grid: its reported bound, within 1%."""
    import numpy as np
    from pitotcal.studies.engine.common import get_plan
    from pitotcal.studies.design.reported import emulated_reported_kt

    from pitotcal.core.information import delta_v_band_kt, qci_sensitivities
    from pitotcal.core.models import get_model
    from pitotcal.core.units import isa_density_kgm3

    plan = get_plan(profile="two-speed", duration_s=240.0)
    grid = np.linspace(72.0, 98.0, 7)
    median, mean = emulated_reported_kt(plan, 1e-6, grid, draws=20, seed=1)
    t = np.arange(plan.time_s[0], plan.time_s[-1], 0.2)
    model, k = get_model("inverse"), (0.02, -15.0)
    jac = qci_sensitivities(np.interp(t, plan.time_s, plan.tas_mps),
                            np.interp(t, plan.time_s, np.unwrap(np.radians(plan.heading_deg))),
                            float(isa_density_kgm3(244.0)), model, k, (0.0, 0.0))
    s2 = np.mean(0.5 ** 2 / (0.2 * 50.0) + np.sum(jac[:, 2:] ** 2, axis=1) * 0.05 ** 2)
    plain = delta_v_band_kt(model, k, s2 * np.linalg.inv(jac.T @ jac)[:2, :2], grid).max()
    assert abs(median / plain - 1.0) < 0.01 and abs(mean / plain - 1.0) < 0.01
