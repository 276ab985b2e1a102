"""Figure helpers of the studies: pyplot-free figures, saving, and plain log-axis tick labels."""

from pathlib import Path

from pitotcal.io.atomic import save_figure

__all__ = ["new_figure", "plain_log_ticks", "save"]


def new_figure(nrows=1, ncols=1, size=(6.0, 4.0)):
    """A matplotlib Figure without pyplot (no GUI backend, safe in workers and CI), and its
    axes as a 2-D array; `size` is the size of one panel, inches."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=(size[0] * ncols, size[1] * nrows), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False)
    return fig, axes


def save(fig, out_dir, filename):
    """Save `fig` as out_dir/filename (110 dpi); the path as text."""
    path = Path(out_dir) / filename
    save_figure(fig, path, dpi=110)
    return str(path)


def plain_log_ticks(ax, axis="y"):
    """Label a log axis "0.6", "2", "300" instead of "6×10⁻¹" (same ticks, plain numbers)."""
    formatter = _plain_log_formatter()
    for which in ("x", "y") if axis == "both" else (axis,):
        target = ax.xaxis if which == "x" else ax.yaxis
        target.set_major_formatter(formatter())
        target.set_minor_formatter(formatter())


def _plain_log_formatter():
    from matplotlib.ticker import LogFormatterSciNotation

    class PlainLogFormatter(LogFormatterSciNotation):
        """Matplotlib's choice of which log ticks get a label, written as plain numbers."""

        def __call__(self, x, pos=None):
            return f"{x:g}" if super().__call__(x, pos) else ""

    return PlainLogFormatter
