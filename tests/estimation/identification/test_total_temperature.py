"""Static temperature from a total-temperature probe at the calibrated (true) Mach, and the
ram-rise warning of a static `oat_k` column that is total.

A 180-260 KCAS / 10,000 ft compressible flight (Mach 0.33-0.47) logs `tat_k` from a probe of
recovery factor 0.97. Converted with the indicated Mach (q_ci / p_s,ind, the reader's only
Mach) T_s is 0.23 K off at the top speed and k2 comes out -10.9 against -15; `identify` makes
T_s again at the calibration's Mach until it settles.
"""

import dataclasses

import numpy as np
import pytest
from pitotcal.estimation.identification.identify import identify
from pitotcal.maneuvers.fly.options import AirSensors
from pitotcal.maneuvers.fly.simulator import simulate
from plans import circle_plan

from pitotcal.core import airdata as ad
from pitotcal.core.moist_air import at_mach, ram_rise_note, with_static_air
from pitotcal.core.units import isa_temperature_k

RECOVERY = 0.97


@pytest.fixture(scope="module")
def flown():
    plan = circle_plan(duration_s=240.0, cas_kt=(180.0, 260.0), radius_m=4500.0,
                       altitude_m=3048.0, wind_speed_mps=5.0)
    return simulate(plan, seed=0, rate_hz=10.0, air_sensors=AirSensors(tat_recovery=RECOVERY),
                    turbulence_mps=0.0, keep_history=True, air_data="compressible")


def test_static_temperature_at_the_true_mach(flown):
    flight, truth = flown
    read = with_static_air(flight, temp_recovery=RECOVERY)
    ts = isa_temperature_k(truth.history["alt_m"])
    assert np.max(np.abs(read.oat_k - ts)) > 0.2            # the indicated Mach's error
    true_mach = truth.history["tas_mps"] / ad.speed_of_sound_mps(ts)
    again = at_mach(read, true_mach)
    np.testing.assert_allclose(again.oat_k, ts, atol=1e-9)
    np.testing.assert_allclose(again.rho_kgm3, again.ps_pa / (287.05287 * ts), rtol=1e-12)
    assert at_mach(dataclasses.replace(read, meta={}), true_mach) is None   # oat_k given


def test_identify_iterates_the_recovery(flown):
    flight, truth = flown
    result = identify(with_static_air(flight, temp_recovery=RECOVERY), model="inverse")
    for name in ("k1", "k2", "wind_speed_mps", "wind_from_deg"):
        z = (result.value(name) - truth.parameters[name]) / result.stddev(name)
        assert abs(z) < 3.0, (name, z)
    assert result.value("k2") == pytest.approx(-15.0, abs=0.6)


def test_a_static_oat_column_that_is_total_is_warned_about(flown):
    flight, truth = flown
    ts = isa_temperature_k(truth.history["alt_m"])
    mach = truth.history["tas_mps"] / ad.speed_of_sound_mps(ts)
    static = dataclasses.replace(flight, tat_k=None, oat_k=ts)
    assert ram_rise_note(static) is None
    total = dataclasses.replace(static, oat_k=ts * (1.0 + 0.2 * mach ** 2))
    with pytest.warns(UserWarning, match="column oat_k rises with airspeed as a total"):
        read = with_static_air(total)
    note = next(w for w in read.warnings if "ram rise" in w)
    slope = float(note.split("it follows ")[1].split(" ")[0])
    assert slope == pytest.approx(1.0, abs=0.1)       # of the indicated Mach's ram rise
    # at low speed (70-100 KCAS, ram rise below 1.5 K) there is nothing to tell it by
    slow, slow_truth = simulate(circle_plan(duration_s=60.0), seed=1, rate_hz=10.0,
                                air_data="compressible", keep_history=True)
    ts = isa_temperature_k(slow_truth.history["alt_m"])
    mach = slow_truth.history["tas_mps"] / ad.speed_of_sound_mps(ts)
    assert ram_rise_note(dataclasses.replace(slow, oat_k=ts * (1 + 0.2 * mach ** 2))) is None
