"""Plan outputs: plan CSV round trip, pilot card, auto-throttle setpoints, figures, output paths.

The command (`pitotcal plan`) is tested in tests/cli/test_plan.py."""

import numpy as np
import pytest
from pitotcal.maneuvers.plan.outputs import (
    autothrottle_setpoints,
    check_output_paths,
    output_paths,
    pilot_card_text,
    start_figures,
    write_plan_outputs,
)
from pitotcal.maneuvers.plan.planner import plan_maneuver

from pitotcal.core.errors import PitotcalError
from pitotcal.core.plan import PLAN_COLUMNS
from pitotcal.core.units import kt_to_mps
from pitotcal.io.plan_csv import read_plan

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module", params=["continuous", "step-pause"])
def plan(request):
    return plan_maneuver(request.param)


def test_plan_csv_round_trip(plan, tmp_path):
    paths = write_plan_outputs(plan, tmp_path / "plan.csv", figures=False)
    header = [line for line in paths["plan"].read_text().splitlines()
              if not line.startswith("#")][0]
    assert header.split(",") == list(PLAN_COLUMNS)
    back = read_plan(paths["plan"])
    for name in PLAN_COLUMNS:
        assert np.allclose(back.column(name), plan.column(name), rtol=1e-5, atol=1e-3), name
    assert back.settings == plan.settings


def test_autothrottle_setpoints(plan, tmp_path):
    sp = autothrottle_setpoints(plan)
    assert np.allclose(sp["cas_cmd_kt"] * kt_to_mps(1.0), plan.cas_mps)
    # the feed-forward integrates to the commanded true airspeed
    tas = plan.tas_mps[0] + np.r_[0.0, np.cumsum(sp["accel_ff_mps2"][:-1] * np.diff(sp["time_s"]))]
    assert np.allclose(tas, plan.tas_mps, atol=1e-9)
    assert np.max(np.abs(sp["accel_ff_mps2"])) <= plan.settings["accel_max_mps2"] + 1e-9
    resampled = autothrottle_setpoints(plan, rate_hz=10.0)
    assert np.allclose(np.diff(resampled["time_s"]), 0.1)
    paths = write_plan_outputs(plan, tmp_path / "p.csv", figures=False)
    lines = paths["autothrottle"].read_text().splitlines()
    header = [line for line in lines if not line.startswith("#")][0]
    assert header == "time_s,cas_cmd_kt,cas_cmd_mps,tas_cmd_mps,accel_ff_mps2"
    assert len(lines) - lines.index(header) - 1 == plan.n


def test_pilot_card_text(plan):
    text = pilot_card_text(plan)
    assert "70-100 KCAS" in text and "801 ft +-50 ft" in text and "3038 ft" in text
    rows = [line for line in text.splitlines() if line[:5].strip().count(":") == 1
            and "±5" in line]
    assert rows[0].split()[:3] == ["0:00", "70.0±5", rows[0].split()[2]]
    assert rows[-1].split()[1] == "100.0±5" and rows[-1].endswith("end")
    assert all(" ft " in row for row in rows)
    if plan.settings["profile"] == "step-pause":
        assert "accelerate to 81" in text and "hold" in text
    else:
        assert "kt/s" in text


def test_figures_are_pngs(tmp_path):
    plan = plan_maneuver("two-speed")
    paths = write_plan_outputs(plan, tmp_path / "two.csv")
    assert set(paths) == {"plan", "card_txt", "card_png", "autothrottle", "figure"}
    for key in ("card_png", "figure"):
        data = paths[key].read_bytes()
        assert data.startswith(PNG_MAGIC) and len(data) > 20_000


def test_figures_started_before_the_plan_are_the_same(tmp_path):
    """`start_figures` (the child that imports matplotlib while the plan is solved) writes the
    same PNGs, byte for byte, as drawing them after the plan."""
    with start_figures(tmp_path / "early.csv") as early:
        plan = plan_maneuver("two-speed")
        early_paths = write_plan_outputs(plan, tmp_path / "early.csv", early=early)
    here = write_plan_outputs(plan, tmp_path / "here.csv")
    for key in ("card_png", "figure"):
        assert early_paths[key].read_bytes() == here[key].read_bytes()


def test_output_paths_beside_the_plan(tmp_path):
    paths = output_paths(tmp_path / "T2.csv")
    assert paths["card_txt"] == tmp_path / "T2.card.txt"
    assert paths["autothrottle"] == tmp_path / "T2.autothrottle.csv"
    assert paths["figure"] == tmp_path / "T2.png"


