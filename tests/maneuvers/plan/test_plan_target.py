"""`target_2sigma_kt`: the plan meets the target on the path it plans (the prediction it
records), or says that it does not and what would."""

import warnings

import pytest

from pitotcal.maneuvers import plan_maneuver
from pitotcal.maneuvers.plan import planner


def test_the_recorded_prediction_meets_the_target():
    # the speed design alone gave 320 s, whose path predicts 0.608 kt
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        plan = plan_maneuver(design="optimal", design_options={"target_2sigma_kt": 0.6})
    assert plan.settings["target_2sigma_kt"] == 0.6
    assert plan.settings["predicted_dv_2sigma_kt"] <= 0.6
    assert 320.0 < plan.time_s[-1] < 360.0


def test_a_missed_target_is_said_with_a_duration(monkeypatch):
    monkeypatch.setattr(planner, "_TARGET_ROUNDS", 0)
    with pytest.warns(UserWarning, match=r"target_2sigma_kt 0.6 kt is not met: the path planned "
                                         r"predicts 0.6\d+ kt in 3\d\d s; a plan of duration_s "
                                         r"3\d\d s without the target should meet it"):
        plan = plan_maneuver(design="optimal", design_options={"target_2sigma_kt": 0.6})
    assert plan.settings["predicted_dv_2sigma_kt"] > 0.6


def test_the_cli_says_the_target_is_met(tmp_path, capsys):
    from pitotcal.cli import main

    assert main(["plan", "--design", "optimal", "--target-2sigma-kt", "0.6", "--no-figures",
                 "-o", str(tmp_path / "p.csv")]) == 0
    captured = capsys.readouterr()
    assert "(target 0.6 kt: met)" in captured.out and "not met" not in captured.err
