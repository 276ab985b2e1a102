"""The README's numbers are what its examples print now: docs/readme_numbers.py regenerates
each marked block; here the deterministic ones are run and compared (the wall-clock ones are
this machine's and are only rewritten by the script)."""

import importlib.util
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "docs" / "readme_numbers.py"


def _load():
    spec = importlib.util.spec_from_file_location("readme_numbers", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


rn = _load()
README = rn.README.read_text(encoding="utf-8")
FIXED = [n for n, (kind, _) in rn.GENERATORS.items() if kind == "fixed"]


def test_every_marked_block_has_a_generator_and_back():
    assert set(rn.blocks(README)) == set(rn.GENERATORS)
    for name in rn.GENERATORS:          # each opened block is closed, once or more
        assert README.count(f"<!-- readme-numbers:{name} -->") == \
            README.count(f"<!-- /readme-numbers:{name} -->") >= 1


@pytest.fixture(scope="module")
def fresh():
    return rn.generate(FIXED)


@pytest.mark.parametrize("name", FIXED)
def test_readme_block_is_a_fresh_run(fresh, name):
    assert rn.blocks(README)[name] == fresh[name], (
        f"README.md block {name} is stale: run `python docs/readme_numbers.py`")


DATA = [n for n, (kind, _) in rn.GENERATORS.items() if kind == "data"]


@pytest.mark.parametrize("name", DATA)
def test_real_log_block_is_a_fresh_run(tmp_path, name):
    got = rn.GENERATORS[name][1](tmp_path)
    if got is None:
        pytest.skip("the ArduPlane SITL log is absent: set PITOTCAL_SHARED_DATA to the folder "
                    "holding ardupilot/arduplane_sitl.log")
    assert rn.blocks(README)[name] == got


STUDIES = [n for n, (kind, _) in rn.GENERATORS.items() if kind == "studies"]


@pytest.mark.slow
@pytest.mark.parametrize("name", STUDIES)
def test_study_block_is_a_fresh_run(tmp_path, name):
    """The studies' tables (seeded, a minute or more each)."""
    assert rn.blocks(README)[name] == rn.GENERATORS[name][1](tmp_path), (
        f"README.md block {name} is stale: run `python docs/readme_numbers.py --studies`")


def test_rewrite_replaces_only_the_bodies():
    text = "a <!-- readme-numbers:x -->old<!-- /readme-numbers:x --> b"
    assert rn.rewrite(text, {"x": "new"}) == "a <!-- readme-numbers:x -->new<!-- " \
                                             "/readme-numbers:x --> b"
    assert rn.rewrite(text, {"x": None}) == text