def _broken(text, row, new):
    """The plan CSV text with data row `row` (1-based) replaced by `new` (None: dropped)."""
    lines = text.splitlines()
    first = next(i for i, line in enumerate(lines) if not line.startswith("#")) + 1
    if new is None:
        del lines[first + row - 1]
    else:
        lines[first + row - 1] = new(lines[first + row - 1].split(","))
    return "\n".join(lines) + "\n"


BROKEN_PLANS = [
    (5, lambda c: ",".join([c[0], "abc", *c[2:]]), r"column north_m, row 5 \(line \d+\): "
                                                    r"not a number: 'abc'"),
    (7, lambda c: ",".join([c[0], c[1], "nan", *c[3:]]), r"column east_m, row 7 \(line \d+\): nan"),
    (9, lambda c: ",".join(["0.000", *c[1:]]), r"column time_s, row 9 \(line \d+\): 0 s is not "
                                               r"after the previous row's [\d.]+ s"),
    (4, lambda c: ",".join(c[:3]), r"row 4 \(line \d+\): 3 cells, the header has 9"),
    (6, lambda c: ",".join([*c[:7], "-3", c[8]]), r"column cas_mps, row 6 \(line \d+\): "
                                                  r"airspeed -3 m/s must be > 0"),
]


@pytest.mark.parametrize("row, edit, match", BROKEN_PLANS)
def test_read_plan_names_file_column_and_row(plan, tmp_path, row, edit, match):
    good = write_plan_outputs(plan, tmp_path / "good.csv", figures=False)["plan"]
    bad = tmp_path / "bad.csv"
    bad.write_text(_broken(good.read_text(), row, edit))
    with pytest.raises(PitotcalError, match=rf"bad.csv: {match}"):
        read_plan(bad)


def test_read_plan_bom_crlf_and_truncation_warning(plan, tmp_path):
    good = write_plan_outputs(plan, tmp_path / "good.csv", figures=False)["plan"]
    text = good.read_text()
    crlf = tmp_path / "crlf.csv"
    crlf.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    back = read_plan(crlf)
    assert back.n == plan.n and back.settings == plan.settings
    cut = tmp_path / "cut.csv"
    cut.write_text("\n".join(text.splitlines()[:-100]) + "\n")
    with pytest.warns(UserWarning, match=r"cut.csv: the plan spans [\d.]+ s but its settings "
                                         r"say duration_s 240 s: is the file truncated\?"):
        assert read_plan(cut).n == plan.n - 100


def test_pilot_card_gives_where_to_start_and_bearings(plan):
    text = pilot_card_text(plan)
    start_ft = np.hypot(plan.north_m[0], plan.east_m[0]) / 0.3048
    bearing = np.degrees(np.arctan2(plan.east_m[0], plan.north_m[0])) % 360
    assert f"Start {start_ft:.0f} ft from centre on bearing {bearing:03.0f}°" in text
    first = next(line for line in text.splitlines() if line.startswith(" 0:00"))
    assert f"{start_ft:6.0f} ft {bearing:03.0f}°" in first


def test_calm_plan_card_says_calm():
    """Item 7 of issue 8: a calm plan's card said "270° / 0 kt"."""
    text = pilot_card_text(plan_maneuver(wind_speed_mps=0.0))
    assert "expected wind calm" in text and "/ 0 kt" not in text
    assert "expected wind 270° / 10 kt" in pilot_card_text(plan_maneuver())


def test_setpoints_hold_the_acceleration_of_each_interval(plan):
    """The feed-forward at any time is that of the interval it falls in (the last interval's
    from the final node on): sample-and-hold through pitotcal.io.resample."""
    sp = autothrottle_setpoints(plan, rate_hz=4.0)
    accel = np.diff(plan.tas_mps) / np.diff(plan.time_s)
    k = np.minimum(np.searchsorted(plan.time_s, sp["time_s"], side="right") - 1, plan.n - 2)
    np.testing.assert_array_equal(sp["accel_ff_mps2"], accel[k])


@pytest.mark.parametrize("make, match", [
    (lambda d: d / "missing" / "p.csv", r"output .*p.csv: folder .*missing does not exist"),
    (lambda d: d, r"output .* is a folder: name the plan CSV, e.g. .*plan.csv"),
    (lambda d: (d / "p.card.txt").mkdir() or d / "p.csv",
     r"output .*p.csv: .*p.card.txt is a folder, the file beside the plan cannot be written"),
])
def test_output_paths_checked_before_any_work(tmp_path, make, match):
    with pytest.raises(PitotcalError, match=match) as info:
        check_output_paths(make(tmp_path))
    assert info.value.param == "output"
    assert set(check_output_paths(tmp_path / "ok.csv", figures=False)) == {
        "plan", "card_txt", "autothrottle"}
