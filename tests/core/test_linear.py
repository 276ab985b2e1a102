"""The plain-numpy matrix exponential and zero-order hold against scipy."""

import numpy as np
import pytest

from pitotcal.core.linear import expm, zoh_transfer_function


@pytest.mark.parametrize("scale", [0.01, 1.0, 40.0])
def test_expm_matches_scipy(scale):
    from scipy.linalg import expm as scipy_expm

    m = scale * np.array([[-0.5, 0.2, 0.0], [0.1, -3.0, 1.0], [0.0, -1.0, 0.0]])
    np.testing.assert_allclose(expm(m), scipy_expm(m), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("num, den, dt", [
    ([0.3], [2.0, 1.0], 0.1),
    ([0.85, 0.5], [4.0, 4.0, 1.0], 0.02),
    ([61.2, 1.2], [900.0, 60.0, 1.0], 0.2),
    ([1.0], [1.0, 3.0, 2.0], 0.05),
])
def test_zoh_matches_scipy_cont2discrete(num, den, dt):
    from scipy.signal import cont2discrete

    num_d, den_d = zoh_transfer_function(num, den, dt)
    ref_num, ref_den, _ = cont2discrete((num, den), dt, method="zoh")
    ref_num = np.trim_zeros(ref_num[0], "f")
    assert num_d.shape == ref_num.shape
    np.testing.assert_allclose(num_d, ref_num, rtol=1e-12)
    np.testing.assert_allclose(den_d, ref_den, rtol=1e-12)
