"""Issue 15: a logger glitch in an autopilot log (1e200 in a GPS velocity, 1e160 in the
differential pressure) is cut with a warning naming it, and the calibration is the truth's."""

import dataclasses

import numpy as np
import pytest
from logwriters import write_dataflash_text
from pitotcal.estimation import identify
from synthetic import synthetic_flight

from pitotcal.io.logs import load_log


def test_glitches_in_a_dataflash_log_are_cut_and_named(tmp_path):
    flight, truth = synthetic_flight(seed=1, n=3000, rate_hz=10.0, vertical=True)
    vn, q = flight.gps_vn_mps.copy(), flight.qci_pa.copy()
    vn[1000], q[2001] = 1e200, 1e160
    bad = dataclasses.replace(flight, gps_vn_mps=vn, qci_pa=q)
    path = write_dataflash_text(tmp_path / "f.log", bad)
    with pytest.warns(UserWarning, match=r"cut \d+ samples with implausible values \(first: "
                                         r"gps_vn_mps [\d.]+e\+\d+ at \d+\.\d+ s, outside -515 to 515\)"):
        flog = load_log(path)
    got = flog.flight
    assert flog.excluded["implausible value"] >= 2 and got.n >= flight.n - 10
    assert np.all(np.abs(got.gps_vn_mps) < 100) and got.qci_pa.max() < 1e4
    assert any("implausible" in w for w in got.warnings)
    result = identify(got, "inverse", air="incompressible")
    for i, name in enumerate(("k1", "k2")):
        assert abs(result.params[i] - truth["parameters"][name]) < 3 * result.std[i]
