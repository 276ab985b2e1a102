"""Robust identification (issue 15): plausibility gates and outlier trimming against truth."""

import dataclasses

import numpy as np
import pytest
from pitotcal.estimation import identify
from pitotcal.estimation.robustness import consistency
from pitotcal.estimation.robustness import gates as robust
from synthetic import synthetic_flight

from pitotcal.core.errors import ObservabilityError

OPTIONS = {"turbulence_mps": 1.0, "gps_rate_hz": 5.0, "gps_noise_mps": 0.1}


@pytest.fixture(scope="module")
def clean():
    return synthetic_flight(seed=3, **OPTIONS)


def _within(result, truth, sigmas=3.0):
    for name, true in truth["parameters"].items():
        diff = result.value(name) - true
        if name == "wind_from_deg":
            diff = (diff + 180.0) % 360.0 - 180.0
        assert abs(diff) < sigmas * result.stddev(name), (name, result.value(name), true)


def _rows(flight, fraction=0.005, seed=7):
    rng = np.random.default_rng(seed)
    return rng.choice(flight.n, int(fraction * flight.n), replace=False)


def _with(flight, name, rows, func):
    values = getattr(flight, name).copy()
    values[rows] = func(values[rows])
    return dataclasses.replace(flight, **{name: values})


def _fit(flight):
    return identify(flight, air="incompressible")


@pytest.mark.parametrize("glitch_pa", [0.01, 1.0])
def test_one_qci_glitch_is_gated(clean, glitch_pa):
    flight, truth = clean
    row = flight.n // 3
    result = _fit(_with(flight, "qci_pa", [row], lambda v: np.full_like(v, glitch_pa)))
    _within(result, truth)
    note = [w for w in result.warnings if "dropped before the fit" in w]
    assert len(note) == 1 and note[0].startswith(f"{flight.source}: 1 samples dropped")
    assert f"t = {flight.time_s[row]:.2f} s" in note[0] and "q_ci" in note[0]
    assert result.n_samples == flight.n - 1


@pytest.mark.parametrize("name,func,words", [
    ("qci_pa", lambda v: 3.0 * v, "trimmed as outliers"),
    ("gps_vn_mps", lambda v: v + 20.0, "GPS velocity jumps"),
    ("rho_kgm3", lambda v: np.full_like(v, 1e6), "rho_kgm3 outside the plausible"),
])
def test_sparse_outliers_are_removed_and_named(clean, name, func, words):
    flight, truth = clean
    rows = _rows(flight)
    result = _fit(_with(flight, name, rows, func))
    _within(result, truth)
    note = [w for w in result.warnings if words in w]
    assert len(note) == 1 and f"{rows.size} samples" in note[0], result.warnings
    first = flight.time_s[np.sort(rows)[0]]
    assert f"{first:.2f} s" in note[0]
    assert result.n_samples == flight.n - rows.size


def test_extreme_cell_in_memory_does_not_crash(clean):
    flight, truth = clean
    result = _fit(_with(flight, "gps_ve_mps", [10], lambda v: np.full_like(v, 1e200)))
    _within(result, truth)
    assert any("gps_ve_mps outside the plausible" in w for w in result.warnings)


def test_clean_flight_unchanged(clean):
    """No sample gated or trimmed: the answer is the plain fit's, bit for bit."""
    flight, _ = clean
    result = _fit(flight)
    assert result.n_samples == flight.n
    assert not [w for w in result.warnings if "dropped" in w or "trimmed" in w]
    assert not robust.outliers(result.residuals_pa).any()


def test_heavy_tails_are_refused(clean):
    """Outliers on far more rows than a few glitches: exit 3, one line, no calibration."""
    flight, _ = clean
    rows = _rows(flight, fraction=0.05)
    with pytest.raises(ObservabilityError, match=r"beyond .* sigma .*cannot support"):
        _fit(_with(flight, "qci_pa", rows, lambda v: 2.0 * v))


