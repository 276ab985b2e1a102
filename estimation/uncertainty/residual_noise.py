"""A residual noise model of several time scales for the colored-residual covariance.

Real residuals mix time scales: 5 Hz held GPS noise (tenths of a second), turbulence (seconds)
and the GPS receiver's slowly drifting velocity error (tens of seconds). One white + one
exponential term, fitted where the autocovariance first falls to 1/e, follows the fastest of
them and misses the slow ones that dominate the parameters' variance (coverage 63% of table
rows with 0.5 m/s GPS noise in 0.5 m/s turbulence, docs/measured.md).

Here the residual autocovariance is modelled as white noise plus a non-negative mix of
exponentials on a log-spaced grid of correlation times (a completely monotone autocovariance),
fitted by non-negative least squares to the autocovariance the residuals should show after
the fit has removed what lies along the sensitivities (projection-aware, as
`covariance._fit_projected`). The fit and the sandwich are formed on block means of
`step` samples (at most BLOCK_SAMPLES blocks): the sensitivities barely change within a block,
so S^T e = step * S_b^T e_b to that order and the block means carry every time scale's
contribution to the long-run variance, the short ones included, at a cost independent of N.
"""

import numpy as np

from pitotcal.core.information import DOF_TAUS

__all__ = ["MultiscaleFit", "block_means", "fit_multiscale", "multiscale_acov", "nnls",
           "residual_acf"]

# At most this many block means are fitted (the fit costs the same at N = 1e6 as at 16,000).
BLOCK_SAMPLES = 1500
# Correlation times of the grid, in blocks: from half a block to a quarter of the record,
# spaced by this ratio.
TAU_RATIO = 2.0
# Lags fitted: every lag up to DENSE_LAGS, then log-spaced to a quarter of the record.
DENSE_LAGS = 16
LOG_LAGS = 48
# With a velocity disturbance in the model (flight data: gusts and GPS velocity error reach
# the residual as u . d), neighbouring amplitudes of the pressure terms are tied by a penalty
# of this weight (per fitted lag, against the autocovariance misfit; scale-free, both in
# Pa^2): the non-negative fit otherwise turns a positive excursion of the sample
# autocovariance at long lags into one slow pressure term (~46 s on a 240 s record) and a
# negative one into none, all or nothing, so one flight's bounds came out ~1.4x too wide and
# the next ~1.2x too narrow by chance (the 90th percentile of the default flight's ΔV band
# 2.2 kt against a median of 1.0). Tied, the excursion spreads over neighbouring times
# (docs/measured.md, "Steadier bounds").
SMOOTHING = 1.0
# ... and then the terms slower than SLOW_FRACTION of the record, which one record cannot
# resolve, carry at least SLOW_FLOOR of the long-run variance of the faster ones: without it
# the tied fit leaves our simulator's bounds ~15% narrow on the flights that show no slow term
# (k1 rms z 1.18 over 200 flights), with it 1.12, and JSBSim's 0.87 (docs/measured.md).
# Pressure-domain noise alone (no velocity term) is fitted as it was: a single exponential
# there has no such tail, and the floor would overstate its sigma by ~1.3x.
SLOW_FRACTION = 0.1
SLOW_FLOOR = 0.2




def multiscale_acov(residuals, jac, velocity=None, known=None):
    """(fit, a, dof) for `covariance.colored_covariance`: the `MultiscaleFit` (block-mean
    autocovariances), a = exp(-1 / tau) of its long-run-weighted correlation time tau
    (samples), dof = N / (DOF_TAUS tau). White residuals (lag-1 correlation within sampling
    noise of 0) and no known term give h = [R(0)] at full rate.

    `known`: (sigma_mps, tau_samples) of a stated Gauss-Markov GPS velocity error, each
    component (`fit_multiscale`)."""
    n, p = jac.shape
    acov = residual_acf(residuals, 1) * n / max(n - p, 1)
    if acov[1] <= 3.0 * acov[0] / np.sqrt(n) and (known is None or velocity is None):
        fit = MultiscaleFit(acov[:1], None, 1, [], float(acov[0]))
        return fit, float(acov[1] / acov[0]), float("inf")
    fit = fit_multiscale(residuals, jac, velocity, known)
    tau = fit.tau_samples
    a = float(np.exp(-1.0 / tau)) if tau > 0 else 0.0
    return fit, a, (n / (DOF_TAUS * tau) if tau > 0 else float("inf"))


