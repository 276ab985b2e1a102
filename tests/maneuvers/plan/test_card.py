"""Pilot-card parts: the track sketch draws the plan's track and circle; KIAS targets invert
the calibration."""

import numpy as np
from pitotcal.maneuvers.plan.card import draw_text_block, draw_track_sketch, kias_targets

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


def _pixels(draw):
    """The darkness (0-255) of a 6 x 3 in figure at 110 dpi with `draw(fig)` on it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 3), dpi=110)
    draw(fig)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return 255.0 - np.asarray(canvas.buffer_rgba())[..., :3].mean(axis=2)


def _line_rows(dark):
    """(first, last) row of each run of inked rows."""
    inked = np.r_[0, (dark.sum(axis=1) > 0).astype(int), 0]
    edges = np.flatnonzero(np.diff(inked))
    return np.column_stack([edges[::2], edges[1::2]])


def test_text_block_draws_what_fig_text_draws():
    """The card's text as one image: the same glyphs (ink within 0.5 %) on the same lines
    (within 2 pixels) as matplotlib's own monospace text, blank line included."""
    text = "TIME  KCAS   BANK\n0:00  70.0±5  R19°  015°\n\n4:00 100.0±5  end |_gy\n"
    mine = _pixels(lambda fig: draw_text_block(fig, text, 0.05, 0.9, fontsize=8))
    ref = _pixels(lambda fig: fig.text(0.05, 0.9, text, family="monospace", fontsize=8,
                                       va="top"))
    assert abs(mine.sum() / ref.sum() - 1) < 0.005
    rows_mine, rows_ref = _line_rows(mine), _line_rows(ref)
    assert rows_mine.shape == rows_ref.shape == (3, 2)
    assert np.abs(rows_mine - rows_ref).max() <= 2
    cols = np.flatnonzero(mine.sum(axis=0) > 0), np.flatnonzero(ref.sum(axis=0) > 0)
    assert abs(cols[0][0] - cols[1][0]) <= 1 and abs(cols[0][-1] - cols[1][-1]) <= 1


def test_text_block_leaves_a_character_the_font_lacks_to_matplotlib():
    from matplotlib.figure import Figure

    fig = Figure(dpi=110)
    draw_text_block(fig, "calibration from \U0001F600.json", 0.05, 0.9, fontsize=8)
    assert [t.get_text() for t in fig.texts] == ["calibration from \U0001F600.json"]
    assert not fig.images
