"""Autopilot airspeed parameters: the ratio/scale formula against a known constant error, the
files read back by pymavlink's own loader and by a QGC parse, the SITL log, the refusals."""

import math
import re

import numpy as np
import pytest
from pitotcal.estimation.reporting.autopilot_params import (ParameterRefused, recommend,
                                                            write_parameter_file)
from synthetic import synthetic_flight

from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import RHO0_KGM3
from pitotcal.io.param_files import read_qgc_params

K1 = 0.18        # ArduPilot's default ratio 1.9936 is about this error: 2/(rho0 (1-k1))


@pytest.fixture(scope="module")
def constant_flight():
    return synthetic_flight(seed=3, n=6000, model="constant", k=(K1,), qc_noise_pa=0.3)[0]


def test_ardupilot_ratio_recovers_the_truth_and_loads_in_pymavlink(constant_flight, tmp_path):
    from pymavlink.mavparm import MAVParmDict

    rec = recommend(constant_flight, "ArduPilot", current=1.6)
    truth = 2.0 / (RHO0_KGM3 * (1.0 - K1))
    assert abs(rec.value - truth) <= rec.two_sigma and rec.two_sigma < 0.01 * truth
    assert rec.name == "ARSPD_RATIO" and rec.track_spread_deg > 350
    path = write_parameter_file(rec, tmp_path / "new.param")
    loaded = MAVParmDict()
    assert loaded.load(str(path))
    assert loaded["ARSPD_RATIO"] == pytest.approx(rec.value, abs=1e-6)
    text = path.read_text()
    assert "2 sigma" in text and "current value 1.6" in text and "new / current" in text


def test_a_stated_gps_error_reaches_the_recommendation(constant_flight):
    """identify --params passes the receiver's stated slow velocity error on: a slow GPS bias
    the residuals cannot show widens the ratio's bound (issue 11)."""
    plain = recommend(constant_flight, "ArduPilot", current=1.6)
    stated = recommend(constant_flight, "ArduPilot", current=1.6, gps_error_sigma_mps=0.3,
                       gps_error_tau_s=60.0)
    truth = 2.0 / (RHO0_KGM3 * (1.0 - K1))
    assert stated.two_sigma > 1.2 * plain.two_sigma
    assert abs(stated.value - truth) <= stated.two_sigma


def test_px4_scale_is_the_square_root_and_parses_as_qgc(constant_flight, tmp_path):
    rec = recommend(constant_flight, "PX4", current=1.0)
    assert abs(rec.value - 1.0 / math.sqrt(1.0 - K1)) <= rec.two_sigma
    path = write_parameter_file(rec, tmp_path / "new.params")
    assert read_qgc_params(path) == {"ASPD_SCALE_1": pytest.approx(rec.value, abs=1e-6)}
    rows = [r for r in path.read_text().splitlines() if not r.startswith("#")]
    assert rows == [f"1\t1\tASPD_SCALE_1\t{rec.value:.6f}\t9"]


def test_refuses_a_track_that_did_not_turn_enough():
    # 0.6 of a turn: identify itself accepts it (> 180 deg), a parameter needs 270
    flight = synthetic_flight(seed=1, n=3000, model="constant", k=(K1,), turns=0.6)[0]
    with pytest.raises(PitotcalError, match=r"turned through only 2\d\d deg \(need 270"):
        recommend(flight, "ArduPilot", current=1.9936)


def test_refuses_when_one_scale_cannot_represent_the_error():
    # Δp/q_c from -0.40 at 70 kt to -0.15 at 100 kt: one ratio is off by 2.4 kt somewhere,
    # more than the tolerance (a third of the 5 kt limit)
    flight = synthetic_flight(seed=2, n=6000, model="inverse", k=(0.0, -250.0))[0]
    with pytest.raises(PitotcalError, match="a single ARSPD_RATIO cannot represent") as exc:
        recommend(flight, "ArduPilot", current=1.9936)
    # the refusal states what one ratio would cost, in kt, and the tolerance it exceeds
    assert re.search(r"one value is off by up to \d+\.\d\d kt at \d+ KIAS", str(exc.value))
    assert "`misfit_tolerance_kt` 1.67 kt" in str(exc.value)
    assert isinstance(exc.value, ParameterRefused) and exc.value.misfit["max_dv_kt"] > 2.0


