"""The drifting-wind bound benchmark runs on two flights: its bound is no larger than the
estimator's expected error under the same noise spectrum, the one-ratio floor is the truth's
structure (k2 = -15 Pa over 70-100 KCAS: ~0.14 kt), and identify's error is of the bound's
size."""

import json
import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_drift_bound.py"


def test_bound_rows_on_two_flights(tmp_path):
    done = subprocess.run([sys.executable, str(BENCH), "--flights", "2", "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    rows = {r["name"]: r for r in json.loads((tmp_path / "drift_bound.json").read_text())["rows"]}
    iv = rows["IV, expected from the noise spectrum"]["median"]
    bound = rows["bound: design regressors, same spectrum"]["median"]
    assert 0.0 < bound <= iv * 1.03           # a bound, up to the draws' noise
    assert rows["bound counting the gusts' copy in q_ci (GLS on the measured q_ci)"]["median"] < bound
    assert rows["GLS on the measured q_ci (actual)"]["median"] > 1.0     # biased by the gusts
    assert 0.13 < rows["one ratio, best possible (no noise)"]["median"] < 0.16
    assert 0.02 < rows["identify (inverse, wind model by its test)"]["median"] < 0.8
    assert "| bound: design regressors, same spectrum |" in (tmp_path / "drift_bound.md").read_text()


def test_one_flight_is_refused_with_the_flag_named(tmp_path):
    done = subprocess.run([sys.executable, str(BENCH), "--flights", "1", "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "--flights must be at least 2" in done.stderr
