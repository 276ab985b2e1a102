"""The peers' speed benchmark runs end to end at a tiny size, and its three tools answer alike:
identify, the plain scipy script and (when node and the WebTools core are at hand) AirspeedFit."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_peers_speed.py"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "peers.json"
    done = subprocess.run([sys.executable, str(BENCH), "--sizes", "2000", "--repeats", "1",
                           "--no-profile", "--no-sitl", "--no-fetch", "--json", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(out.read_text()), done.stdout


def test_the_table_times_every_tool_it_has(run):
    data, text = run
    r = data["results"]["2,000"]
    tools = {"identify", "scipy"} | ({"AirspeedFit"} if data["skipped"] is None else set())
    assert set(r["wall_s"]) == tools
    for name in tools:
        assert 0 < r["wall_s"][name] < 60 and 20 < r["peak_mb"][name] < 2000
    assert "| 2,000 | 1 |" in text and "identify / scipy" in text
    if data["skipped"] is not None:
        assert "AirspeedFit skipped: " in text


def test_the_tools_answer_near_the_truth(run):
    """Same flight, comparable answers: wind within 0.1 m/s and 1 deg of the truth for all;
    ΔV within 0.1 kt for the two k1 + k2/q_ci fits (AirspeedFit fits a ratio only: within
    0.25 kt over 70-100 kt, where the truth's ΔV spans 0.5 kt)."""
    data, _ = run
    r = data["results"]["2,000"]
    truth = r["truth"]
    for name, a in r["answers"].items():
        assert abs(a["wind_mps"] - truth["wind_mps"]) < 0.1, name
        assert abs(a["wind_from_deg"] - truth["wind_from_deg"]) < 1.0, name
        tol = 0.25 if name == "AirspeedFit" else 0.1
        assert max(abs(x - y) for x, y in zip(a["dv_kt"], truth["dv_kt"])) < tol, name
