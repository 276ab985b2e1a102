"""Issue 15: no NaN or infinity reaches a file pitotcal writes as JSON (strict JSON)."""

import json

import numpy as np
from plans import circle_plan

from pitotcal.io.jsonfile import write_json
from pitotcal.io.plan_csv import read_plan, write_plan


def _strict(text):
    """json.loads that refuses NaN / Infinity (which Python's json would accept)."""
    def refuse(name):
        raise ValueError(f"not JSON: {name}")
    return json.loads(text, parse_constant=refuse)


def test_write_json_turns_nan_and_infinities_into_null(tmp_path):
    path = write_json(tmp_path / "r.json", {"a": np.nan, "b": [np.inf, -np.inf, 1.5],
                                            "c": np.float32("nan"), "d": np.array([np.nan])})
    assert _strict(path.read_text()) == {"a": None, "b": [None, None, 1.5], "c": None,
                                         "d": [None]}


def test_plan_settings_with_nan_are_written_as_null(tmp_path):
    plan = circle_plan(duration_s=20.0)
    plan.settings["wind_from_deg"] = float("nan")
    path = write_plan(plan, tmp_path / "plan.csv")
    header = [line for line in path.read_text().splitlines() if line.startswith("# wind_from")]
    assert header == ["# wind_from_deg: null"]
    assert read_plan(path).time_s.size == plan.time_s.size


def test_the_autothrottle_csv_header_is_strict_json(tmp_path):
    from pitotcal.maneuvers.plan.outputs import write_autothrottle_csv

    plan = circle_plan(duration_s=20.0)
    plan.settings["cas_max_kt"] = float("inf")
    path = tmp_path / "sp.csv"
    write_autothrottle_csv(plan, path)
    values = [line.split(": ", 1)[1] for line in path.read_text().splitlines()
              if line.startswith("# ")]
    assert [_strict(v) for v in values][:3] == ["test-circle", 70.0, None]
