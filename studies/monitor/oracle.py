"""The fastest any detector could find a fault on a flight: an oracle told the fault's exact
effect on the monitor's residual (its size and shape), not its onset.

The oracle sees what the monitor sees, the block residuals e (`uncertainty.block_noise`; in airspeed,
e V_i/2, when the calibration's noise model is), whitened with the calibration's AR
coefficients, w_k = e_k − Σ φ_i e_{k−i}, and scaled by the flight's own innovation spread (it
knows the noise level). It knows the fault's effect d_m on e, m blocks
after the onset (taken from the same flight flown with and without the fault), so an onset at
block j adds u_{k−j} = (d − Σ φ_i d_{−i})_{k−j} to the scaled innovation x_k. Its statistic is
the Shiryaev–Roberts sum over onsets of the likelihood ratios,

    R_n = Σ_j exp(Σ_{m=1}^{n−j} (u_m x_{j+m} − u_m² / 2)),

and it alarms at R_n ≥ γ, γ the average run length (in blocks) of the false-alarm rate. R_n − n
is a martingale when nothing is wrong, so the oracle's false alarms are no more frequent than
the rate (for innovations that are white and normal: the same assumption the monitor's design
makes). The Shiryaev–Roberts test is the fastest for a known change at a given false-alarm
rate in the asymptotic and minimax senses (Pollak 1985), so a monitor, which knows neither the
size nor the shape, cannot be expected to be faster over many flights; on one flight it can be,
by luck (in the monitor study a 10 % leak in 1 m/s turbulence: the monitor's one-block jump
limit fired on an innovation of −5.1 σ where the oracle expected −6.5 σ and waited).
"""

import numpy as np
from pitotcal.estimation.uncertainty.block_noise import airspeed_residual_mps

__all__ = ["oracle_delay_s"]

_WINDOW_S = 180.0           # onsets considered this far back (the monitor's ramp test's window)


def oracle_delay_s(clean, spoiled, phi, onset_s, rate_per_hour, warmup_s, velocity=True):
    """Seconds from `onset_s` to the oracle's first alarm at or after it (None: none).

    Parameters
    ----------
    clean, spoiled : dict of ndarray
        The monitor's block traces (`MonitorResult.blocks`) of one flight flown without and
        with the fault; both must hold the same blocks (time_s, e, pred_pa).
    phi : array_like
        The calibration's AR coefficients (`monitor_cusum.ar_coefficients`).
    onset_s, warmup_s : float
        The fault's onset, and the start of the record left to the monitor's warm-up.
    rate_per_hour : float
        The false-alarm rate the oracle is held to, per flight hour.
    velocity : bool
        Test the residual in airspeed (`monitor_cusum.in_velocity`), else relative.
    """
    t = np.asarray(spoiled["time_s"], float)
    if not np.array_equal(t, np.asarray(clean["time_s"], float)):
        raise ValueError("the clean and spoiled traces hold different blocks")
    phi = np.atleast_1d(np.asarray(phi, float))
    block_s = float(np.median(np.diff(t)))
    e_clean, e_spoiled = _residual(clean, velocity), _residual(spoiled, velocity)
    live = t > warmup_s
    spread = _whiten(e_clean, phi)[live]
    x = _whiten(e_spoiled, phi) / float(np.std(spread))
    j0 = int(np.searchsorted(t, onset_s))                  # the first block the fault reaches
    d = e_spoiled[j0:] - e_clean[j0:]
    n_win = min(d.size, round(_WINDOW_S / block_s))
    u = _whiten(d[:n_win], phi) / float(np.std(spread))
    stat = _shiryaev_roberts(x, u, first=int(np.argmax(live)))
    gamma = 3600.0 / block_s / rate_per_hour
    hits = np.flatnonzero((stat >= gamma) & (t >= onset_s))
    return None if hits.size == 0 else float(t[hits[0]] - onset_s)


def _residual(trace, velocity):
    """The trace's residual in the unit the monitor tests: ΔV_i = e V_i/2 (m/s) or e."""
    e = np.asarray(trace["e"], float)
    return airspeed_residual_mps(e, trace["pred_pa"]) if velocity else e


def _whiten(e, phi):
    """w_k = e_k − Σ φ_i e_{k−i}, with e = 0 before the first block."""
    w = e.copy()
    for i, p in enumerate(phi, start=1):
        w[i:] -= p * e[:-i]
    return w


def _shiryaev_roberts(x, u, first):
    """R_n for every block n (onsets j ≥ `first`, the signal u_1.. after block j)."""
    n, m = x.size, u.size
    r = np.zeros(n)
    for j in range(first, n - 1):
        seg = x[j + 1:j + 1 + m]
        llr = np.cumsum(u[:seg.size] * seg - 0.5 * u[:seg.size] ** 2)
        r[j + 1:j + 1 + seg.size] += np.exp(np.minimum(llr, 700.0))
    return r
