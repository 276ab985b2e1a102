"""Parameter covariance of the output-error estimate: plain and corrected for colored residuals.

At 50 Hz in turbulence, or with 5 Hz sample-and-hold GPS, the residuals are strongly
correlated and the plain bounds s^2 (J^T J)^-1 come out 2-20x too small (docs/measured.md). The
corrected covariance (Morelli & Klein, SIDPAC `colores`) is what `std` and every band report.
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core.information import student_t_widening

from .residual_noise import _fast_len, _inv_sym, block_means, residual_acf

__all__ = [
    "ColoredCovariance",
    "colored_covariance",
    "known_gps_error",
    "lag_weights",
    "plain_covariance",
    "residual_acf",
    "student_t_widening",
    "truncation_lag",
]

# Fewer independent stretches (N / 2 tau) than this: warn that the bounds are rough.
MIN_STRETCHES = 10
# A lag window shorter than this cannot describe even sample-and-hold GPS at 5 Hz in 50 Hz data.
MIN_LAG = 10


def known_gps_error(gps_error, time_s):
    """A stated GPS velocity error (sigma_mps, tau_s) as `colored_covariance` takes it (`known_velocity`), tau in
    samples of the median interval; None when none is stated."""
    if gps_error is None:
        return None
    return gps_error[0], gps_error[1] / max(float(np.median(np.diff(time_s))), 1e-9)

def plain_covariance(jac, residuals, information=None):
    """Plain (Cramer-Rao) covariance s^2 M^-1, M = J^T J or the given information matrix.

    Parameters
    ----------
    jac : ndarray, shape (N, p)
        Output sensitivities dr/dtheta at the optimum.
    residuals : ndarray, shape (N,)
        Output residuals, Pa.
    information : ndarray, shape (p, p), optional
        M from the exact Hessian of the objective (`estimation.identification.oe`); J^T J when None.

    Returns
    -------
    ndarray, shape (p, p)
        With s^2 = r^T r / (N - p).
    """
    n, p = jac.shape
    s2 = float(residuals @ residuals) / max(n - p, 1)
    return s2 * _inv_sym(jac.T @ jac if information is None else information)


@dataclass(frozen=True)
class ColoredCovariance:
    """The colored-residual covariance and how it was computed."""

    covariance: np.ndarray
    lag: int                 # last lag of R_vv used, samples
    window: str
    ar1: float               # exponential: decay per sample; windows: lag-1 autocorrelation
    warning: str | None = None
    dof: float = float("inf")  # degrees of freedom of the noise-model fit (Student-t widening)

    def describe(self):
        return f"{self.window} R_vv, {self.lag} lags (decay/AR(1) {self.ar1:.4f} per sample)"


def truncation_lag(residuals, window="bartlett"):
    """Andrews' (1991) AR(1) plug-in truncation lag, samples, and the fitted AR(1) coefficient.

    Notes
    -----
    Bartlett: L = 1.1447 (alpha1 N)^(1/3), alpha1 = 4 a^2 / ((1 - a)^2 (1 + a)^2);
    Parzen:   L = 2.6614 (alpha2 N)^(1/5), alpha2 = 4 a^2 / (1 - a)^4,
    with a the lag-1 autocorrelation of the residuals. Clipped to [MIN_LAG, N / 4].
    """
    n = residuals.size
    v = residuals - residuals.mean()
    a = float(v[1:] @ v[:-1]) / max(float(v[:-1] @ v[:-1]), 1e-300)
    a = min(max(a, 0.0), 0.9999)
    if window == "bartlett":
        alpha = 4 * a * a / ((1 - a) ** 2 * (1 + a) ** 2)
        lag = 1.1447 * (alpha * n) ** (1 / 3)
    elif window == "parzen":
        alpha = 4 * a * a / (1 - a) ** 4
        lag = 2.6614 * (alpha * n) ** (1 / 5)
    else:
        raise ValueError(f"window {window!r} is not one of bartlett, parzen")
    return int(np.clip(np.ceil(lag), MIN_LAG, max(MIN_LAG, n // 4))), a


def lag_weights(lag, window="bartlett"):
    """Lag-window weights w(k), k = 0..lag."""
    x = np.arange(lag + 1) / (lag + 1)
    if window == "bartlett":
        return 1.0 - x
    # Parzen
    return np.where(x <= 0.5, 1 - 6 * x ** 2 + 6 * x ** 3, 2 * (1 - x) ** 3)


def colored_covariance(jac, residuals, *, window="multiscale", lag=None, information=None,
                       instruments=None, velocity=None, known_velocity=None):
    """Covariance corrected for colored residuals (Morelli & Klein 1997; SIDPAC `colores`).

    Parameters
    ----------
    jac : ndarray, shape (N, p)
        Output sensitivities S = dr/dtheta at the optimum.
    residuals : ndarray, shape (N,)
    window : {"multiscale", "exponential", "bartlett", "parzen"}
        How R_vv is formed: "multiscale" (default) models it as white noise plus exponentials
        of several correlation times, in the pressure and in the velocity
        (`estimation.uncertainty.residual_noise`); "exponential" as white noise plus one
        exponential decay; "bartlett" and "parzen" taper the sample autocovariance with that
        lag window.
    lag : int, optional
        Truncation lag of "bartlett"/"parzen", samples; Andrews' AR(1) plug-in when None.
    information : ndarray, shape (p, p), optional
        M from the exact Hessian of the objective; S^T S when None.
    velocity, known_velocity : ndarray (N, 2), (float, float), optional
        The residual's sensitivities to a velocity disturbance (the wind columns of S): with
        "multiscale", GPS velocity error and gusts enter as u . d, modulated by the heading;
        and (sigma_mps, tau_samples) of a stated Gauss-Markov velocity error.

    Returns
    -------
    ColoredCovariance

    Notes
    -----
    For one output with noise variance R,

        Cov = M^-1 [ sum_i sum_j S_i^T R^-1 R_vv(|i-j|) R^-1 S_j ] M^-1,  M = S^T R^-1 S,

    and R cancels: Cov = (S^T S)^-1 S^T (H S) (S^T S)^-1 with H the Toeplitz matrix of
    h(k) = w(k) R_vv(k). H S is a convolution of each sensitivity column with h, done by FFT
    O(N log N). Summing every lag of a sample autocovariance is degenerate, so R_vv needs a
    model or a lag window; the models are fitted to the autocovariance as the fit leaves it
    and widened for their few degrees of freedom (`student_t_widening`).
    Coverage of each model on the noise cases: docs/measured.md ("Bounds under real noise");
    Bartlett with Andrews' plug-in lag gave 86% on the T-2 flight. Lags count samples as given;
    time gaps are treated as adjacent samples (`OutputErrorProblem` warns when gaps are not
    rare). White residuals: the plain s^2 (S^T S)^-1.
    """
    n, p = jac.shape
    a, dof, step, h_vel = 0.0, float("inf"), 1, None
    if window == "multiscale":
        from .residual_noise import multiscale_acov
        fit, a, dof = multiscale_acov(residuals, jac, velocity, known_velocity)
        h, h_vel, step, lag = fit.h, fit.h_vel, fit.step, (fit.h.size - 1) * fit.step
    elif window == "exponential":
        h, lag, a, dof = _exponential_acov(residuals, jac)
    else:
        if lag is None:
            lag, a = truncation_lag(residuals, window)
        lag = int(min(lag, n - 1))
        acov = residual_acf(residuals, lag) * n / max(n - p, 1)
        h = lag_weights(lag, window) * acov
    # h is the autocovariance of block means of `step` samples: S^T e = step S_b^T e_b
    x = block_means(jac if instruments is None else instruments, step)
    middle = step ** 2 * (x.T @ _toeplitz_times(h, x))
    if h_vel is not None:        # e_i = u_i . d_i: sum over d's components of (x u_d)^T H (x u_d)
        for col in block_means(velocity, step).T:
            xu = x * col[:, None]
            middle += step ** 2 * (xu.T @ _toeplitz_times(h_vel, xu))
    if instruments is None:
        m_inv = _inv_sym(jac.T @ jac if information is None else information)
        cov = m_inv @ (0.5 * (middle + middle.T)) @ m_inv
    else:
        # instrumental variables: A^-1 Z^T R_vv Z A^-T, A = Z^T S
        a_inv = np.linalg.inv(instruments.T @ jac if information is None else information)
        cov = a_inv @ (0.5 * (middle + middle.T)) @ a_inv.T
    # The noise model is fitted to one record: its long-run variance has few degrees of
    # freedom (T / (4 tau) for one exponential, `DOF_TAUS`): Student-t widening.
    cov = cov * student_t_widening(dof) ** 2
    return ColoredCovariance(cov, lag, window, a, _few_stretches(residuals), dof)


def _few_stretches(residuals):
    """The warning when the record holds fewer than MIN_STRETCHES independent stretches, else
    None.

    A stretch is 2 tau = 1 + 2 sum_k rho_k samples, the residuals' autocorrelation summed up
    to its first zero (their integral time scale), measured on the residuals themselves: the
    fitted model's long-run-weighted correlation time is no measure of it, as its slowest term
    lands near the longest time its grid allows (a fifth of the record) on about half of the
    flights in plain turbulence (docs/measured.md, "The few-stretches warning").
    """
    v = residuals - residuals.mean()
    acov = residual_acf(v, v.size // 4)
    if acov.size < 2 or not acov[0] > 0.0:
        return None
    rho = acov[1:] / acov[0]
    first_zero = np.flatnonzero(rho <= 0.0)
    two_tau = 1.0 + 2.0 * float(rho[:first_zero[0] if first_zero.size else rho.size].sum())
    stretches = v.size / two_tau
    if stretches >= MIN_STRETCHES:
        return None
    return (f"residuals correlated over ~{two_tau:.0f} samples: only ~{stretches:.0f} "
            "independent stretches of data, so the corrected bounds are themselves "
            f"uncertain by ~{100 / np.sqrt(max(stretches, 1.0)):.0f}%; fly longer")


def _exponential_acov(residuals, jac):
    """Residual autocovariance modelled as white noise plus an exponential decay.

    Returns (h, lag, a): h(k) = white * [k == 0] + amp * a^k for k = 0..lag, summed out to
    a^k = 1e-4, and the decay per sample a.

    Notes
    -----
    When the correlation time is long (turbulence: hundreds of samples at 50 Hz), fitting
    k1 and k2 removes the slow part of the noise that lies along their sensitivities (the
    q ramp) from the residuals, so the residuals' own autocovariance decays too fast and
    dips below zero; a model fitted to it made the k1/k2 bounds ~1.3x too small
    (coverage 80% in 1 m/s simulator turbulence). `_fit_projected` therefore fits the model
    to what the residuals should show, E[acov((I - P) e)], P = S (S^T S)^-1 S^T. Short
    correlation times (ke < MIN_FIT_TAU * step) lose nothing to the projection and are fitted
    directly at full rate.
    """
    n = residuals.size
    p = jac.shape[1]
    kmax = int(min(n // 4, 20000))
    acov = residual_acf(residuals, kmax) * n / max(n - p, 1)
    # lag-1 correlation within sampling noise of zero (~1/sqrt(N)): white residuals
    if acov[1] <= 3.0 * acov[0] / np.sqrt(n):
        return acov[:1], 0, float(acov[1] / acov[0]), float("inf")
    below = np.nonzero(acov[1:] < acov[1] / np.e)[0]
    ke = int(below[0]) + 1 if below.size else kmax      # 1/e lag of the sample ACF
    step = int(np.ceil(n / FIT_SAMPLES))
    dof = float("inf")
    if ke >= MIN_FIT_TAU * step:
        tau = _decay_from_increments(residuals, ke)
        white, amp, _ = _fit_projected(jac[::step], residuals[::step], ke / step, tau=tau / step)
        dof = n / (DOF_TAUS * tau)
    else:
        white, amp, tau = _fit_direct(acov, ke)
    a = float(np.exp(-1.0 / max(tau, 1e-3)))
    lag = int(min(np.ceil(tau * np.log(1e4)), n - 1))
    h = amp * a ** np.arange(lag + 1)
    h[0] += white
    return h, lag, a, dof


def _decay_from_increments(residuals, ke):
    """Decay time (samples) of white + exponential noise from the residuals' increments.

    gamma(k) = white + amp (1 - a^k) for k >= 1, so gamma(2s) - gamma(s) ~ amp s / tau for
    s << tau (the white part cancels) and tau ~ s var / (gamma(2s) - gamma(s)). Every increment
    counts, so the decay is known to CV ~ sqrt(2 tau / T) (0.23 measured on the T-2 flight)
    where a fit to the autocovariance's shape leans on its noisy long lags (CV 0.8 measured,
    the main cause of the k1/k2 bounds' run-to-run scatter and, with the gust bias, of their 89%
    coverage when the decay comes from that fit).
    """
    n = residuals.size
    s = max(round(ke / 12), 2)
    v = residuals - residuals.mean()
    g1 = 0.5 * np.mean((v[s:] - v[:-s]) ** 2)
    g2 = 0.5 * np.mean((v[2 * s:] - v[:-2 * s]) ** 2)
    tau = s * float(np.mean(v * v)) / max(g2 - g1, 1e-300)
    return float(np.clip(tau, 2.0 * s, n / 4.0))


# The noise model of long correlation times is fitted on every step-th sample, at most this
# many samples: the decay spans hundreds of samples, so thinning loses nothing and the fit
# costs the same at N = 1e6 as at 16,000.
FIT_SAMPLES = 4000
# Degrees of freedom of the fitted noise model: one per DOF_TAUS correlation times.
DOF_TAUS = 4.0
# Thinned, the 1/e lag must still span this many samples to be resolved.
MIN_FIT_TAU = 4
# The fit uses lags up to this many 1/e lags.
FIT_LAGS = 6


def _fit_direct(acov, ke):
    """White + exponential from the sample autocovariance: the decay from its 1/e crossing."""
    r1 = acov[1]
    lo, hi = acov[ke - 1], acov[ke]            # crossing of r1/e between lags ke-1 and ke
    frac = (lo - r1 / np.e) / max(lo - hi, 1e-300)
    tau = max(ke - 1 + frac - 1.0, 0.2)        # R(k)/R(1) = a^(k-1)
    amp = min(r1 * np.exp(1.0 / tau), acov[0])
    return max(acov[0] - amp, 0.0), amp, tau


def _fit_projected(s, r, ke, tau=None):
    """Fit (white, amp, tau) so that E[acov((I - P) e)] matches the residuals' acov.

    With e of autocovariance R (Toeplitz Sigma) and X = (I - P) Sigma (I - P),
    E[sum_i r_i r_(i+k)] = sum_i X_(i, i+k) = (m - k) R(k) - c_UV(k) - c_VU(k) + c_(SC)S(k),
    U = S M^-1, V = Sigma S, C = M^-1 S^T V M^-1, c_xy(k) = sum_i x_i . y_(i+k): FFT
    cross-correlations, O(p m log m) per trial decay. Linear in (white, amp) for a given
    decay: non-negative least squares for those, a log-grid and golden section for tau.
    """
    m = s.shape[0]
    minv = _inv_sym(s.T @ s)
    kfit = int(min(np.ceil(FIT_LAGS * (ke if tau is None else tau)), m // 4))
    obs = residual_acf(r, kfit)
    size = _fast_len(2 * m)
    fs = np.fft.rfft(s, size, axis=0)
    fu = fs @ minv
    lags = np.arange(kfit + 1)

    def basis(h):
        circ = np.zeros(size)
        circ[:h.size] = h
        circ[size - h.size + 1:] = h[:0:-1]
        v = np.fft.irfft(fs * np.fft.rfft(circ)[:, None], size, axis=0)[:m]
        fv = np.fft.rfft(v, size, axis=0)
        fsc = fs @ (minv @ (s.T @ v) @ minv)
        cross = np.fft.irfft(np.sum(np.conj(fu) * fv + np.conj(fv) * fu - np.conj(fsc) * fs,
                                    axis=1), size)[:kfit + 1]
        own = np.zeros(kfit + 1)
        own[:min(h.size, kfit + 1)] = h[:kfit + 1]
        return ((m - lags) * own - cross) / m

    b_white = basis(np.ones(1))

    def fit(tau):
        a = np.exp(-1.0 / tau)
        b_exp = basis(a ** np.arange(int(min(np.ceil(tau * np.log(1e4)), m - 1)) + 1))
        coef, sse = _nnls2(b_white, b_exp, obs)
        return sse, coef

    if tau is not None:                          # decay given: amplitudes only
        _, (white, amp) = fit(tau)
        return white, amp, tau
    taus = np.geomspace(max(ke / 4, 0.3), 12 * ke, 12)
    i = int(np.argmin([fit(t)[0] for t in taus]))
    lo, hi = np.log(taus[max(i - 1, 0)]), np.log(taus[min(i + 1, taus.size - 1)])
    g = (np.sqrt(5) - 1) / 2                     # golden section on log tau
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = fit(np.exp(x1))[0], fit(np.exp(x2))[0]
    for _ in range(8):
        if f1 < f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - g * (hi - lo)
            f1 = fit(np.exp(x1))[0]
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + g * (hi - lo)
            f2 = fit(np.exp(x2))[0]
    tau = float(np.exp(0.5 * (lo + hi)))
    _, (white, amp) = fit(tau)
    return white, amp, tau


def _nnls2(b1, b2, y):
    """min |c1 b1 + c2 b2 - y|^2 over c1, c2 >= 0; returns ((c1, c2), sse)."""
    best = None
    gram = np.array([[b1 @ b1, b1 @ b2], [b1 @ b2, b2 @ b2]])
    rhs = np.array([b1 @ y, b2 @ y])
    candidates = [np.array([rhs[0] / gram[0, 0], 0.0]), np.array([0.0, rhs[1] / gram[1, 1]])]
    if abs(np.linalg.det(gram)) > 1e-300:
        candidates.append(np.linalg.solve(gram, rhs))
    for c in candidates:
        if np.all(c >= 0):
            sse = float(np.sum((c[0] * b1 + c[1] * b2 - y) ** 2))
            if best is None or sse < best[1]:
                best = (c, sse)
    return best if best is not None else (np.zeros(2), float(y @ y))


def _toeplitz_times(h, x):
    """H @ x for the symmetric Toeplitz H with first row h (zero beyond), by FFT.

    numpy's FFT rather than scipy.signal: importing scipy.signal costs ~0.3-1.7 s, more than
    the whole identification at N = 16,000.
    """
    n = x.shape[0]
    lag = h.size - 1
    if lag == 0:
        return h[0] * x
    kernel = np.concatenate([h[::-1], h[1:]])             # lags -L..L
    size = _fast_len(n + 2 * lag)
    conv = np.fft.irfft(np.fft.rfft(x, size, axis=0) * np.fft.rfft(kernel, size)[:, None],
                        size, axis=0)
    return conv[lag:lag + n]
