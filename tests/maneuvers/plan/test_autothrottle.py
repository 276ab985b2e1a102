"""Auto-throttle: the PI tuning and the linear check (plain numpy) against python-control, and
tracking within the paper's +-5 KCAS."""

import numpy as np
import pytest
from pitotcal.maneuvers.plan.autothrottle import (
    autothrottle_report,
    check_autothrottle,
    speed_plant,
    tune_autothrottle,
)
from plans import circle_plan

from pitotcal.core.errors import PitotcalError
from pitotcal.core.plan import Plan
from pitotcal.core.airdata import qc_from_cas_pa
from pitotcal.core.speeds import cas_from_tas_mps, tas_from_cas_mps
from pitotcal.core.units import kt_to_mps


def step_pause_plan(levels_kt=(70.0, 80.0, 90.0, 100.0), dwell_s=50.0, accel_mps2=1.0,
                    altitude_m=244.0, step_s=0.5):
    """A CAS schedule only (the lateral columns are unused by the speed loop)."""
    cas = [kt_to_mps(levels_kt[0])] * int(dwell_s / step_s)
    for v in levels_kt[1:]:
        target = kt_to_mps(v)
        while cas[-1] < target:
            cas.append(min(cas[-1] + accel_mps2 * step_s, target))
        cas += [target] * int(dwell_s / step_s)
    cas = np.array(cas)
    t = np.arange(cas.size) * step_s
    zeros = np.zeros(t.size)
    return Plan(time_s=t, north_m=zeros, east_m=zeros, alt_m=zeros + altitude_m,
                heading_deg=zeros, bank_deg=zeros, tas_mps=tas_from_cas_mps(cas, altitude_m),
                cas_mps=cas, qc_pa=qc_from_cas_pa(cas))


def test_tuning_meets_phase_margin_and_is_stable():
    import control

    loop = tune_autothrottle(44.0, phase_margin_deg=60.0)
    assert loop.phase_margin_deg == pytest.approx(60.0, abs=0.5)
    assert loop.gain_margin_db > 6.0
    assert 0.1 < loop.crossover_rad_s < 2.0
    closed = control.feedback(control.tf([loop.kp, loop.ki], [1, 0])
                              * speed_plant(44.0, loop.engine_lag_s, loop.lift_to_drag), 1)
    assert np.all(np.real(closed.poles()) < 0)
    assert loop.drag_slope_per_s == pytest.approx(2 * 9.80665 / (8.0 * 44.0))


@pytest.mark.parametrize("kwargs, match", [
    ({"trim_tas_mps": 0.0}, "trim_tas_mps 0 must be > 0"),
    ({"trim_tas_mps": 40.0, "engine_lag_s": -1.0}, "engine_lag_s -1 must be > 0"),
    ({"trim_tas_mps": 40.0, "phase_margin_deg": 95.0}, "phase_margin_deg 95 must be > 0 and < 90"),
])
def test_bad_tuning_arguments(kwargs, match):
    with pytest.raises(PitotcalError, match=match):
        tune_autothrottle(**kwargs)


@pytest.mark.parametrize("name, plan", [
    ("continuous", circle_plan()),
    ("step-pause", step_pause_plan()),
])
@pytest.mark.parametrize("turbulence", [0.0, 0.5])
def test_hand_plans_within_5_kcas(name, plan, turbulence):
    check = check_autothrottle(plan, turbulence_mps=turbulence, seed=1)
    assert check.success, check.summary()
    assert check.max_error_kt < 5.0
    if turbulence == 0.0 and name == "continuous":
        # feed-forward carries the slow ramp; what is left is the start (already ramping at t=0)
        assert check.max_error_kt < 0.5
        assert check.rms_error_kt < 0.1
    assert check.error_kt.shape == check.time_s.shape
    assert "KCAS" in check.summary()


@pytest.mark.parametrize("profile", ["continuous", "step-pause", "two-speed"])
def test_default_plans_within_5_kcas(profile):
    from pitotcal.maneuvers.plan.planner import plan_maneuver

    plan = plan_maneuver(profile=profile)
    check = check_autothrottle(plan, turbulence_mps=0.5, seed=0)
    assert check.success and check.max_error_kt < 5.0, check.summary()


