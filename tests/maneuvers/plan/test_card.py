"""Pilot-card parts: the track sketch draws the plan's track and circle; KIAS targets invert
the calibration."""

import numpy as np
from pitotcal.maneuvers.plan.card import draw_track_sketch, kias_targets

from pitotcal.core.models import delta_v_kt, get_model
from pitotcal.core.plan import Plan
from pitotcal.core.airdata import qc_from_cas_pa
from pitotcal.core.speeds import tas_from_cas_mps
from pitotcal.core.units import FT_TO_M, RHO0_KGM3, isa_density_kgm3, kt_to_mps, mps_to_kt

ALT_M = 244.0


def _plan(settings):
    t = np.linspace(0.0, 100.0, 101)
    psi = t / 20.0
    cas = kt_to_mps(np.linspace(70.0, 100.0, t.size))
    return Plan(t, 500.0 * np.cos(psi), 500.0 * np.sin(psi), np.full(t.size, ALT_M), psi,
                np.full(t.size, 20.0), tas_from_cas_mps(cas, ALT_M), cas, qc_from_cas_pa(cas),
                settings=settings)


def test_sketch_draws_the_circle_and_the_track_in_kft():
    from matplotlib.figure import Figure

    plan = _plan({"radius_m": 926.0, "wind_speed_mps": 5.0, "wind_from_deg": 270.0})
    ax = Figure().add_subplot()
    draw_track_sketch(ax, plan)
    circle, track = ax.lines[0], ax.lines[1]
    kft = 1.0 / FT_TO_M / 1000.0
    np.testing.assert_allclose(np.hypot(circle.get_xdata(), circle.get_ydata()), 926.0 * kft)
    np.testing.assert_allclose(track.get_xdata(), plan.east_m * kft)
    np.testing.assert_allclose(track.get_ydata(), plan.north_m * kft)


def test_kias_targets_are_corrected_back_to_the_kcas():
    plan = _plan({"calibration": {"model": "linear", "k": [0.03, -1e-5]}})
    kias = kias_targets(plan)
    back = kias + delta_v_kt(get_model("linear"), (0.03, -1e-5), kias)
    # an incompressible calibration's V_c is sqrt(2 q_c / rho0) with q_c = ½ρV_t²: the
    # equivalent airspeed of the target's TAS, within 0.01 kt of its CAS at 800 ft
    eas_kt = mps_to_kt(plan.tas_mps * np.sqrt(isa_density_kgm3(ALT_M) / RHO0_KGM3))
    np.testing.assert_allclose(back, eas_kt, atol=1e-6)
    np.testing.assert_allclose(back, mps_to_kt(plan.cas_mps), atol=0.01)
    assert kias_targets(_plan({})) is None


def test_kias_targets_of_a_compressible_calibration_use_the_standard_law():
    cal = {"model": "inverse", "k": [0.02, -15.0], "air_data": "compressible"}
    plan = _plan({"calibration": cal})
    kias = kias_targets(plan)
    back = kias + delta_v_kt(get_model("inverse"), (0.02, -15.0), kias, "compressible")
    np.testing.assert_allclose(back, mps_to_kt(plan.cas_mps), atol=1e-6)
    incompressible = kias_targets(_plan({"calibration": {**cal, "air_data": "incompressible"}}))
    assert np.max(np.abs(kias - incompressible)) > 1e-4