class MultiscaleFit:
    """Fitted block-mean autocovariances, k = 0..lag: `h` of the noise in the pressure itself
    and `h_vel` of a velocity disturbance d (GPS velocity error, gusts) that reaches the
    residual as u . d, u the wind sensitivities; and their summary numbers."""

    def __init__(self, h, h_vel, step, terms, white, known_lrv=0.0):
        self.h, self.h_vel, self.step = h, h_vel, step
        self.terms, self.white = terms, white   # [(kind, tau in blocks, amplitude, gain)]
        self.known_lrv = known_lrv              # long-run variance of the stated term, Pa^2

    @property
    def tau_samples(self):
        """Long-run-variance-weighted correlation time of the fitted terms, samples (0 for
        white noise); a stated term counts in the total but is not uncertain."""
        lrv = np.array([2.0 * a * t * g for _, t, a, g in self.terms])
        taus = np.array([t for _, t, _, _ in self.terms])
        total = self.white + lrv.sum() + self.known_lrv
        return float(self.step * (lrv * taus).sum() / total) if total > 0 else 0.0

    def describe(self):
        parts = [f" + {kind} {a:.3g} x {t * self.step:.0f} samples"
                 for kind, t, a, _ in self.terms]
        return f"white {self.white:.3g} Pa^2" + "".join(parts)


def block_means(x, step):
    """Means of consecutive blocks of `step` rows (the remainder < step rows dropped)."""
    x = np.asarray(x, dtype=float)
    if step <= 1:
        return x
    m = x.shape[0] // step
    return x[: m * step].reshape(m, step, *x.shape[1:]).mean(axis=1)


