"""The consistency test's second half (issue 15, item 2): what a maneuver cannot tell apart.

The step test's own power is tested in test_robust.py; here: the smallest detected step and
the shift it causes, checked against refits of flights with that step, and the warning on a
one-way speed sweep that a flight flown up and back down the speeds does not get.
"""

import dataclasses
import json

import numpy as np
import pytest
from pitotcal.estimation import identify
from pitotcal.estimation.robustness import consistency
from synthetic import synthetic_flight

from pitotcal.core.errors import PitotcalError
from pitotcal.core.flight import Flight
from pitotcal.core.models import delta_v_kt, get_model

HIDES = "hides in the calibration"


def _fit(flight):
    return identify(flight, air="incompressible")


def _leak(flight, size, onset_s):
    """q_ci (1 - size) from onset_s on (the simulator's `leak` fault)."""
    qci = np.where(flight.time_s >= onset_s, (1.0 - size) * flight.qci_pa, flight.qci_pa)
    return dataclasses.replace(flight, qci_pa=qci)


def _two_pass(seed, n=8000, **options):
    """Up the speed range and back down: a synthetic sweep, then a second one reversed."""
    up, truth = synthetic_flight(seed=seed, n=n, **options)
    down, _ = synthetic_flight(seed=seed + 100, n=n, **options)
    dt = up.time_s[1] - up.time_s[0]
    return Flight(time_s=np.arange(2 * n) * dt,
                  qci_pa=np.r_[up.qci_pa, down.qci_pa[::-1]],
                  gps_vn_mps=np.r_[up.gps_vn_mps, down.gps_vn_mps[::-1]],
                  gps_ve_mps=np.r_[up.gps_ve_mps, down.gps_ve_mps[::-1]],
                  rho_kgm3=np.r_[up.rho_kgm3, down.rho_kgm3], source="two-pass"), truth


@pytest.fixture(scope="module")
def sweep():
    """A one-way sweep in turbulence, and its fit."""
    flight, truth = synthetic_flight(seed=2, n=12000, turbulence_mps=0.5, gps_rate_hz=5.0,
                                     gps_noise_mps=0.1)
    return flight, truth, _fit(flight)


def test_one_way_sweep_says_it_cannot_tell(sweep):
    """Asked for 0.2 kt, the sweep says it hides a change: the scan misses one that moves ΔV
    by several bands, and a sudden one the jump test misses (below its 1 % floor) moves ΔV
    by more than 0.2 kt."""
    flight, _, _ = sweep
    result = identify(flight, air="incompressible", hides_threshold_kt=0.2)
    details = result.consistency
    hidden, sudden = details["undetected"], details["undetected_sudden"]
    assert not details["flagged"] and details["hidden"]
    assert details["hides_threshold_kt"] == 0.2
    assert hidden["dv_shift_kt"] > consistency.HIDDEN_RATIO * hidden["dv_2sigma_kt"]
    assert sudden["step"] <= hidden["step"] and 0.2 < sudden["dv_shift_kt"] < 1.0
    note = [w for w in result.warnings if HIDES in w]
    assert len(note) == 1, result.warnings
    assert f"t = {hidden['onset_s']:.0f} s" in note[0]
    assert f"{100 * hidden['step']:.1f}% up" in note[0] and "plan a return sweep" in note[0]
    assert f"{100 * sudden['step']:.1f}% up" in note[0] and "0.2 kt asked" in note[0]
    # in the JSON, strict
    out = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    assert out["consistency"]["undetected"]["power"] == consistency.POWER
    assert out["consistency"]["hidden"] is True


def test_default_threshold_keeps_quiet_when_a_leak_is_caught(sweep):
    """At the default 1 kt the same sweep says nothing: a sudden change the checks miss moves
    ΔV by less; made again at 0.2 kt from the details alone, the statement is identify's."""
    flight, _, result = sweep
    details = result.consistency
    assert details["hides_threshold_kt"] == consistency.HIDES_THRESHOLD_KT == 1.0
    assert not details["hidden"] and not [w for w in result.warnings if HIDES in w]
    again = consistency.with_hides_threshold(result, 0.2)
    asked = identify(flight, air="incompressible", hides_threshold_kt=0.2)
    assert again.consistency["hidden"] and again.warnings == asked.warnings
    assert consistency.with_hides_threshold(again, 1.0).warnings == result.warnings


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), "x"])
def test_hides_threshold_is_checked(sweep, bad):
    flight, _, result = sweep
    with pytest.raises(PitotcalError, match="`?hides_threshold_kt"):
        identify(flight, hides_threshold_kt=bad)
    with pytest.raises(PitotcalError, match="`?hides_threshold_kt"):
        consistency.with_hides_threshold(result, bad)


