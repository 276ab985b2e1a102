"""Centred running medians and means of a record, the ends held (``mode="nearest"``).

The robustness checks run them on every identification. `scipy.ndimage` computes them fastest
on long records but costs ~0.15-0.3 s to import, most of a short record's checks: below
`_NUMPY_WORK` window-samples the median is taken here with numpy, exactly the same value.
"""

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

__all__ = ["running_mean", "running_median"]

# Samples × window under which numpy's partition (O(N w)) beats importing scipy.ndimage.
_NUMPY_WORK = 20_000_000
# Rows of the window view copied at once: bounds the temporary to ~_CHUNK × width floats.
_CHUNK = 1 << 15


def _held(x, width):
    """`x` extended by its end values so that window i is samples i - width // 2 on (an even
    window reaches one sample further back than forward, as scipy.ndimage's does)."""
    h = width // 2
    return np.concatenate([np.full(h, x[0]), x, np.full(width - 1 - h, x[-1])])


def running_median(x, width):
    """The median of the `width` samples centred on each sample of `x` (of an even window, its
    upper middle value, as scipy.ndimage's `median_filter`)."""
    x = np.asarray(x, dtype=float)
    width = int(width)
    if x.size * width > _NUMPY_WORK:
        from scipy.ndimage import median_filter

        return median_filter(x, size=width, mode="nearest")
    windows = sliding_window_view(_held(x, width), width)
    out = np.empty_like(x)
    for a in range(0, x.size, _CHUNK):
        rows = np.array(windows[a:a + _CHUNK])
        rows.partition(width // 2, axis=1)
        out[a:a + _CHUNK] = rows[:, width // 2]
    return out


def running_mean(x, width):
    """The mean of the `width` samples centred on each sample of `x`: one
    cumulative sum of the record about its mean (rounding stays at the data's scale)."""
    x = np.asarray(x, dtype=float)
    width = int(width)
    centre = float(np.mean(x))
    c = np.concatenate([[0.0], np.cumsum(_held(x, width) - centre)])
    return (c[width:] - c[:-width]) / width + centre