def fit_multiscale(residuals, jac, velocity=None, known=None):
    """The `MultiscaleFit` of `residuals` at the sensitivities `jac` (N, p).

    `velocity` (N, 2): the residual's sensitivities to a velocity disturbance (the wind
    columns of `jac`); None: pressure-domain terms only. `known` (sigma_mps, tau_samples): a
    Gauss-Markov velocity error stated by the user (the GPS receiver's), autocovariance
    sigma^2 exp(-|k| / tau) per component; what it puts into the residuals is taken out of
    their autocovariance before the fit, and it enters h_vel as it is. A slow GPS error
    looks like wind: the residuals barely show it, so only a statement can count it.
    """
    n, p = jac.shape
    step = max(1, int(np.ceil(n / BLOCK_SAMPLES)))
    rb, sb = block_means(residuals, step), block_means(jac, step)
    m = rb.size
    kmax = max(int(m // 4), 2)
    lags = np.unique(np.concatenate([np.arange(min(DENSE_LAGS, kmax) + 1),
                                     np.geomspace(DENSE_LAGS, kmax, LOG_LAGS).round()]))
    lags = lags[lags <= kmax].astype(int)
    obs = residual_acf(rb, kmax)[lags] * m / max(m - p, 1)
    taus = np.exp(np.arange(np.log(0.5), np.log(kmax) + 1e-9, np.log(TAU_RATIO)))
    ub = None if velocity is None else block_means(velocity, step)
    basis = _projected_basis(sb, kmax, _inv_sym, _fast_len)
    cols, kinds = [basis(np.ones(1))[lags]], [("white", 0.0)]
    gain = 1.0
    if ub is not None:
        gain = float(np.mean(np.sum(ub * ub, axis=1)))      # u.u: d's variance -> Pa^2
    for kind, mod in (("pressure", None), ("velocity", ub)):
        if kind == "velocity" and ub is None:
            continue
        for tau in taus:
            cols.append(basis(np.exp(-np.arange(_span(tau, m) + 1) / tau), mod)[lags])
            kinds.append((kind, tau))
    h_known, known_lrv = np.zeros(1), 0.0
    if known is not None and ub is not None and known[0] > 0:
        sigma, tau_k = float(known[0]), max(float(known[1]) / step, 1e-3)
        h_known = sigma ** 2 * np.exp(-np.arange(_span(tau_k, m) + 1) / tau_k)
        obs = obs - basis(h_known, ub)[lags]
        known_lrv = gain * float(h_known[0] + 2.0 * h_known[1:].sum())
    coef = _smooth_nnls(np.column_stack(cols), obs, kinds)
    if ub is not None:
        coef = _slow_floor(coef, kinds, gain, m)
    terms = [(kind, tau, float(c), gain if kind == "velocity" else 1.0)
             for (kind, tau), c in zip(kinds[1:], coef[1:]) if c > 0]
    lag = max([_span(t, m) for _, t, _, _ in terms] + [h_known.size - 1])
    k = np.arange(lag + 1)
    h, h_vel = np.zeros(lag + 1), np.zeros(lag + 1)
    h_vel[:h_known.size] += h_known if known_lrv else 0.0
    for kind, tau, amp, _ in terms:
        (h_vel if kind == "velocity" else h)[:] += amp * np.exp(-k / tau)
    h[0] += coef[0]
    return MultiscaleFit(h, h_vel if h_vel.any() else None, step, terms, float(coef[0]),
                         known_lrv)


def _smooth_nnls(a, b, kinds):
    """The mix's amplitudes: non-negative least squares of `a` c = `b`, with the neighbouring
    amplitudes of the pressure terms tied (`SMOOTHING`) when a velocity disturbance is
    modelled beside them."""
    if not any(kind == "velocity" for kind, _ in kinds):
        return nnls(a, b)
    idx = [i for i, (kind, _) in enumerate(kinds) if kind == "pressure"]
    pen = np.zeros((max(len(idx) - 1, 0), a.shape[1]))
    for row, (i, j) in enumerate(zip(idx[:-1], idx[1:])):
        pen[row, i], pen[row, j] = 1.0, -1.0
    pen *= np.sqrt(SMOOTHING * b.size)
    return nnls(np.vstack([a, pen]), np.r_[b, np.zeros(pen.shape[0])])


def _slow_floor(coef, kinds, gain, m):
    """`coef` with every term scaled up when the terms slower than `SLOW_FRACTION` of the
    record hold less than `SLOW_FLOOR` of the long-run variance of the faster ones."""
    tau = np.array([t for _, t in kinds])
    lrv = 2.0 * coef * tau * np.array([gain if k == "velocity" else 1.0 for k, _ in kinds])
    slow = float(lrv[tau > SLOW_FRACTION * m].sum())
    mid = float(lrv[(tau > 0) & (tau <= SLOW_FRACTION * m)].sum())
    if not mid > 0 or slow >= SLOW_FLOOR * mid:
        return coef
    return np.where(tau > 0, coef * (1.0 + SLOW_FLOOR) * mid / (mid + slow), coef)


def _span(tau, m):
    """Lags an exponential of `tau` is summed over (down to 1e-4), below the record."""
    return int(min(np.ceil(tau * np.log(1e4)), m - 1))


def _projected_basis(s, kmax, inv_sym, fast_len):
    """(h, u) -> E[acov((I - P) e)](0..kmax), P the projection on `s`, for e of
    autocovariance h (u None) or e_i = u_i . d_i with d two independent components of
    autocovariance h (u of shape (m, 2)).

    With Sigma the covariance of e, E[sum_i r_i r_(i+k)] = sum_i Sigma_(i, i+k) - c_UV(k) -
    c_VU(k) + c_(SC)S(k), U = S M^-1, V = Sigma S, C = M^-1 S^T V M^-1 (`covariance.
    _fit_projected`); FFT cross-correlations, O(p m log m) per h.
    """
    m = s.shape[0]
    minv = inv_sym(s.T @ s)
    size = fast_len(2 * m)
    fs = np.fft.rfft(s, size, axis=0)
    fu = fs @ minv
    lags = np.arange(kmax + 1)

    def toeplitz(fh, x):
        return np.fft.irfft(np.fft.rfft(x, size, axis=0) * fh[:, None], size, axis=0)[:m]

    def basis(h, u=None):
        circ = np.zeros(size)
        circ[:h.size] = h
        if h.size > 1:
            circ[size - h.size + 1:] = h[:0:-1]
        fh = np.fft.rfft(circ)
        own = np.zeros(kmax + 1)
        own[:min(h.size, kmax + 1)] = h[:kmax + 1]
        if u is None:
            v = np.fft.irfft(fs * fh[:, None], size, axis=0)[:m]
            own = (m - lags) * own
        else:
            v = sum(u[:, [d]] * toeplitz(fh, u[:, [d]] * s) for d in range(u.shape[1]))
            fuu = np.fft.rfft(u, size, axis=0)
            own = own * np.fft.irfft(np.sum(np.abs(fuu) ** 2, axis=1), size)[:kmax + 1]
        fv = np.fft.rfft(v, size, axis=0)
        fsc = fs @ (minv @ (s.T @ v) @ minv)
        cross = np.fft.irfft(np.sum(np.conj(fu) * fv + np.conj(fv) * fu - np.conj(fsc) * fs,
                                    axis=1), size)[:kmax + 1]
        return (own - cross) / m

    return basis


def nnls(a, b, max_iter=None):
    """min |a x - b| subject to x >= 0 (Lawson & Hanson 1974, active set).

    A dozen columns: importing scipy.optimize for it would cost 1-3 s, more than the whole
    identification.
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    n = a.shape[1]
    x = np.zeros(n)
    passive = np.zeros(n, dtype=bool)
    scale = np.linalg.norm(a, axis=0)
    scale[scale == 0] = 1.0
    a = a / scale
    tol = 1e-12 * max(1.0, float(np.abs(a.T @ b).max(initial=0.0)))
    for _ in range(max_iter or 3 * n):
        w = a.T @ (b - a @ x)
        if passive.all() or np.max(np.where(passive, -np.inf, w)) <= tol:
            break
        passive[int(np.argmax(np.where(passive, -np.inf, w)))] = True
        while True:
            z = np.zeros(n)
            z[passive] = np.linalg.lstsq(a[:, passive], b, rcond=None)[0]
            if np.all(z[passive] > 0):
                x = z
                break
            neg = passive & (z <= 0)
            alpha = np.min(x[neg] / (x[neg] - z[neg]))
            x = x + alpha * (z - x)
            passive &= x > 1e-15
            x[~passive] = 0.0
    return x / scale


def residual_acf(residuals, max_lag):
    """Biased sample autocovariance R_vv(k) = (1/N) sum_i v_i v_(i+k), k = 0..max_lag, by FFT."""
    n = residuals.size
    size = _fast_len(n + max_lag + 1)
    spec = np.fft.rfft(residuals, size)
    acov = np.fft.irfft(spec * np.conj(spec), size)[: max_lag + 1]
    return acov / n


def _inv_sym(m):
    """Inverse of a symmetric positive (semi)definite matrix, pseudo-inverse if singular."""
    try:
        inv = np.linalg.inv(m)
    except np.linalg.LinAlgError:
        inv = np.linalg.pinv(m)
    return 0.5 * (inv + inv.T)


def _fast_len(n):
    """Next power of two (numpy's FFT is fast there)."""
    return 1 << int(np.ceil(np.log2(max(n, 2))))
