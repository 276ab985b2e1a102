"""`pitotcal plan --export`: advice that leads somewhere. Alternating turns are refused before
any radius advice; an altitude above mean sea level is checked against the ground's elevation
at the centre (PX4 SITL's home, 47.39774 8.54559, is 488 m above mean sea level)."""

import warnings

import pytest

from pitotcal.cli import main
from pitotcal.core.errors import PlanInfeasibleError
from pitotcal.maneuvers.plan.export_checks import check_ground_clearance

SITL = ["--center", "47.39774", "8.54559"]


@pytest.mark.parametrize("radius", ["500", "554", "700"])
def test_turn_both_is_refused_first_whatever_the_radius(tmp_path, capsys, radius):
    # 500 m alone is below the smallest radius of the maneuver (554 m): that advice would lead
    # to the refusal of --turn both, so --turn both is said first
    out = tmp_path / "b.csv"
    assert main(["plan", "--design", "optimal", "--check-fraction", "0", "--turn", "both",
                 "--radius-m", radius, *SITL, "--export", "px4", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--radius-m" not in err
    assert err.startswith("pitotcal plan: --turn both cannot be exported at any radius or "
                          "duration") and "--turn right or left" in err
    assert not out.exists()


def test_an_underground_loiter_is_refused_naming_the_altitude(tmp_path, capsys):
    out = tmp_path / "t2.csv"
    assert main(["plan", "--radius-m", "575", "--duration-s", "290", *SITL,
                 "--ground-elevation-m", "488", "--export", "px4", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == ("pitotcal plan: --altitude-m 244 m MSL is 244 m below the ground at the "
                   "centre (488 m MSL): plan --altitude-m at least 518 m (the ground plus 30 m)"
                   "\n")
    assert not out.exists()


def test_the_readme_px4_example_is_244_m_above_sitl_ground(tmp_path, capsys):
    out = tmp_path / "t2.csv"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["plan", "--radius-m", "601", "--duration-s", "290", "--altitude-m", "732",
                     *SITL, "--ground-elevation-m", "488", "--export", "px4", "--no-figures",
                     "-o", str(out)]) == 0
    assert "loiter 601 m clockwise at 732 m MSL" in capsys.readouterr().out


@pytest.mark.parametrize("ref, ground, warns", [("msl", None, True), ("agl", None, False),
                                                ("msl", 0.0, False), ("agl", 1000.0, False)])
def test_msl_without_ground_elevation_is_a_warning(ref, ground, warns):
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        check_ground_clearance(244.0, ref, ground)
    said = [str(w.message) for w in seen]
    assert bool(said) == warns
    if warns:
        assert said[0].startswith("the mission's loiters are at 244 m above mean sea level and "
                                  "the ground's elevation at the centre is not given")


@pytest.mark.parametrize("alt, ref, ground", [(244.0, "msl", 230.0), (20.0, "agl", 0.0)])
def test_less_than_30_m_above_the_ground_is_refused(alt, ref, ground):
    with pytest.raises(PlanInfeasibleError, match=r"plan altitude_m at least"):
        check_ground_clearance(alt, ref, ground)


def test_ground_elevation_without_export_is_refused(tmp_path, capsys):
    assert main(["plan", "--ground-elevation-m", "488", "-o", str(tmp_path / "p.csv")]) == 2
    assert "--ground-elevation-m is for --export or --altitude-ref agl" in capsys.readouterr().err


def test_agl_plans_its_airspeeds_at_the_ground_plus_the_height(tmp_path, capsys):
    """--altitude-ref agl --altitude-m 300 over ground at 1500 m flies the same air, so the same
    true airspeeds and radius advice, as --altitude-m 1800 (MSL); its mission counts from home."""
    import json

    from pitotcal.io.plan_csv import read_plan

    common = ["--center", "47", "8", "--ground-elevation-m", "1500", "--radius-m", "661",
              "--duration-s", "308", "--export", "px4", "--no-figures"]
    assert main(["plan", *common, "--altitude-m", "1800", "-o", str(tmp_path / "m.csv")]) == 0
    assert main(["plan", *common, "--altitude-ref", "agl", "--altitude-m", "300",
                 "-o", str(tmp_path / "a.csv")]) == 0
    msl, agl = (read_plan(tmp_path / f"{n}.csv") for n in ("m", "a"))
    assert agl.tas_mps.tolist() == msl.tas_mps.tolist()
    items = json.loads((tmp_path / "a.plan").read_text())["mission"]["items"]
    assert {item["params"][6] for item in items if item["command"] == 19} == {300.0}


def test_agl_without_ground_elevation_is_a_warning(tmp_path, capsys):
    assert main(["plan", "--center", "47", "8", "--altitude-ref", "agl", "--no-figures",
                 "-o", str(tmp_path / "p.csv")]) == 0
    assert "--altitude-ref agl without --ground-elevation-m" in capsys.readouterr().err