def test_a_significant_but_small_misfit_is_recommended_and_stated():
    """Δp/q_c from -0.05 at 70 kt to -0.02 at 100 kt: the inverse model departs from one scale
    far beyond its 2σ (statistically certain) but by 0.57 kt only: one ratio is recommended
    with its misfit; a tolerance below it (`misfit_tolerance_kt`) refuses it."""
    flight = synthetic_flight(seed=2, n=6000, model="inverse", k=(0.0, -40.0))[0]
    rec = recommend(flight, "ArduPilot", current=1.9936)
    m = rec.misfit
    assert m["two_sigma_kt"] < m["max_dv_kt"] == pytest.approx(0.57, abs=0.05)
    assert any("structure misfit 0.57 kt is within the tolerance 1.67 kt" in n
               for n in rec.notes)
    with pytest.raises(ParameterRefused, match="`misfit_tolerance_kt` 0.30 kt"):
        recommend(flight, "ArduPilot", current=1.9936, misfit_tolerance_kt=0.3)
    with pytest.raises(PitotcalError, match="misfit_tolerance_kt"):
        recommend(flight, "ArduPilot", current=1.9936, misfit_tolerance_kt=0.0)


def test_px4_sdp3x_compensation_is_warned_with_its_factor(constant_flight):
    sdp3x = {"SENS_EN_SDP3X": 1, "CAL_AIR_CMODEL": 0, "CAL_AIR_TUBELEN": 0.2}
    with pytest.warns(UserWarning, match="already includes its SDP3x compensation") as caught:
        rec = recommend(constant_flight, "PX4", current=1.0, log_parameters=sdp3x)
    factor = float(re.search(r"by a factor (\d\.\d+)", str(caught[0].message)).group(1))
    # PX4's SDP3x flow model at the flight's median dp (about 1,000 Pa): the tip-speed term
    # 0.125 x flow alone adds about 11 m/s to the 40 m/s of sqrt(2 dp/rho0)
    assert factor == pytest.approx(1.27, abs=0.02)
    assert any("SENS_EN_SDP3X set, CAL_AIR_CMODEL 0" in n for n in rec.notes)
    # a membrane sensor (no SDP3x enabled): PX4 scales sqrt(2 dp/rho0) itself, no warning
    plain = recommend(constant_flight, "PX4", current=1.0,
                      log_parameters={"CAL_AIR_CMODEL": 0, "CAL_AIR_TUBED_MM": 1.5})
    assert not any("SDP3x" in n for n in plain.notes)


def test_px4_q_ci_made_of_its_compensated_ias_is_not_compensated_again(constant_flight):
    """A PX4 log whose q_ci the reader made of airspeed.indicated_airspeed_m_s (PX4's IAS,
    its SDP3x compensation included): the scale is already relative to that IAS, so no
    "divide by the factor" advice (it said divide by about 1.27: a scale 27 % low)."""
    import dataclasses
    import warnings

    meta = {**constant_flight.meta, "qc_source": "airspeed.indicated_airspeed_m_s converted: "
                                                 "q_ci = 0.5 rho0 IAS^2"}
    flight = dataclasses.replace(constant_flight, meta=meta)
    sdp3x = {"SENS_EN_SDP3X": 1, "CAL_AIR_CMODEL": 0, "CAL_AIR_TUBELEN": 0.2}
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*SDP3x.*")
        rec = recommend(flight, "PX4", current=1.0, log_parameters=sdp3x)
    assert not any("SDP3x" in n for n in rec.notes)
    truth = 1.0 / np.sqrt(1.0 - K1)                 # V_c / V_i of the constant model
    assert abs(rec.value - truth) <= rec.two_sigma


