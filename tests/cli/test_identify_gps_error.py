"""`identify --gps-error-sigma-mps S --gps-error-tau-s T` (issue 11): the stated GPS velocity
error widens the wind's bounds, is recorded in the JSON, and is refused half-stated."""

import json

import pytest
from synthetic import synthetic_flight

from pitotcal.cli import main
from pitotcal.io import write_flight_csv


@pytest.fixture(scope="module")
def flight_csv(tmp_path_factory):
    flight, truth = synthetic_flight(seed=5, n=4000, turbulence_mps=0.0, gps_rate_hz=5.0,
                                     gps_noise_mps=0.05)
    return write_flight_csv(flight, tmp_path_factory.mktemp("gps") / "flight.csv"), truth


def test_stated_gps_error_widens_the_wind_and_is_recorded(flight_csv, tmp_path, capsys):
    path, truth = flight_csv
    out = {}
    for name, extra in (("none", []), ("stated", ["--gps-error-sigma-mps", "0.1",
                                                  "--gps-error-tau-s", "30"])):
        status = main(["identify", str(path), "--json", str(tmp_path / f"{name}.json"), *extra])
        assert status == 0, capsys.readouterr().err
        out[name] = json.loads((tmp_path / f"{name}.json").read_text())
    assert out["none"]["gps_error"] == {"stated": False, "sigma_mps": None, "tau_s": None}
    assert out["stated"]["gps_error"] == {"stated": True, "sigma_mps": 0.1, "tau_s": 30.0}
    assert "noise_model" in out["stated"]
    std = {k: out[k]["parameters"]["wind_speed_mps"]["std"] for k in out}
    # a 0.1 m/s error that the 80 s record cannot average out: the wind's sigma at least it
    # divided by the ~2.7 correlation times flown, far above the calm-air noise's
    assert std["stated"] > 0.1 / 2.7 > 3 * std["none"]
    for name, true in truth["parameters"].items():
        p = out["stated"]["parameters"][name]
        assert abs(p["value"] - true) < 3 * p["std"]


@pytest.mark.parametrize("extra, match", [
    (["--gps-error-sigma-mps", "0.05"], "--gps-error-tau-s"),
    (["--gps-error-tau-s", "30"], "--gps-error-sigma-mps"),
    (["--gps-error-sigma-mps", "-1", "--gps-error-tau-s", "30"], "--gps-error-sigma-mps"),
    (["--gps-error-sigma-mps", "0.05", "--gps-error-tau-s", "0"], "--gps-error-tau-s"),
])
def test_half_or_bad_statement_refused(flight_csv, capsys, extra, match):
    path, _ = flight_csv
    assert main(["identify", str(path), *extra]) == 2
    err = capsys.readouterr().err
    assert match in err and len(err.strip().splitlines()) == 1


def test_a_correlation_time_below_the_sample_interval_is_refused():
    """A 'slow' error faster than the samples is white noise: refused naming the flag and the
    interval, not silently clamped (review finding)."""
    from pitotcal.estimation import identify

    from pitotcal.core.errors import PitotcalError

    flight, _ = synthetic_flight(seed=1, n=2000)
    with pytest.raises(PitotcalError, match="shorter than the sample interval") as err:
        identify(flight, air="incompressible", gps_error_sigma_mps=0.05, gps_error_tau_s=1e-9)
    assert err.value.param == "gps_error_tau_s"
