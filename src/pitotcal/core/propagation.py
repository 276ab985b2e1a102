"""The delta method: a derived quantity's standard deviation from the coefficients' covariance.

One place for the propagation every 2-sigma band of a derived quantity uses (ΔV, Δp/q_c in
`estimation.identification.result`; Δp_p/q_cic, ΔM_pc, ΔH_pc in `estimation.identification.static_source`; the planner's
predicted band in `core.information`; the leg fit's ΔV in `estimation.legs.global_fit`).
"""

import numpy as np

__all__ = ["band", "gradient"]


def gradient(fun, k):
    """Central-difference gradient of a vector function of the coefficients, shape (len(k), ...)."""
    k = np.asarray(k, dtype=float)
    rows = []
    for i in range(k.size):
        h = 1e-6 * max(1.0, abs(k[i]))
        up, dn = k.copy(), k.copy()
        up[i] += h
        dn[i] -= h
        rows.append((fun(up) - fun(dn)) / (2 * h))
    return np.array(rows)


def band(grad, cov):
    """One-sigma of a derived quantity: sqrt(g^T C g) for each column of `grad`."""
    return np.sqrt(np.maximum(np.einsum("i...,ij,j...->...", grad, cov, grad), 0.0))
