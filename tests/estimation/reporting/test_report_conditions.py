"""The report's test conditions from simulated flights with known turbulence: the turbulence
word follows the Dryden intensity flown, and the RMS it rests on is that intensity."""

import warnings

import pytest
from pitotcal.estimation.reporting.calibration_report import build_report
from pitotcal.estimation.reporting.conditions import TURBULENCE_WORDS, turbulence_rms_mps

import pitotcal
from pitotcal.core.scenario import T2_PLAN

WORDS = [w for _, w in TURBULENCE_WORDS]


@pytest.fixture(scope="module")
def results_by_turbulence():
    plan = pitotcal.plan_maneuver(**{**T2_PLAN, "duration_s": 180.0})
    out = {}
    for sigma in (0.0, 0.5, 1.5, 3.0):
        flight, _ = pitotcal.simulate(plan, seed=0, turbulence_mps=sigma, rate_hz=10.0,
                                      air_data="compressible", qc_noise_pa=0.5,
                                      gps_noise_mps=0.05)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out[sigma] = pitotcal.identify(flight, model="inverse",
                                           air="compressible").to_dict()
    return out


def _word(result):
    rows = dict(build_report(result)["conditions"])
    return rows["Turbulence indication"].split(":")[0]


def test_turbulence_words_order_with_the_dryden_intensity(results_by_turbulence):
    words = {s: _word(r) for s, r in results_by_turbulence.items()}
    assert words == {0.0: "calm", 0.5: "light", 1.5: "moderate", 3.0: "severe"}
    ranks = [WORDS.index(words[s]) for s in sorted(words)]
    assert ranks == sorted(ranks)


@pytest.mark.parametrize("sigma, rel", [(0.5, 0.3), (1.5, 0.3), (3.0, 0.3)])
def test_the_rms_is_the_along_path_gust(results_by_turbulence, sigma, rel):
    # turbulence_mps is sigma_u; the residual carries rho V u plus GPS noise (0.05 m/s)
    assert turbulence_rms_mps(results_by_turbulence[sigma]) == pytest.approx(sigma, rel=rel)


def test_still_air_is_at_the_gps_noise_floor(results_by_turbulence):
    assert turbulence_rms_mps(results_by_turbulence[0.0]) < 0.1


def test_no_noise_no_word():
    assert _word({"airspeed_correction": [{"vi_kt": 80.0, "dv_kt": 0.0, "vc_kt": 80.0}]}) == "—"
