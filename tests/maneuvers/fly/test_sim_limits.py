"""Issue 15: every simulator option has an upper bound that says why, each bound is flown
without overflow, and the values suggested in a refusal are computed from the real limits and
pass them."""

import numpy as np
import pytest
from pitotcal.maneuvers.plan.request import MAX_DURATION_S, MAX_NODES, min_dt_s
from pitotcal.maneuvers.plan.planner import plan_maneuver
from pitotcal.maneuvers.fly.flyable import check_samples as _check_samples
from pitotcal.maneuvers.fly.options import MAX_SAMPLES, MIN_SAMPLES, SIM_LIMITS
from pitotcal.maneuvers.fly.simulator import simulate
from plans import circle_plan

from pitotcal.core.errors import PitotcalError


@pytest.fixture(scope="module")
def plan():
    return circle_plan(duration_s=30.0)


def _kwargs(name, value):
    return {"wind_drift_mps2": (value, 0.0)} if name == "wind_drift_mps2" else {name: value}


@pytest.mark.parametrize("name", sorted(SIM_LIMITS))
def test_above_the_bound_is_refused_with_the_reason(plan, name):
    hi, why = SIM_LIMITS[name]
    param = "wind_drift_n_mps2" if name == "wind_drift_mps2" else name
    with pytest.raises(PitotcalError, match=rf"{param} {hi * 10:g} must be .*<= {hi:g} "
                                            rf"\({why}\)") as info:
        simulate(plan, **_kwargs(name, hi * 10))
    assert info.value.param == param


@pytest.mark.parametrize("name", sorted(SIM_LIMITS))
def test_the_bound_itself_is_flown_to_finite_numbers(plan, name):
    hi, _ = SIM_LIMITS[name]
    flight, _ = simulate(plan, seed=2, rate_hz=10.0, **_kwargs(name, hi))
    for column in (flight.qci_pa, flight.gps_vn_mps, flight.gps_ve_mps, flight.rho_kgm3):
        assert np.all(np.isfinite(column))


def test_turbulence_100_is_one_line_naming_the_flag(tmp_path, capsys):
    from pitotcal.cli import main
    from pitotcal.io.plan_csv import write_plan

    path = write_plan(circle_plan(duration_s=30.0), tmp_path / "plan.csv")
    status = main(["simulate", str(path), "-o", str(tmp_path / "f.csv"),
                   "--turbulence-mps", "100"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("pitotcal simulate: --turbulence-mps 100 must be >= 0 and <= 10 "
                          "(MIL-F-8785C")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.csv"]


@pytest.mark.parametrize("span_s", [0.5, 7.0, 30.0, 240.0, 3333.3, 1e4, 4.9e5])
@pytest.mark.parametrize("rate_hz", [1e-6, 1e9])
def test_the_suggested_rate_passes(span_s, rate_hz):
    import re

    with pytest.raises(PitotcalError, match="use at (least|most)") as info:
        _check_samples(rate_hz, span_s)
    suggested = float(re.search(r"use at (?:least|most) ([\d.e+-]+) Hz", str(info.value))[1])
    _check_samples(suggested, span_s)               # no error
    assert MIN_SAMPLES <= span_s * suggested + 1 <= MAX_SAMPLES


def test_a_plan_longer_than_max_samples_seconds_gets_a_rate_above_zero():
    """Before issue 15 the suggestion was floored to whole Hz: "use at most 0 Hz"."""
    with pytest.raises(PitotcalError, match=r"use at most 0.0499 Hz"):
        _check_samples(1.0, 1e7)


@pytest.mark.parametrize("duration_s", [3000.1, 9000.0, 10001.0, 14400.0])
def test_the_suggested_dt_passes_and_is_never_the_value_refused(duration_s):
    dt_s = min_dt_s(duration_s)
    assert duration_s / dt_s <= MAX_NODES and dt_s <= duration_s / 2
    refused = duration_s / MAX_NODES * 0.9999
    with pytest.raises(PitotcalError, match=rf"use at least {dt_s:g} s") as info:
        plan_maneuver("continuous", 60.0, 100.0, 600.0, 300.0, duration_s, 30.0, 5.0, 270.0,
                      dt_s=refused)
    assert info.value.param == "dt_s"


def test_a_duration_beyond_the_longest_maneuver_says_why():
    with pytest.raises(PitotcalError, match=rf"duration_s 1e\+09 must be <= {MAX_DURATION_S:g} "
                                            "s: a calibration maneuver is minutes long"):
        plan_maneuver("continuous", 60.0, 100.0, 600.0, 300.0, 1e9, 30.0, 5.0, 270.0,
                      dt_s=333333.0)


def test_a_pressure_error_beyond_half_of_qc_is_refused_naming_the_flags(tmp_path, capsys):
    from pitotcal.cli import main
    from pitotcal.io.plan_csv import write_plan

    path = write_plan(circle_plan(duration_s=30.0), tmp_path / "plan.csv")
    status = main(["simulate", str(path), "-o", str(tmp_path / "f.csv"), "--k2=-1e6"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1
    assert err.startswith("pitotcal simulate: --k1 0.02, --k2 -1e+06: the inverse pressure error "
                          "dp/qc reaches 1.26e+03 on the plan's q_c 797-")
    flight, _ = simulate(circle_plan(duration_s=30.0), k=(0.3, -100.0), rate_hz=5.0)
    assert flight.qci_pa.min() > 0
