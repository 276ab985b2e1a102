"""The real-log tests read the shared flight logs from the folder PITOTCAL_SHARED_DATA names;
without them they skip, and the reason names the variable and the missing file."""

import os
import subprocess
import sys
from pathlib import Path

TESTS = Path(__file__).resolve().parent


def test_a_missing_shared_log_skips_naming_the_variable_and_the_file(tmp_path):
    nowhere = tmp_path / "no-logs"
    env = {**os.environ, "PITOTCAL_SHARED_DATA": str(nowhere)}
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-rs", "-p", "no:cacheprovider",
         "tests/io/test_logs.py::test_ulog_reader_on_real_px4_log",
         "tests/io/test_alfa.py::test_reader_density_choices"],
        cwd=TESTS.parent, env=env, capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    out = " ".join(run.stdout.split())
    assert "2 skipped" in out
    for relpath in ("px4-ulog/sample_log_small.ulg", "alfa-carbonz"):
        assert (f"real-log test: {nowhere / relpath} not found "
                f"(PITOTCAL_SHARED_DATA={nowhere}; set PITOTCAL_SHARED_DATA") in out, out