def _true_misfit(model, k, const, misfit):
    """What the recommended single value costs against the true error over the same V_i range:
    the largest |ΔV_true − ΔV_constant fit| and the span of the true local ratio."""
    from pitotcal.core.models import delta_v_kt, get_model
    from pitotcal.core.units import kt_to_mps

    vi = np.linspace(misfit["vi_min_kt"], misfit["vi_max_kt"], 301)
    dv_true = delta_v_kt(get_model(model), k, vi)
    dv_const, _ = const.delta_v_kt(vi)
    ratio = kt_to_mps(vi + dv_true) ** 2 / (0.5 * RHO0_KGM3 * kt_to_mps(vi) ** 2)
    return float(np.max(np.abs(dv_true - dv_const))), float(ratio.max() - ratio.min())


def _ratio_bound(rec):
    # a ΔV error δ at V_i moves the local ratio V_c²/q_ci by about 2 δ / V_i of itself
    m = rec.misfit
    return 2.0 * m["two_sigma_kt"] / m["vi_min_kt"] * rec.value


def test_structure_misfit_of_a_speed_dependent_error_matches_the_truth():
    """The campaign's case: a ratio stated +/- 0.03 (2 sigma) whose true local value spans
    1.587-1.625 over 71-100 KIAS. The recommendation states the misfit beside its 2 sigma."""
    from pitotcal import identify

    k = (0.02, -40.0)
    flight = synthetic_flight(seed=5, n=6000, model="inverse", k=k, qc_noise_pa=0.3,
                              turbulence_mps=1.0)[0]
    rec = recommend(flight, "ArduPilot", current=1.9936)
    true_dv, true_span = _true_misfit("inverse", k, identify(flight, model="constant"),
                                      rec.misfit)
    m = rec.misfit
    assert true_dv > 0.8 and true_span > 0.02 * rec.value     # a real structure error
    assert abs(m["max_dv_kt"] - true_dv) <= m["two_sigma_kt"]
    assert abs((m["local_max"] - m["local_min"]) - true_span) <= _ratio_bound(rec)
    assert m["local_min"] < rec.value < m["local_max"]
    text = "\n".join(rec.comments())
    assert f"by up to {m['max_dv_kt']:.2f} kt" in text and f"{m['local_min']:.4f} to" in text
    assert rec.to_dict()["structure_misfit"] == m


def test_structure_misfit_of_a_constant_error_is_nil(constant_flight):
    rec = recommend(constant_flight, "ArduPilot", current=1.6)
    m = rec.misfit
    assert m["max_dv_kt"] <= m["two_sigma_kt"]
    assert m["local_max"] - m["local_min"] <= _ratio_bound(rec)
    assert m["local_min"] <= rec.value <= m["local_max"]


def test_refuses_bounds_too_wide_to_improve_on_the_current_value():
    flight = synthetic_flight(seed=4, n=400, model="constant", k=(K1,), qc_noise_pa=25.0,
                              turbulence_mps=1.5)[0]
    truth = 2.0 / (RHO0_KGM3 * (1.0 - K1))
    with pytest.raises(PitotcalError, match="bounds too wide to improve on the current value"):
        recommend(flight, "ArduPilot", current=truth)


def test_unknown_autopilot_is_refused(constant_flight):
    with pytest.raises(PitotcalError, match="ArduPilot or PX4 log"):
        recommend(constant_flight, None)


def test_refuses_a_fit_that_did_not_converge(constant_flight, monkeypatch):
    import dataclasses

    from pitotcal.estimation.identification import identify as identification

    real = identification.identify

    def stalled(*args, **kw):
        return dataclasses.replace(real(*args, **kw), success=False,
                                   message="Maximum_Iterations_Exceeded")

    monkeypatch.setattr(identification, "identify", stalled)
    with pytest.raises(PitotcalError, match="did not converge \\(Maximum_Iterations"):
        recommend(constant_flight, "ArduPilot", current=1.9936)