def test_stated_shift_is_what_a_refit_does(sweep):
    """A quarter of the stated step at the stated onset, refitted: ΔV moves by a quarter of
    the stated shift away from the clean calibration, or from the one the same change over the
    whole record gives (the shift is linear in the step; a quarter keeps ΔV's own curvature
    in k1 and k2 out of the comparison)."""
    flight, _, result = sweep
    hidden = result.consistency["undetected"]
    size, vi = 0.25 * hidden["step"], hidden["vi_kt"]
    model = get_model("inverse")
    leaky = _fit(_leak(flight, size, hidden["onset_s"]))
    after = _fit(_leak(flight, size, -1.0))
    dv = {name: delta_v_kt(model, res.coefficients, vi) for name, res in
          (("clean", result), ("leak", leaky), ("after", after))}
    # the test counts the nearer of the two calibrations over the grid; at vi either one
    moved = (abs(dv["leak"] - dv["clean"]), abs(dv["leak"] - dv["after"]))
    assert any(m == pytest.approx(0.25 * hidden["dv_shift_kt"], rel=0.15) for m in moved), moved


def test_flown_up_and_down_does_not_warn():
    """Two passes over the speeds: a step at mid-flight leaves the fit halfway, at about
    (threshold + z_power) / 2 = 2.50 bands, below HIDDEN_RATIO."""
    flight, _ = _two_pass(seed=4, turbulence_mps=0.5, gps_rate_hz=5.0, gps_noise_mps=0.1)
    result = _fit(flight)
    ratio = result.consistency["undetected"]["dv_shift_kt"] \
        / result.consistency["undetected"]["dv_2sigma_kt"]
    assert 1.8 < ratio < consistency.HIDDEN_RATIO
    assert not [w for w in result.warnings if HIDES in w or "changes during" in w]