def test_trim_threshold_false_trim_rate():
    """The threshold's Gaussian tail, times N, is the stated false-trim rate."""
    from scipy.stats import norm

    for n in (1000, 16000, 10 ** 6):
        z = robust.trim_threshold(n)
        assert 2 * n * norm.sf(z) == pytest.approx(robust.FALSE_TRIM_RATE, rel=1e-6)
    rng = np.random.default_rng(0)
    flagged = sum(robust.outliers(rng.normal(size=16000)).any() for _ in range(200))
    assert flagged <= 6     # expect 2 of 200 at 1 %; 6 is p < 0.02


def test_spans_text():
    t = np.arange(10) * 0.5
    mask = np.zeros(10, dtype=bool)
    mask[[1, 2, 3, 7]] = True
    assert robust.spans_text(t, mask) == "t = 0.50-1.50 s, 3.50 s"


@pytest.fixture(scope="module")
def calm():
    return synthetic_flight(seed=1, turbulence_mps=0.3)


def test_leak_from_mid_flight_is_named(calm):
    """q_ci 5 % low from the middle of the record on: a warning naming the onset and size."""
    flight, _ = calm
    t_mid = flight.time_s[flight.n // 2]
    leak = _with(flight, "qci_pa", np.flatnonzero(flight.time_s >= t_mid), lambda v: 0.95 * v)
    result = _fit(leak)
    note = [w for w in result.warnings if "changes during the flight" in w]
    assert len(note) == 1, result.warnings
    _, details = consistency.step_test(leak, result, "incompressible")
    assert abs(details["onset_s"] - t_mid) < 0.1 * flight.time_s[-1]
    assert details["step"] == pytest.approx(0.05, abs=0.025)
    assert f"t = {details['onset_s']:.0f} s" in note[0]


def test_consistent_flight_not_flagged(calm):
    flight, _ = calm
    result = _fit(flight)
    warning, details = consistency.step_test(flight, result, "incompressible")
    assert warning is None and abs(details["z"]) < details["threshold"]
    assert details["step"] == pytest.approx(0.0, abs=0.025)


def test_cli_json_names_the_trimmed_samples(clean, tmp_path):
    """`pitotcal identify`: exit 0, the removal in the JSON `warnings`, truth within 3 sigma."""
    import json

    from pitotcal.cli import main
    from pitotcal.io import write_flight_csv

    flight, truth = clean
    rows = _rows(flight)
    csv = write_flight_csv(_with(flight, "qci_pa", rows, lambda v: 3.0 * v), tmp_path / "f.csv")
    out = tmp_path / "r.json"
    assert main(["identify", str(csv), "--air", "incompressible", "--json", str(out)]) == 0
    result = json.loads(out.read_text())
    assert [w for w in result["warnings"] if f"{rows.size} samples trimmed as outliers" in w]
    for name, true in truth["parameters"].items():
        p = result["parameters"][name]
        diff = (p["value"] - true + 180.0) % 360.0 - 180.0 if name == "wind_from_deg" \
            else p["value"] - true
        assert abs(diff) < 3 * p["std"], name


def test_running_median_and_mean_are_scipy_ndimage_ones():
    # numpy's route (short records) and scipy's (long ones) give the same running statistics
    from scipy.ndimage import median_filter, uniform_filter1d

    from pitotcal.estimation.robustness.running import running_mean, running_median

    rng = np.random.default_rng(5)
    for n, width in ((1, 1), (3, 4), (7, 10), (2_000, 2), (16_000, 25), (16_000, 250),
                     (100_000, 251)):
        x = 1.0 + 0.01 * rng.normal(size=n)
        assert np.array_equal(running_median(x, width),
                              median_filter(x, size=width, mode="nearest"))
        assert np.allclose(running_mean(x, width), uniform_filter1d(x, size=width, mode="nearest"),
                           rtol=1e-12, atol=0)
