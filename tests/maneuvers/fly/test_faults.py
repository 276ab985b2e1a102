"""maneuvers.fly.faults: each fault spoils q_ci from its onset as documented, keeps the transducer
noise, leaves the samples before the onset untouched; `simulate --fault` writes its truth."""

import json

import numpy as np
import pytest
from pitotcal.maneuvers import simulate
from pitotcal.maneuvers.fly.faults import Fault, apply_fault, parse_fault
from plans import circle_plan

from pitotcal.cli import main
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model, qci_from_qc_pa
from pitotcal.core.units import RHO0_KGM3, kt_to_mps
from pitotcal.io.plan_csv import write_plan


@pytest.fixture(scope="module")
def flown():
    plan = circle_plan(duration_s=120.0)
    return simulate(plan, seed=3, rate_hz=20.0, keep_history=True)


def _clean(truth):
    return qci_from_qc_pa(get_model(truth.model), truth.k, truth.history["qc_pa"])


@pytest.mark.parametrize("kind,size", [("blocked", 0.0), ("leak", 0.1), ("icing", 2.0),
                                       ("water", 0.05), ("static", 0.0), ("blocked", 5.0)])
def test_before_onset_unchanged_noise_kept(flown, kind, size):
    flight, truth = flown
    spoiled = apply_fault(flight, truth, Fault(kind, 60.0, size))
    before = flight.time_s < 60.0
    assert np.array_equal(spoiled.qci_pa[before], flight.qci_pa[before])
    assert spoiled.meta["fault"] == f"{kind}:60:{size:g}"
    assert not np.array_equal(spoiled.qci_pa[~before], flight.qci_pa[~before]) or kind == "static"


def test_each_fault_against_its_formula(flown):
    flight, truth = flown
    clean, noise = _clean(truth), flight.qci_pa - _clean(truth)
    t, after = flight.time_s, flight.time_s >= 60.0
    i0 = int(np.argmax(after))
    leak = apply_fault(flight, truth, Fault("leak", 60.0, 0.1))
    np.testing.assert_allclose(leak.qci_pa[after], 0.9 * clean[after] + noise[after])
    frozen = apply_fault(flight, truth, Fault("blocked", 60.0, 0.0))
    # level flight (the circle plan holds its altitude): the trapped q_ci stays at its onset value
    held = frozen.qci_pa[after] - noise[after]
    assert np.ptp(held) < 0.05 * np.ptp(clean[after]) and abs(held[0] - clean[i0]) < 1e-6
    drained = apply_fault(flight, truth, Fault("blocked", 60.0, 5.0))
    late = t >= 90.0
    assert np.all(np.abs(drained.qci_pa[late] - noise[late]) < 0.01 * clean[i0] + 2.0)
    icing = apply_fault(flight, truth, Fault("icing", 60.0, 2.0))
    vi = np.sqrt(2 * (icing.qci_pa - noise) / RHO0_KGM3)
    vi0 = np.sqrt(2 * clean / RHO0_KGM3)
    # 60 s after the onset the indicated airspeed is 2 kt low
    j = int(np.argmin(np.abs(t - 120.0)))
    assert vi0[j] - vi[j] == pytest.approx(kt_to_mps(2.0), rel=1e-6)
    water = apply_fault(flight, truth, Fault("water", 60.0, 0.05))
    drop = 1 - (water.qci_pa - noise)[after] / clean[after]
    assert np.all(drop >= -1e-9) and 0.03 < np.mean(drop) < 0.05   # E|u| = 0.8 for unit RMS


@pytest.mark.parametrize("text,match", [("leak:1", "KIND:ONSET_S:SIZE"),
                                        ("rain:10:1", "not one of blocked"),
                                        ("leak:x:0.1", "must be numbers"),
                                        ("leak:10:1.5", "fault size 1.5 must be")])
def test_parse_errors(text, match):
    with pytest.raises(PitotcalError, match=match):
        parse_fault(text)


def test_simulate_fault_option_writes_truth(tmp_path, capsys):
    plan_csv = write_plan(circle_plan(duration_s=60.0), tmp_path / "plan.csv")
    out = tmp_path / "f.csv"
    assert main(["simulate", str(plan_csv), "-o", str(out), "--rate-hz", "10",
                 "--fault", "leak:30:0.2"]) == 0
    truth = json.loads((tmp_path / "f.truth.json").read_text())
    assert truth["fault"] == {"kind": "leak", "onset_s": 30.0, "size": 0.2, "seed": 0,
                              "size_unit": "fraction"}
    assert main(["simulate", str(plan_csv), "-o", str(out), "--fault", "leak"]) == 2
    assert "--fault" in capsys.readouterr().err


def test_onset_at_or_after_the_end_refused(flown):
    flight, truth = flown
    end = float(flight.time_s[-1])
    for onset in (end, end + 380.0):
        with pytest.raises(PitotcalError, match=f"onset {onset:g} s is at or after the "
                                                "flight's end"):
            apply_fault(flight, truth, Fault("leak", onset, 0.1))
    assert apply_fault(flight, truth, Fault("leak", end - 1.0, 0.1)).n == flight.n


def test_simulate_fault_errors_name_the_option(tmp_path, capsys):
    plan_csv = write_plan(circle_plan(duration_s=60.0), tmp_path / "plan.csv")
    out = tmp_path / "f.csv"
    assert main(["simulate", str(plan_csv), "-o", str(out), "--rate-hz", "5",
                 "--fault", "leak:500:0.1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--fault" in err[0] and "after the flight's end" in err[0]
    assert not out.exists()
    assert main(["simulate", str(plan_csv), "-o", str(out), "--fault", "leak:10:1.5"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--fault 'leak:10:1.5'" in err[0] and "size 1.5" in err[0]