def test_three_percent_leak_in_calm_air_is_flagged():
    flight, _ = synthetic_flight(seed=5, n=12000)
    onset = flight.time_s[flight.n // 2]
    result = _fit(_leak(flight, 0.03, onset))
    details = result.consistency
    assert details["flagged"]
    assert abs(details["onset_s"] - onset) < 0.1 * flight.time_s[-1]
    assert details["step"] == pytest.approx(0.03, abs=0.005)
    assert [w for w in result.warnings if "changes during the flight" in w]
    assert not [w for w in result.warnings if HIDES in w]


def test_calm_sweep_hides_nothing_an_indicator_shows():
    """In calm air the smallest detected step is a few tenths of a percent: whatever it does
    to ΔV stays below MIN_SHIFT_KT, so no warning even on a one-way sweep."""
    flight, _ = synthetic_flight(seed=6, n=12000)
    details = _fit(flight).consistency
    assert not details["flagged"] and not details["hidden"]
    assert details["undetected"]["dv_shift_kt"] < consistency.MIN_SHIFT_KT
    assert details["undetected"]["step"] < 0.01


# --- abrupt jumps (estimation.robustness.jumps) ------------------------------------------------------

@pytest.fixture(scope="module")
def turbulent():
    """A one-way sweep in 1 m/s turbulence with 5 Hz GPS, its fit, and the leak's onset."""
    flight, _ = synthetic_flight(seed=8, n=12000, turbulence_mps=1.0, gps_rate_hz=5.0,
                                 gps_noise_mps=0.1)
    return flight, flight.time_s[flight.n // 2 + 7]


def test_abrupt_leak_in_turbulence_is_named_at_its_sample(turbulent):
    """3 % from mid-flight in 1 m/s turbulence: the change of scale hides in the slow noise,
    the jump does not: a warning naming the sample and the size."""
    flight, onset = turbulent
    result = _fit(_leak(flight, 0.03, onset))
    jump = result.consistency["jump"]
    assert jump["flagged"] and jump["time_s"] == pytest.approx(onset)
    assert jump["step"] == pytest.approx(0.03, abs=0.01)
    note = [w for w in result.warnings if "jumps at" in w]
    assert len(note) == 1 and f"t = {onset:.2f} s" in note[0]
    assert not [w for w in result.warnings if HIDES in w]


def test_clean_turbulent_flight_has_no_jump(turbulent):
    flight, _ = turbulent
    jump = _fit(flight).consistency["jump"]
    assert not jump["flagged"] and abs(jump["z"]) < jump["threshold"]


def test_a_spike_is_not_a_jump(turbulent):
    """Two samples 5 % low and back: neither median moves, so no lasting jump."""
    from pitotcal.estimation.robustness.jumps import jump_test

    flight, onset = turbulent
    i = int(np.searchsorted(flight.time_s, onset))
    qci = flight.qci_pa.copy()
    qci[i:i + 2] *= 0.95
    warning, details = jump_test(dataclasses.replace(flight, qci_pa=qci))
    assert warning is None and not details["flagged"]
    assert jump_test(_leak(flight, 0.05, onset))[1]["flagged"]      # the same, lasting


def test_no_jump_across_a_time_gap(turbulent):
    """A 3 s gap in the record while q_ci moved 5 %: the aircraft had time, it is no jump."""
    from pitotcal.estimation.robustness.jumps import jump_test

    flight, onset = turbulent
    later = flight.time_s >= onset
    gapped = dataclasses.replace(_leak(flight, 0.05, onset),
                                 time_s=np.where(later, flight.time_s + 3.0, flight.time_s))
    assert not jump_test(gapped)[1]["flagged"]
    assert jump_test(_leak(flight, 0.05, onset))[1]["flagged"]


def test_a_tiny_jump_on_a_quiet_transducer_is_not_named():
    """0.3 Pa (0.03 % of q_ci) stands ~50 sigma above 0.01 Pa of noise, but moves nothing:
    below MIN_STEP it is not named; 3 % on the same flight is."""
    from pitotcal.estimation.robustness.jumps import MIN_STEP, jump_test

    flight, _ = synthetic_flight(seed=4, n=6000, qc_noise_pa=0.01)
    onset = float(flight.time_s[3000])
    tiny = flight.qci_pa - np.where(flight.time_s >= onset, 0.3, 0.0)
    details = jump_test(dataclasses.replace(flight, qci_pa=tiny))[1]
    assert abs(details["z"]) > details["threshold"] and abs(details["step"]) < MIN_STEP
    assert not details["flagged"]
    details = jump_test(_leak(flight, 0.03, onset))[1]
    assert details["flagged"] and details["time_s"] == pytest.approx(onset, abs=0.05)


def test_samples_missing_for_a_while_are_no_jump():
    """A record with 30-60 % of it missing (a dropped stream): the airspeed moved meanwhile;
    neither the gap nor its neighbours may read as a jump (the running means and scales skip
    it), and a 3 % leak after such a gap is still named."""
    from pitotcal.estimation.robustness.jumps import jump_test

    flight, _ = synthetic_flight(seed=2, n=12000, turbulence_mps=0.5, gps_rate_hz=5.0,
                                 gps_noise_mps=0.1)
    for a, b in ((0.2, 0.5), (0.1, 0.9)):
        keep = np.ones(flight.n, dtype=bool)
        keep[int(a * flight.n):int(b * flight.n)] = False
        details = jump_test(flight.select(keep))[1]
        assert not details["flagged"] and abs(details["z"]) < details["threshold"], (a, b)
    keep = np.ones(flight.n, dtype=bool)
    keep[2000:4000] = False
    onset = float(flight.time_s[8000])
    details = jump_test(_leak(flight, 0.03, onset).select(keep))[1]
    assert details["flagged"] and details["time_s"] == pytest.approx(onset, abs=0.05)
    assert details["z"] < 0 and details["step"] == pytest.approx(0.03, abs=0.01)


def test_held_qci_is_not_tested():
    from pitotcal.estimation.robustness.jumps import jump_test

    flight, _ = synthetic_flight(seed=9, n=2000, quantization_pa=5.0)
    warning, details = jump_test(flight)
    assert warning is None and "held or quantized" in details["skipped"]


def test_noise_free_flight_has_no_numeric_warning():
    """On a noise-free flight the change test's variances round to a hair below zero: it says
    nothing (no warning in the record, no RuntimeWarning on the console) and k is exact."""
    import warnings

    flight, truth = synthetic_flight(seed=1, n=4000, rate_hz=10.0, qc_noise_pa=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        res = identify(flight, air="incompressible")
    assert res.warnings == ()
    assert abs(res.value("k2") - truth["k"][1]) < 1e-6
