"""What a command imports: `simulate`, `identify` (default options, no --plot) and `monitor`
leave out the heavy modules they do not use (each costs 0.1-1 s of every run)."""

import json
import os
import subprocess
import sys

from plans import circle_plan
from synthetic import synthetic_flight

from pitotcal.io import write_flight_csv
from pitotcal.io.plan_csv import write_plan

HEAVY = ("scipy.ndimage", "scipy.stats", "scipy.special", "scipy.signal", "control", "matplotlib", "jsbsim",
         "dask")

_PROBE = """
import json, sys
from pitotcal.cli import main
for argv in json.loads(sys.argv[1]):
    assert main(argv) in (0, 1), argv      # monitor: 1 is an alarm
heavy = json.loads(sys.argv[2])
print(json.dumps(sorted(m for m in sys.modules if m in heavy or m.startswith(tuple(h + "." for h in heavy)))))
"""


def test_simulate_identify_monitor_import_nothing_heavy(tmp_path):
    plan = write_plan(circle_plan(duration_s=60.0), tmp_path / "plan.csv")
    flight, _ = synthetic_flight(seed=2, n=4000)
    csv = write_flight_csv(flight, tmp_path / "flight.csv")
    cal = tmp_path / "cal.json"
    runs = [["simulate", str(plan), "-o", str(tmp_path / "sim.csv")],
            ["identify", str(csv), "--json", str(cal)],
            ["monitor", str(csv), "--calibration", str(cal)]]
    out = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(runs), json.dumps(HEAVY)],
                         capture_output=True, text=True, timeout=120,
                         env={**os.environ, "MPLBACKEND": "Agg"})
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout.strip().splitlines()[-1]) == []
    assert cal.exists() and (tmp_path / "sim.csv").exists()
