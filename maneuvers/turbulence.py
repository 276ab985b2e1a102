"""Dryden turbulence: MIL-F-8785C shaping filters in plain numpy, run on whole arrays.

The gust field is frozen and the aircraft flies through it at the mean true airspeed V, so a
spatial spectrum with scale L becomes a temporal one with time constant L / V. Unit-intensity
white noise through the shaping filters gives the gust components along the flight path (u),
across it (v, to the right) and vertical (w, down).

Notes
-----
MIL-F-8785C (also MIL-HDBK-1797 Appendix, "Dryden form"), with V in m/s and L in m::

    H_u(s) = sigma_u sqrt(2 L_u / (pi V)) / (1 + (L_u/V) s)
    H_v(s) = sigma_v sqrt(L_v / (pi V)) (1 + sqrt(3) (L_v/V) s) / (1 + (L_v/V) s)^2
    H_w(s) = sigma_w sqrt(L_w / (pi V)) (1 + sqrt(3) (L_w/V) s) / (1 + (L_w/V) s)^2

driven by white noise of two-sided spectral density pi (so the output variance is sigma^2);
in discrete time at step dt that is unit Gaussian samples times sqrt(pi / dt). Autocorrelation
in distance xi: R_u = sigma_u^2 exp(-xi/L_u), R_v = sigma_v^2 (1 - xi/(2 L_v)) exp(-xi/L_v).

Low-altitude scales (h in feet, 10 ft <= h <= 1000 ft)::

    L_w = h,   L_u = L_v = h / (0.177 + 0.000823 h)^1.2,
    sigma_u / sigma_w = sigma_v / sigma_w = 1 / (0.177 + 0.000823 h)^0.4

Above 2000 ft the turbulence is isotropic with L = 1750 ft; in between, the scales and the
intensity ratio are interpolated linearly in altitude (as the MATLAB/Simulink Dryden block does).
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core.checks import integer, number, positive
from pitotcal.core.linear import zoh_transfer_function
from pitotcal.core.units import FT_TO_M

__all__ = ["DrydenScales", "along_path_gust", "discrete_dryden_filters", "dryden_filters",
           "dryden_gusts", "dryden_scales", "plunge_response"]

_LOW_FT, _HIGH_FT = 1000.0, 2000.0
_HIGH_SCALE_FT = 1750.0


@dataclass(frozen=True)
class DrydenScales:
    """Intensities (m/s, one standard deviation) and scale lengths (m) of the three gust axes."""

    sigma_u_mps: float
    sigma_v_mps: float
    sigma_w_mps: float
    length_u_m: float
    length_v_m: float
    length_w_m: float


def _low_altitude(h_ft):
    h = float(np.clip(h_ft, 10.0, _LOW_FT))
    base = 0.177 + 0.000823 * h
    return h / base ** 1.2, h, 1.0 / base ** 0.4          # L_uv, L_w (ft), sigma_uv / sigma_w


def dryden_scales(alt_m, sigma_horizontal_mps, length_m=None):
    """MIL-F-8785C scales at an altitude for a given horizontal intensity.

    Parameters
    ----------
    alt_m : float
        Height above ground, m (>= 0).
    sigma_horizontal_mps : float
        RMS of the horizontal gust components sigma_u = sigma_v, m/s (>= 0).
    length_m : float, optional
        Override of the horizontal scale length L_u = L_v, m (> 0).

    Returns
    -------
    DrydenScales
    """
    number("alt_m", alt_m, 0.0)
    number("sigma_horizontal_mps", sigma_horizontal_mps, 0.0)
    if length_m is not None:
        positive("length_m", length_m)
    h_ft = alt_m / FT_TO_M
    l_uv, l_w, ratio = _low_altitude(h_ft)
    if h_ft > _LOW_FT:
        # Blend to the isotropic medium/high-altitude model between 1000 and 2000 ft.
        f = min((h_ft - _LOW_FT) / (_HIGH_FT - _LOW_FT), 1.0)
        l_uv = l_uv + f * (_HIGH_SCALE_FT - l_uv)
        l_w = l_w + f * (_HIGH_SCALE_FT - l_w)
        ratio = ratio + f * (1.0 - ratio)
    l_uv_m = l_uv * FT_TO_M if length_m is None else float(length_m)
    sigma = float(sigma_horizontal_mps)
    return DrydenScales(sigma, sigma, sigma / ratio, l_uv_m, l_uv_m, l_w * FT_TO_M)


def _along_path_filter(scales, tas_mps):
    """Gain and time constant of H_u(s) = gain / (1 + tau s) (module Notes)."""
    t_u = scales.length_u_m / positive("tas_mps", tas_mps)
    return scales.sigma_u_mps * np.sqrt(2.0 * t_u / np.pi), t_u


def _white_noise(n, dt_s, scales, tas_mps, rng):
    """(burn, noise): the burn-in of ten time constants, in samples, and the unit-spectrum
    white noise (3, burn + n) that drives the three filters (one draw for all of them)."""
    integer("n", n, 1)
    positive("dt_s", dt_s)
    tau = max(scales.length_u_m, scales.length_v_m, scales.length_w_m) / tas_mps
    burn = int(np.ceil(10.0 * tau / dt_s))
    return burn, rng.standard_normal((3, burn + n)) * np.sqrt(np.pi / dt_s)


def dryden_filters(scales, tas_mps):
    """Continuous shaping filters (u, v, w) as transfer-function coefficients.

    Parameters
    ----------
    scales : DrydenScales
    tas_mps : float
        Mean true airspeed through the frozen field, m/s (> 0).

    Returns
    -------
    tuple of (ndarray, ndarray)
        (num, den) of H_u, H_v, H_w of the module Notes, polynomials in s with the highest
        power first (input: white noise of spectral density pi); what ``control.tf(num, den)``
        takes, for analysis with python-control.
    """
    gain_u, t_u = _along_path_filter(scales, tas_mps)
    v = float(tas_mps)
    t_v, t_w = scales.length_v_m / v, scales.length_w_m / v
    h_u = (np.array([gain_u]), np.array([t_u, 1.0]))

    def lateral(sigma, tau):
        gain = sigma * np.sqrt(tau / np.pi)
        return np.array([gain * np.sqrt(3.0) * tau, gain]), np.array([tau * tau, 2.0 * tau, 1.0])

    return h_u, lateral(scales.sigma_v_mps, t_v), lateral(scales.sigma_w_mps, t_w)


def discrete_dryden_filters(scales, tas_mps, dt_s):
    """The shaping filters discretised with a zero-order hold at step `dt_s`.

    Returns
    -------
    tuple of (ndarray, ndarray)
        (num, den) in powers of z^-1 of H_u, H_v, H_w, as ``scipy.signal.lfilter`` takes them.

    Notes
    -----
    `pitotcal.core.linear.zoh_transfer_function` of `dryden_filters`: what python-control's
    ``c2d(tf(num, den), dt_s, method="zoh")`` computes (through scipy's `cont2discrete`), to
    rounding, in plain numpy (importing scipy.signal costs `simulate` about 1 s on a busy
    machine). Its leading zero dropped, the response leads the hold's by one sample: the same
    gust process, since the input is white.
    """
    positive("dt_s", dt_s)
    return tuple(zoh_transfer_function(num, den, dt_s)
                 for num, den in dryden_filters(scales, tas_mps))


def _filter(num, den, x):
    """``scipy.signal.lfilter(num, den, x)`` for den[0] = 1 and at most second order, from rest:
    y_k = b0 x_k + b1 x_(k-1) + b2 x_(k-2) - a1 y_(k-1) - a2 y_(k-2), a plain loop over floats."""
    if len(num) > 3 or len(den) > 3:
        raise ValueError("_filter runs filters of at most second order")
    b0, b1, b2 = (*num, 0.0, 0.0, 0.0)[:3]
    _, a1, a2 = (*den, 0.0, 0.0)[:3]
    x1 = x2 = y1 = y2 = 0.0
    out = []
    for v in x.tolist():
        y = b0 * v + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2
        out.append(y)
        x2, x1, y2, y1 = x1, v, y1, y
    return np.array(out)


def dryden_gusts(n, dt_s, scales, tas_mps, rng):
    """Gust time series (u, v, w) of `n` samples at step `dt_s`, stationary from the first sample.

    Each filter is discretised with a zero-order hold (`discrete_dryden_filters`) and run over
    the whole noise array; a burn-in of ten time constants is discarded so the series starts in
    the stationary distribution rather than at zero.

    Parameters
    ----------
    n : int
        Number of samples.
    dt_s : float
        Sample step, s.
    scales : DrydenScales
    tas_mps : float
        Mean true airspeed, m/s.
    rng : numpy.random.Generator
        Source of the white noise (the only randomness used).

    Returns
    -------
    ndarray, shape (n, 3)
        Columns u (along the path), v (to the right), w (down), m/s.
    """
    burn, noise = _white_noise(n, dt_s, scales, tas_mps, rng)
    out = np.empty((n, 3))
    for j, (num, den) in enumerate(discrete_dryden_filters(scales, tas_mps, dt_s)):
        out[:, j] = _filter(num, den, noise[j])[burn:]
    return out


def along_path_gust(n, dt_s, scales, tas_mps, rng):
    """The along-path gust alone, in plain numpy: ``dryden_gusts(...)[:, 0]`` to rounding.

    The same noise draws and burn-in as `dryden_gusts`, and the same recursion its
    zero-order-hold filter runs (y_k = c x_k + a y_(k-1), a = exp(-dt / tau_u),
    c = gain (1 - a)), with `a` and `c` in closed form: the plan command's auto-throttle check
    needs the along-path gust alone.

    Returns
    -------
    ndarray (n,)
        u_g, m/s.
    """
    burn, noise = _white_noise(n, dt_s, scales, tas_mps, rng)
    gain, tau = _along_path_filter(scales, tas_mps)
    a = float(np.exp(-dt_s / tau))
    c, y = gain * (1.0 - a), 0.0
    out = []
    for x in noise[0].tolist():
        y = c * x + a * y
        out.append(y)
    return np.array(out[burn:])


# Plunge (heave) of the aircraft in a vertical gust: a gust changes the angle of attack, the
# lift change accelerates the aircraft with the air mass, dv_z/dt = (w_air - v_z) / tau_p,
# tau_p = 2 (W/S) / (g rho V C_L_alpha) (Etkin & Reid, "Dynamics of Flight", the plunge mode).
# A light aircraft's wing loading and lift slope; tau_p ~ 0.5 s at 40 m/s near sea level.
WING_LOADING_NPM2 = 600.0
LIFT_SLOPE_PER_RAD = 5.0


def plunge_response(w_down_mps, dt_s, tas_mps, rho_kgm3, k_alt_per_s):
    """The aircraft's response to the vertical gust: altitude offset and climb-rate offset.

    Parameters
    ----------
    w_down_mps : ndarray (n,)
        Vertical gust, positive down (`dryden_gusts` column w), on a grid of step `dt_s`.
    tas_mps, rho_kgm3 : float
        Mean true airspeed and density of the flight.
    k_alt_per_s : float
        Gain of the autopilot's altitude hold (climb command per metre of error), which
        pulls the offset back.

    Returns
    -------
    dh_m, vz_mps : ndarray (n,)
        Altitude offset and the aircraft's extra climb rate (up), by forward Euler of
        dv_z/dt = (-w - v_z) / tau_p and dh/dt = v_z - k_alt dh (linear, so it adds to the
        flight the autopilot flies). The air-relative vertical velocity is then
        v_z + climb - (-w): the fast part of the gust, what reaches the angle of attack.
    """
    tau = 2.0 * WING_LOADING_NPM2 / (9.80665 * rho_kgm3 * tas_mps * LIFT_SLOPE_PER_RAD)
    a = min(dt_s / tau, 1.0)
    vz, dh = np.zeros(w_down_mps.size), np.zeros(w_down_mps.size)
    v = h = 0.0
    for i, w in enumerate((-np.asarray(w_down_mps, dtype=float)).tolist()):
        vz[i], dh[i] = v, h
        v, h = v + a * (w - v), h + dt_s * (v - k_alt_per_s * h)
    return dh, vz