def _tune_with_python_control(trim_tas_mps, engine_lag_s=1.5, lift_to_drag=8.0,
                              phase_margin_deg=60.0, integral_ratio=0.2):
    """The reference design: crossover by brentq, Kp by control.evalfr, margins by
    control.stability_margins (what tune_autothrottle computed before it was plain numpy)."""
    import control
    from scipy.optimize import brentq

    plant = speed_plant(trim_tas_mps, engine_lag_s, lift_to_drag)
    x_u = 2.0 * 9.80665 / (lift_to_drag * trim_tas_mps)
    budget = np.radians(180.0 - phase_margin_deg) - np.arctan(integral_ratio)
    w_c = brentq(lambda w: np.arctan(engine_lag_s * w) + np.arctan(w / x_u) - budget, 1e-6, 1e3)
    shape = control.tf([1.0, integral_ratio * w_c], [1.0, 0.0])
    kp = 1.0 / abs(complex(control.evalfr(shape * plant, 1j * w_c)))
    gm, pm, _, _, wc = control.stability_margins(kp * shape * plant)[:5]
    return kp, kp * integral_ratio * w_c, wc, pm, 20.0 * np.log10(gm) if np.isfinite(gm) else np.inf


@pytest.mark.parametrize("trim, options", [
    (30.0, {}), (44.2, {}), (80.0, {}),
    (44.2, {"engine_lag_s": 0.5, "phase_margin_deg": 45.0}),
    (44.2, {"lift_to_drag": 15.0, "phase_margin_deg": 80.0}),
    # w_i above 1/tau + X_u: the phase crosses -180° and the gain margin is finite
    (44.2, {"integral_ratio": 5.0, "phase_margin_deg": 10.0, "engine_lag_s": 3.0}),
])
def test_numpy_tuning_agrees_with_python_control(trim, options):
    loop = tune_autothrottle(trim, **options)
    kp, ki, wc, pm, gm_db = _tune_with_python_control(trim, **options)
    assert loop.kp == pytest.approx(kp, rel=1e-10) and loop.ki == pytest.approx(ki, rel=1e-10)
    assert loop.crossover_rad_s == pytest.approx(wc, rel=1e-6)
    assert loop.phase_margin_deg == pytest.approx(pm, abs=1e-6)
    assert loop.gain_margin_db == pytest.approx(gm_db, rel=1e-6)
    assert np.isfinite(loop.gain_margin_db) == (options.get("integral_ratio", 0.2) > 1)


def _check_with_python_control(plan, turbulence_mps, seed, rate_hz=10.0):
    """CAS (m/s) of the linear loop by superposition of python-control forced responses, with
    the gust of maneuvers.turbulence.dryden_gusts (the check's implementation before numpy)."""
    import control
    from pitotcal.maneuvers.turbulence import dryden_gusts, dryden_scales

    t = np.arange(plan.time_s[0], plan.time_s[-1] + 0.5 / rate_hz, 1.0 / rate_hz)
    tas_ref = np.interp(t, plan.time_s, plan.tas_mps)
    loop = tune_autothrottle(0.5 * (tas_ref.min() + tas_ref.max()))
    v0, x_u = loop.trim_tas_mps, loop.drag_slope_per_s
    plant = speed_plant(v0, loop.engine_lag_s, loop.lift_to_drag)
    pi = control.tf([loop.kp, loop.ki], [1.0, 0.0])
    sens = control.feedback(1, pi * plant)
    ff = x_u * (tas_ref - v0) + np.gradient(tas_ref, t)
    ff = ff[np.minimum(np.arange(t.size) + round(loop.engine_lag_s * rate_hz), t.size - 1)]
    ref = tas_ref - v0
    dv = (ref[0] + control.forced_response(control.feedback(pi * plant, 1), t, ref - ref[0]).outputs
          + control.forced_response(sens * plant, t, ff - ff[0]).outputs)
    if turbulence_mps > 0:
        scales = dryden_scales(float(np.mean(plan.alt_m)), turbulence_mps)
        gust = dryden_gusts(t.size, 1.0 / rate_hz, scales, float(np.mean(tas_ref)),
                            np.random.default_rng(seed))[:, 0]
        dv = dv + control.forced_response(control.tf([-1.0, 0.0], [1.0, x_u]) * sens, t,
                                          gust).outputs
    # CAS by the standard law at the plan's altitude, as the check converts
    return cas_from_tas_mps(v0 + dv, np.interp(t, plan.time_s, plan.alt_m))


@pytest.mark.parametrize("turbulence, seed", [(0.0, 0), (0.5, 0), (1.5, 3)])
def test_numpy_check_agrees_with_python_control(turbulence, seed):
    plan = step_pause_plan()
    check = check_autothrottle(plan, turbulence_mps=turbulence, seed=seed)
    np.testing.assert_allclose(check.cas_mps, _check_with_python_control(plan, turbulence, seed),
                               rtol=0, atol=1e-10)


def test_report_line_of_the_default_plan():
    """`pitotcal plan` prints this line; unchanged since the check needed python-control."""
    from pitotcal.maneuvers.plan.planner import plan_maneuver

    assert autothrottle_report(plan_maneuver()) == (
        "auto-throttle check (PI, Kp 0.392 1/s, Ki 0.0274 1/s², 60° phase margin): CAS error "
        "max 0.4 kt in still air, 2.4 kt in 0.5 m/s turbulence: within ±5 KCAS")
