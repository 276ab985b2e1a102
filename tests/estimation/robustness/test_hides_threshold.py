"""The hides statement's threshold on the default flight: quiet where the checks catch a 3 %
leak (0.5 m/s turbulence, the demo's), said where they miss it (1 m/s). Lean: a few seeds;
full size (50 seeds each, docs/measured.md "The hides statement's threshold"): slow."""

import numpy as np
import pytest
from pitotcal.estimation import identify
from pitotcal.maneuvers.fly.faults import apply_fault, check_fault
from pitotcal.studies.engine.common import get_flight

from pitotcal.core.scenario import HIDES_THRESHOLD_KT

LEAK, ONSET_S = 0.03, 120.0


def _checked(seed, turbulence_mps, leak=0.0):
    """(flagged by a test, the hides statement made, its consistency details) of the default
    one-way flight."""
    flight, truth = get_flight(None, {"turbulence_mps": turbulence_mps,
                                      "air_data": "compressible"}, seed)
    if leak:
        flight = apply_fault(flight, truth, check_fault("leak", ONSET_S, leak, seed))
    result = identify(flight)
    found = result.consistency
    flagged = bool(found["flagged"] or found["jump"]["flagged"])
    said = any("hides in the calibration" in w for w in result.warnings)
    return flagged, said, found


@pytest.mark.parametrize("seed", [0, 1])
def test_default_flight_is_quiet_and_a_missed_leak_is_said(seed):
    """Demo flight: the jump test catches a sudden change from ~2 % (0.7-0.8 kt of ΔV), below
    the default 1 kt. In 1 m/s with a 3 % leak no test flags it, the jump test catches one
    only from ~4 % (1.4-1.6 kt): the statement is made, with the threshold in it."""
    flagged, said, found = _checked(seed, 0.5)
    assert not flagged and not said and not found["hidden"]
    assert 0.5 < found["undetected_sudden"]["dv_shift_kt"] < HIDES_THRESHOLD_KT
    assert found["undetected_sudden"]["step"] < found["undetected"]["step"]
    assert found["jump"]["detectable_pa"] > 0
    flagged, said, found = _checked(seed, 1.0, LEAK)
    assert not flagged and said and found["hidden"]
    assert found["undetected_sudden"]["step"] > LEAK
    assert found["undetected_sudden"]["dv_shift_kt"] > 1.2 * HIDES_THRESHOLD_KT


@pytest.mark.slow
def test_hides_rates_over_fifty_flights():
    """Seeds 0-49 each (~1 min): the statement on fewer than 10 % of clean default flights
    (measured 0 of 100) and on at least 90 % of the 1 m/s flights whose 3 % leak no test
    flags (measured 58 of 58)."""
    clean = [_checked(seed, 0.5)[1] for seed in range(50)]
    assert np.mean(clean) < 0.10
    missed = [said for flagged, said, _ in (_checked(s, 1.0, LEAK) for s in range(50))
              if not flagged]
    assert len(missed) >= 40 and np.mean(missed) >= 0.90
