"""What a reader of the studies' figures saw wrong: a y-label running into the title, log ticks
written "6×10⁻¹", 8.5% titled "8%", a wind direction running to 390°."""

import numpy as np
from pitotcal.studies.accuracy import coverage
from pitotcal.studies.accuracy import maneuvers as maneuvers_study
from pitotcal.studies.engine.figures import new_figure, plain_log_ticks
from pitotcal.studies.real_alfa.figure import _direction_band, _wrapped_with_breaks

# a full-size maneuvers summary shape: every profile at every flight time
MANEUVERS = {"by_profile": {
    p: {str(d): {"dv_2sigma_max_kt": 0.6 + 0.1 * i, "dv_err_max_kt_rms": 0.3 + 0.05 * i}
        for d in (180, 240, 480)} for i, p in enumerate(maneuvers_study.PROFILES)}}


def _renderer(fig):
    """Draw `fig` (Agg) and return its renderer, for text positions and tick labels."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    return renderer


def _labels(axis):
    return [t.get_text() for t in axis.get_majorticklabels() + axis.get_minorticklabels()
            if t.get_text()]


def test_maneuvers_labels_clear_of_the_title():
    fig = maneuvers_study.figure(MANEUVERS)
    renderer = _renderer(fig)
    title = fig._suptitle.get_window_extent(renderer)
    for ax in fig.axes:
        assert ax.yaxis.label.get_window_extent(renderer).y1 < title.y0, ax.get_ylabel()
    for ax in fig.axes:
        # plain tick labels on the log axis: "0.6", not "6×10^{-1}"
        texts = _labels(ax.yaxis)
        assert texts and all("times" not in t and "10^" not in t for t in texts), texts


def test_plain_log_ticks():
    fig, ax = new_figure()
    a = ax[0, 0]
    a.plot([1, 2], [0.25, 0.9])
    a.set_yscale("log")
    plain_log_ticks(a)
    _renderer(fig)
    assert {"0.3", "0.6"} <= set(_labels(a.yaxis)), _labels(a.yaxis)


def test_coverage_title_keeps_one_decimal():
    rows = [{"error": "", "success": True, **{f"{p}{s}": 0.5 for p in coverage.PARAMETERS
                                              for s in ("_z", "_z_plain")},
             "dv_inside_2sigma": 1.0}]
    summary = coverage.summarize(rows)
    summary.update(coverage_2sigma=0.961, coverage_2sigma_uncorrected=0.085)
    fig = coverage.figure(rows, summary)
    assert [ax.get_title() for ax in fig.axes[:2]] == [
        "corrected covariance: 96.1% inside ±2σ", "plain Hessian: 8.5% inside ±2σ"]


def test_wind_direction_wraps_into_0_360():
    t, deg = _wrapped_with_breaks([0.0, 1.0, 2.0, 3.0], [350.0, 370.0, 385.0, -325.0])
    assert np.allclose(deg, [350.0, np.nan, 10.0, 25.0, 35.0], equal_nan=True)
    assert np.allclose(t, [0.0, np.nan, 1.0, 2.0, 3.0], equal_nan=True)
    _, ax = new_figure()
    _direction_band(ax[0, 0], 350.0, 15.0)       # 335-365: two pieces, 335-360 and 0-5
    ys = sorted((p.get_y(), p.get_y() + p.get_height()) for p in ax[0, 0].patches)
    assert np.allclose(ys, [(0.0, 5.0), (335.0, 360.0)])
