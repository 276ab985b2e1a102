"""Linear time-invariant helpers in plain numpy: the matrix exponential and the zero-order-hold
discretisation of a transfer function.

The Dryden shaping filters and the auto-throttle check need only these two; plain numpy keeps
`simulate` and `plan` from importing scipy.signal (about 1 s on a busy machine) or
python-control. The tests compare both with scipy and python-control.
"""

import math

import numpy as np

__all__ = ["expm", "zoh_transfer_function"]


def expm(m):
    """exp(m) of a small square matrix: Taylor series after scaling to norm <= 1/2, then squaring.

    Notes
    -----
    After scaling by 2^-s, ||a||_1 <= 1/2 and 20 terms leave a remainder below 1e-24.
    """
    m = np.asarray(m, dtype=float)
    norm = float(np.max(np.sum(np.abs(m), axis=0))) if m.size else 0.0
    squarings = math.ceil(math.log2(norm / 0.5)) if norm > 0.5 else 0
    a = m / 2.0 ** squarings
    out = term = np.eye(m.shape[0])
    for k in range(1, 20):
        term = term @ a / k
        out = out + term
    for _ in range(squarings):
        out = out @ out
    return out


def zoh_transfer_function(num, den, dt_s):
    """Zero-order-hold discretisation of a strictly proper H(s) = num(s) / den(s).

    Parameters
    ----------
    num, den : array_like
        Polynomial coefficients in s, highest power first; deg num < deg den.
    dt_s : float
        Sample step, s.

    Returns
    -------
    num_d, den_d : ndarray
        H(z) in powers of z^-1 (den_d[0] = 1), for ``y = lfilter(num_d, den_d, x)``.

    Notes
    -----
    As `scipy.signal.cont2discrete((num, den), dt_s, "zoh")`: the controllable canonical
    state-space form, exp([[A, B], [0, 0]] dt) = [[A_d, B_d], [0, I]], and back to a transfer
    function, den_d = poly(A_d), num_d = poly(A_d - B_d C) - poly(A_d). The hold has no direct
    feed-through, so num_d starts with an exact zero; it is dropped, as python-control's
    transfer functions drop leading zeros, which advances the response by one sample.
    """
    num = np.atleast_1d(np.asarray(num, dtype=float))
    den = np.atleast_1d(np.asarray(den, dtype=float))
    n = den.size - 1
    num, den = num / den[0], den / den[0]
    a = np.zeros((n, n))
    a[0, :] = -den[1:]
    a[1:, :-1] = np.eye(n - 1)
    c = np.zeros(n)
    c[n - num.size:] = num
    block = np.zeros((n + 1, n + 1))
    block[:n, :n] = a * dt_s
    block[0, n] = dt_s                                   # B = e_1
    e = expm(block)
    a_d, b_d = e[:n, :n], e[:n, n:]
    den_d = np.poly(a_d)
    num_d = np.trim_zeros(np.poly(a_d - b_d @ c[None, :]) - den_d, "f")
    return (num_d if num_d.size else np.zeros(1)), den_d
