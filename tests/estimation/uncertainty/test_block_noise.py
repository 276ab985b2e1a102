"""estimation.uncertainty.block_noise: the vectorised per-block line fits against one
`np.polyfit` per block (the textbook route), on an irregularly sampled record."""

import numpy as np

from pitotcal.estimation.uncertainty.block_noise import block_stats


def _polyfit_blocks(t, q, start, stop):
    means, band = [], []
    for a, b in zip(start, stop):
        tt, qq = t[a:b] - t[a], q[a:b]
        resid = qq - np.polyval(np.polyfit(tt, qq, 1), tt)
        means.append(qq.mean())
        band.append(resid @ resid / max(b - a - 2, 1) / max(qq.mean() ** 2, 1e-9))
    return np.array(means), np.array(band)


def test_block_line_fits_are_polyfit_ones():
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.005, 0.06, 20_000))     # gaps: some blocks under 4 samples
    q = 900.0 + 60.0 * np.sin(t / 25.0) + 3.0 * t / t[-1] + rng.normal(0.0, 2.0, t.size)
    blocks = block_stats(t, q)
    assert np.all(blocks.stop - blocks.start >= 4)
    means, band = _polyfit_blocks(t, q, blocks.start, blocks.stop)
    assert np.allclose(blocks.qci_pa, means, rtol=1e-9, atol=0)
    assert np.allclose(blocks.band_rel_var, band, rtol=1e-9, atol=0)
    assert np.array_equal(blocks.time_s, t[blocks.stop - 1])
