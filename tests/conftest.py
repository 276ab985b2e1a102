import os
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")


def _shared_data():
    """$PITOTCAL_SHARED_DATA, else the nearest ``shared/data`` beside a folder above the tests
    (``../shared/data`` of a checkout; also found from a git worktree one level deeper)."""
    if "PITOTCAL_SHARED_DATA" in os.environ:
        return Path(os.environ["PITOTCAL_SHARED_DATA"])
    above = Path(__file__).resolve().parents[2:]
    return next((p / "shared" / "data" for p in above if (p / "shared" / "data").is_dir()),
                above[0] / "shared" / "data")


SHARED_DATA = _shared_data()


def _not_found(path):
    """The skip reason of a real-log test: what is missing, and the variable that says where."""
    given = os.environ.get("PITOTCAL_SHARED_DATA")
    where = (f"PITOTCAL_SHARED_DATA={given}" if given is not None else
             "PITOTCAL_SHARED_DATA is not set, and no shared/data folder lies above the tests")
    return (f"real-log test: {path} not found ({where}; set PITOTCAL_SHARED_DATA to the folder "
            "of the shared flight logs, README: Tests)")


@pytest.fixture
def shared_data():
    """Path of the shared flight logs (PITOTCAL_SHARED_DATA, else ../shared/data); skips the
    test, naming the variable and the folder, when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(_not_found(SHARED_DATA))
    return SHARED_DATA


@pytest.fixture
def shared_file():
    """`shared_file("ardupilot/arduplane_sitl.log")`: the path of one shared log (a file or a
    folder); skips the test, naming the variable and the missing file, when it is absent."""
    def get(relpath):
        path = SHARED_DATA / relpath
        if not path.exists():
            pytest.skip(_not_found(path))
        return path

    return get
