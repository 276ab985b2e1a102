"""A slowly varying wind in the output-error problem: a drift basis in time, its joint fit with
the pressure-error model, the choice between a constant and a drifting wind, and the track.

The wind is the mean wind plus a drift, W(t) = W_mean + B(t) d: B holds piecewise-linear hat
functions in time with knots every `knot_s` seconds in each calibration window
(`Flight.segment`), each column centred on the record, so W_mean stays the time-average wind
and each window keeps a wind of its own; d holds the knot values (north, then east). Given d,
the problem is the constant-wind one on the flight with B d taken out of the GPS ground
velocity (V_t = V_g − W_mean − B d): every downstream step (the IPOPT solve, the instrumental
variables, the checks, the budget, the legs) works unchanged on that flight.

`fit_wind` estimates d jointly with the coefficients and the mean wind by Gauss-Newton on the
whole residual (`_joint_gauss_newton`), then solves the constant problem given d with the
usual pipeline, so the result is a stationary point of the joint problem. The reported
covariance of k and of the mean wind is widened by the wind's freedom: the same colored-
residual sandwich of the whole problem minus that of the constant one (`_covariances`).

Constant or drifting is chosen by the data: a Wald test of d = 0 with the whole problem's
colored-residual covariance (a likelihood ratio or a BIC with N = 10^4 samples correlated over
seconds would choose a drift on nearly every turbulent flight).
"""

import dataclasses

import numpy as np

from pitotcal.core import checks
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model
from pitotcal.core.units import wind_polar

from ..uncertainty.covariance import colored_covariance, known_gps_error, plain_covariance
from .residual import flight_channels, residual, sensitivities
from .unknowns import WIND, to_reported

__all__ = ["DEFAULT_KNOT_S", "DRIFT_MATTERS_MPS", "DRIFT_TEST_ALPHA", "GN_WIND_TOL_MPS",
           "WIND_MODES", "DriftBasis", "check_wind_options", "constant_wind", "drift_columns",
           "fit_wind", "gauss_newton_step", "shifted"]

WIND_MODES = ("auto", "constant", "drifting")
# Knot spacing of the drift, s: long against an orbit (1-3 min at 40-60 m/s on a 600-900 m
# circle), so within one knot interval the heading turns through every direction and the
# wind still separates from the calibration; a 15-minute flight gets 3 intervals. A flight
# that turns more slowly gets knots `ORBITS_PER_KNOT` of its revolutions apart.
DEFAULT_KNOT_S = 300.0
ORBITS_PER_KNOT = 2.0
MIN_KNOT_S = 30.0
# Test level of d = 0: a false drift on 1 % of constant-wind flights when the bounds are honest
DRIFT_TEST_ALPHA = 0.01
# A fitted drift moving the wind more than this over the record is a warning, m/s
DRIFT_MATTERS_MPS = 1.0
# Points of the reported wind track per knot interval
TRACK_POINTS_PER_KNOT = 6
_GN_ITERATIONS = 6
# The joint Gauss-Newton has converged when the wind (mean and drift) moves less than this, m/s
GN_WIND_TOL_MPS = 1e-4


@dataclasses.dataclass(frozen=True)
class DriftBasis:
    """Hat functions in time per calibration window, centred on the record.

    Attributes
    ----------
    knots : tuple of ndarray
        Knot times (s) of each window, in window order.
    means : ndarray, shape (m,)
        Each column's mean over the record (subtracted: W_mean stays the time-average).
    knot_s : float
        The requested knot spacing, s.
    labels : tuple of int or None
        The `Flight.segment` value of each window (None: 0, 1, ...): a flight cut to some of
        a log's windows keeps their numbers.
    """

    knots: tuple
    means: np.ndarray
    knot_s: float
    labels: tuple | None = None

    @property
    def window_labels(self):
        """The `Flight.segment` value of each window, in window order."""
        return tuple(range(len(self.knots))) if self.labels is None else self.labels

    @property
    def size(self):
        """Drift columns per wind component."""
        return self.means.size

    def rows(self, time_s, segment=None):
        """B at `time_s` (samples of window `segment`, None: window 0), shape (N, m)."""
        time_s = np.asarray(time_s, dtype=float)
        seg = np.zeros(time_s.size, dtype=int) if segment is None else np.asarray(segment)
        cols = []
        for s, knots in zip(self.window_labels, self.knots):
            inside = seg == s
            for j in range(knots.size):
                unit = np.zeros(knots.size)
                unit[j] = 1.0
                cols.append(np.where(inside, np.interp(time_s, knots, unit), 0.0))
        full = np.column_stack(cols)[:, :self.means.size]
        return full - self.means


def default_knot_s(flight):
    """The default knot spacing of `flight`, s: `DEFAULT_KNOT_S`, or `ORBITS_PER_KNOT` times
    the time its ground track takes to turn through 360 deg when that is longer."""
    t = flight.time_s
    if t.size < 2 or t[-1] <= t[0]:
        return DEFAULT_KNOT_S
    # course every second: GPS noise summed over every sample would add turns of its own
    grid = np.arange(t[0], t[-1], 1.0)
    course = np.unwrap(np.arctan2(np.interp(grid, t, flight.gps_ve_mps),
                                  np.interp(grid, t, flight.gps_vn_mps)))
    turns = float(np.sum(np.abs(np.diff(course)))) / (2.0 * np.pi)
    if turns <= 0:
        return DEFAULT_KNOT_S
    return max(DEFAULT_KNOT_S, ORBITS_PER_KNOT * (t[-1] - t[0]) / turns)


def drift_basis(time_s, segment, knot_s):
    """The `DriftBasis` of a record: knots about `knot_s` s apart or more in each window (at
    least its two ends: a linear drift), the last column dropped (centred hats sum to zero)."""
    seg = np.zeros(time_s.size, dtype=int) if segment is None else np.asarray(segment, int)
    labels = tuple(int(s) for s in np.unique(seg))
    knots = []
    for s in labels:
        t = time_s[seg == s]
        if t.size < 2 or t[-1] <= t[0]:
            knots.append(np.array([t[0], t[0] + 1.0]))
            continue
        n_int = max(1, int((t[-1] - t[0]) // knot_s))
        knots.append(np.linspace(t[0], t[-1], n_int + 1))
    raw = DriftBasis(tuple(knots), np.zeros(sum(k.size for k in knots) - 1), float(knot_s),
                     labels)
    means = np.mean(raw.rows(time_s, seg), axis=0)
    return dataclasses.replace(raw, means=means)


def window_basis(time_s, segment):
    """One wind per calibration window: a centred indicator column per window (one knot each,
    the last column dropped), for several windows whose wind has no drift within them."""
    seg = np.asarray(segment, int)
    labels = tuple(int(s) for s in np.unique(seg))
    knots = tuple(time_s[seg == s][:1] for s in labels)
    raw = DriftBasis(knots, np.zeros(len(knots) - 1), 0.0, labels)
    return dataclasses.replace(raw, means=np.mean(raw.rows(time_s, seg), axis=0))


def check_wind_options(wind, knot_s):
    """(wind, knot_s) checked: a choice of `WIND_MODES` and a knot spacing, s (None: the
    flight's `default_knot_s`)."""
    checks.choice("wind", wind, WIND_MODES)
    if knot_s is None:
        return wind, None
    return wind, checks.number("wind_knot_s", knot_s, MIN_KNOT_S, 1e6)


def _held_drift(drift, vn, ve):
    """`drift` held where the GPS velocity is held (equal consecutive samples), so taking it
    out of the velocity keeps the sample-and-hold pattern `interpolate_held` detects."""
    same = np.concatenate([[False], (np.diff(vn) == 0) & (np.diff(ve) == 0)])
    idx = np.maximum.accumulate(np.where(same, 0, np.arange(vn.size)))
    return drift[idx]


def without_drift(flight, basis, d):
    """`flight` with the drift B d taken out of its GPS ground velocity (north, east)."""
    b = basis.rows(flight.time_s, flight.segment)
    m = basis.size
    dn, de = (_held_drift(b @ d[i * m:(i + 1) * m], flight.gps_vn_mps, flight.gps_ve_mps)
              for i in range(2))
    return dataclasses.replace(flight, gps_vn_mps=flight.gps_vn_mps - dn,
                               gps_ve_mps=flight.gps_ve_mps - de)


def _whole_jacobian(model, theta, ch, b):
    """(r, S): the residual and its sensitivities to (theta, d_n, d_e) at the drift already
    taken out of `ch`."""
    jac = sensitivities(model, theta, *_args(ch))
    r = residual(model, theta, *_args(ch))
    return r, np.hstack([jac, drift_columns(jac, b)])


def drift_columns(jac, b):
    """The sensitivities to (d_n, d_e): the wind columns of `jac` (its last two) times B."""
    return np.hstack([jac[:, [-2]] * b, jac[:, [-1]] * b])


def _args(ch):
    return ch.qci, ch.vn, ch.ve, ch.air, ch.vd2, ch.c_eiv


def shifted(ch, b, d):
    """Channels `ch` with the drift B d taken out of the GPS velocity (north, east)."""
    m = b.shape[1]
    if m == 0:
        return ch
    return dataclasses.replace(ch, vn=ch.vn - b @ d[:m], ve=ch.ve - b @ d[m:])


def gauss_newton_step(jac, r):
    """The Gauss-Newton step of the residual `r` with sensitivities `jac`, the columns scaled
    to unit RMS for the least squares."""
    scale = np.sqrt(np.mean(jac ** 2, axis=0))
    scale[scale == 0] = 1.0
    return np.linalg.lstsq(jac / scale, -r, rcond=None)[0] / scale


def _joint_gauss_newton(model, theta, ch, b):
    """(theta, d): Gauss-Newton on the whole residual in (theta, d) from theta and d = 0."""
    d = np.zeros(2 * b.shape[1])
    p = theta.size
    for _ in range(_GN_ITERATIONS):
        r, jac = _whole_jacobian(model, theta, shifted(ch, b, d), b)
        step = gauss_newton_step(jac, r)
        theta, d = theta + step[:p], d + step[p:]
        if np.max(np.abs(step[p - 2:])) < GN_WIND_TOL_MPS:
            break
    return theta, d


def _covariances(model, theta, ch, b, r, known, test_only=False):
    """(whole, whole_plain, constant, constant_plain): the colored-residual and plain
    covariances of (theta, d) and of theta alone at the same residuals (the same noise model).

    `test_only`: the whole problem's alone (the test of no drift). Its noise model is the
    multiscale one too: with one exponential the test chose a drift on 15 of 30 constant-wind
    default flights with 0.5 m/s GPS noise in 0.5 m/s turbulence (Wald statistics up to 60 on
    2 dof) and k1's 2σ then covered 89 of 100 (study noise); with the multiscale model, 0 of 30.
    """
    _, full = _whole_jacobian(model, theta, ch, b)
    p = theta.size
    out = []
    for jac in (full,) if test_only else (full, full[:, :p]):
        colored = colored_covariance(jac, r, velocity=jac[:, p - 2:p], known_velocity=known,
                                     window="multiscale")
        out += [colored.covariance, plain_covariance(jac, r)]
    return tuple(out)


def _psd(matrix):
    """The positive semi-definite part of a symmetric matrix."""
    w, v = np.linalg.eigh(0.5 * (matrix + matrix.T))
    return (v * np.clip(w, 0.0, None)) @ v.T


def wald_test(d, cov_dd):
    """{"statistic", "dof", "p_value", "alpha"}: the Wald test of d = 0 with `cov_dd`.

    d holds a north and an east value per knot, so the degrees of freedom are even and the
    chi-square tail is closed: exp(-x/2) sum_{j < dof/2} (x/2)^j / j! (no scipy.stats import,
    0.5 s of a command's start).
    """
    stat = float(d @ np.linalg.pinv(cov_dd) @ d)
    dof = int(d.size)
    half = 0.5 * max(stat, 0.0)
    terms = np.cumprod(np.concatenate([[1.0], half / np.arange(1, dof // 2)]))
    p_value = float(np.exp(-half) * np.sum(terms)) if dof >= 2 else 1.0
    return {"name": "Wald test of no drift (colored-residual covariance, multiscale noise)",
            "statistic": stat, "dof": dof, "p_value": min(p_value, 1.0),
            "alpha": DRIFT_TEST_ALPHA}


def _kept(flight, result):
    """`flight`'s samples the result kept (outlier trimming, a collapsed tail)."""
    if result.n_samples == flight.n:
        return flight
    return flight.select(np.isin(flight.time_s, result.time_s))


def fit_wind(flight, fit_constant, *, wind, knot_s, gps_noise_std_mps, air_data, gps_error):
    """(result, warnings): the calibration with the wind the data call for.

    Parameters
    ----------
    flight : Flight
        The gated flight.
    fit_constant : callable
        flight -> (IdentificationResult, warnings): the constant-wind fit with its trimming and
        checks (`estimation.identification.fit._fit_trimmed`).
    wind : {"auto", "constant", "drifting"}
        "auto": drifting when the Wald test rejects d = 0 at `DRIFT_TEST_ALPHA`.
    knot_s : float
        Knot spacing of the drift, s.
    gps_noise_std_mps, air_data, gps_error
        As `identify` uses them (the GPS noise; the air-data mode; a stated GPS error).

    Returns
    -------
    (IdentificationResult, tuple of str)
        The result carries `wind_model` {kind, knot_s, test, chosen_by} and `wind_track`
        {time_s, speed_mps, from_deg, speed_2sigma_mps, from_2sigma_deg, segment}.
    """
    result, notes = fit_constant(flight)
    result = dataclasses.replace(result, source=str(flight.source))   # the warnings name it
    if not result.success or (wind == "constant" and _windows(flight) < 2):
        chosen = "option" if wind == "constant" else "the constant fit did not converge"
        return _constant(result, None, knot_s, chosen), notes
    kept = _kept(flight, result)
    model = get_model(result.model)
    sigma = result.gps_noise_std_mps if gps_noise_std_mps is None else gps_noise_std_mps
    ch = flight_channels(kept, sigma, air_data)
    fitted = (model, ch, kept, air_data, known_gps_error(gps_error, kept.time_s))
    if wind == "constant":              # several windows: still a wind for each
        return _per_window(flight, fit_constant, result, None, knot_s, "option", fitted, notes)
    knot_s = default_knot_s(kept) if knot_s is None else knot_s
    basis = drift_basis(kept.time_s, kept.segment, knot_s)
    b = basis.rows(kept.time_s, kept.segment)
    theta, d = _joint_gauss_newton(model, result.internal_params, ch, b)
    r = residual(model, theta, *_args(shifted(ch, b, d)))
    cov = _covariances(model, theta, shifted(ch, b, d), b, r, fitted[-1], test_only=True)
    p = theta.size
    test = wald_test(d, cov[0][p:, p:])
    if wind == "auto" and not test["p_value"] < DRIFT_TEST_ALPHA:
        if _windows(kept) > 1:          # no drift within them: still a wind for each
            return _per_window(flight, fit_constant, result, test, knot_s, "auto: Wald test",
                               fitted, notes)
        return _constant(result, test, knot_s, "auto: Wald test"), notes
    chosen = "option" if wind == "drifting" else "auto: Wald test"
    record = _model_record("drifting", knot_s, test, chosen, basis)
    out, drift_notes = _given_wind(flight, fit_constant, basis, d, air_data, fitted[-1], record)
    if out is None:                     # the constant wind's calibration stands
        return _fallback(result, test, knot_s, f"its fit {drift_notes}", notes)
    note = drift_note(out, out.wind_track, result)
    return out, tuple(drift_notes) + ((note,) if note else ())

def _given_wind(flight, fit_constant, basis, d, air_data, known, record):
    """(result, warnings) of the calibration with the wind B d (basis, d) taken out of the GPS
    velocity, its covariance widened by the wind's freedom and its `wind_track`; (None, why)
    when that fit fails."""
    if not np.all(np.isfinite(d)):
        return None, "did not converge"
    corrected = without_drift(flight, basis, d)
    try:
        out, notes = fit_constant(corrected)
    except PitotcalError as exc:
        return None, f"failed: {exc}"
    if not out.success:
        return None, "did not converge"
    kept = _kept(corrected, out)
    ch = flight_channels(kept, out.gps_noise_std_mps, air_data)
    b = basis.rows(kept.time_s, kept.segment)
    cov = _covariances(get_model(out.model), out.internal_params, ch, b, out.residuals_pa,
                       known)
    out = _widened(out, cov)
    track = wind_track(basis, out.internal_params, d, cov[0])
    return dataclasses.replace(out, wind_model=record, wind_track=track, drift=(basis, d),
                               source=str(flight.source)), tuple(notes)


def _fallback(result, test, knot_s, reason, notes):
    """(the constant-wind result, its warnings and one saying why the drift the test or the
    option asked for was not fitted)."""
    note = (f"{result.source}: a drifting wind was called for but not fitted ({reason}); the "
            "calibration is the constant wind's")
    return _constant(result, test, knot_s, f"constant: the drift's {reason}"), \
        tuple(notes) + (note,)


def _windows(flight):
    return 1 if flight.segment is None or not flight.n else np.unique(flight.segment).size


def _per_window(flight, fit_constant, result, test, knot_s, chosen, fitted, notes):
    """(result, warnings) with one constant wind per calibration window (`window_basis`),
    fitted jointly with the calibration as a drift is; the constant-wind result when that
    fit fails."""
    model, ch, kept, air_data, known = fitted
    basis = window_basis(kept.time_s, kept.segment)
    d = _joint_gauss_newton(model, result.internal_params, ch,
                            basis.rows(kept.time_s, kept.segment))[1]
    record = _model_record("constant per window", knot_s, test, chosen, basis)
    out, each_notes = _given_wind(flight, fit_constant, basis, d, air_data, known, record)
    if out is None:
        return _fallback(result, test, knot_s, f"per-window fit {each_notes}", notes)
    return out, each_notes


def _widened(result, cov):
    """`result` with its covariances widened by the drift's freedom: the whole problem's block
    of (k, W_mean) minus the constant problem's, same noise model, added to the result's own
    (instrumental-variable, colored) covariance."""
    whole, whole_plain, const, const_plain = cov
    p = result.internal_params.size
    internal = result.internal_covariance + _psd(whole[:p, :p] - const)
    plain = result.internal_covariance_plain + _psd(whole_plain[:p, :p] - const_plain)
    _, reported = to_reported(result.internal_params, internal)
    _, reported_plain = to_reported(result.internal_params, plain)
    return dataclasses.replace(result, internal_covariance=internal,
                               internal_covariance_plain=plain, covariance=reported,
                               covariance_plain=reported_plain)


def _model_record(kind, knot_s, test, chosen_by, basis=None):
    out = {"kind": kind, "knot_s": None if knot_s is None else float(knot_s), "test": test,
           "chosen_by": chosen_by}
    if basis is not None:
        out["n_knots"] = int(sum(k.size for k in basis.knots))
    return out


def constant_wind(result, chosen_by):
    """`result` (its own constant wind, no drift) with a constant `wind_model` and a flat
    `wind_track`, no test run."""
    return _constant(result, None, None, chosen_by)


def _constant(result, test, knot_s, chosen_by):
    """The constant-wind result with its `wind_model` and a flat `wind_track`."""
    p = result.internal_params.size
    cov = result.internal_covariance[p - 2:, p - 2:]
    t = result.time_s
    times = np.array([t[0], t[-1]]) if t.size else np.zeros(0)
    w = np.tile(result.internal_params[WIND], (times.size, 1))
    track = _track_record(times, w, [cov] * times.size, None)
    return dataclasses.replace(result, wind_track=track,
                               wind_model=_model_record("constant", knot_s, test, chosen_by))


def wind_track(basis, theta, d, cov_whole):
    """The wind at `TRACK_POINTS_PER_KNOT` points per knot interval of each window, with the
    2σ of its speed and direction from the whole problem's covariance of (W_mean, d)."""
    p = theta.size
    m = basis.size
    times, segs = [], []
    for s, knots in zip(basis.window_labels, basis.knots):
        n = (knots.size - 1) * TRACK_POINTS_PER_KNOT + 1
        times.append(np.linspace(knots[0], knots[-1], n))
        segs.append(np.full(n, s))
    times, segs = np.concatenate(times), np.concatenate(segs)
    b = basis.rows(times, segs)
    w = theta[WIND] + np.column_stack([b @ d[:m], b @ d[m:]])
    covs = []
    for row in b:
        g = np.zeros((2, cov_whole.shape[0]))
        g[0, p - 2], g[1, p - 1] = 1.0, 1.0
        g[0, p:p + m], g[1, p + m:] = row, row
        covs.append(g @ cov_whole @ g.T)
    return _track_record(times, w, covs, segs if len(basis.knots) > 1 else None)


def _track_record(times, w, covs, segs):
    speed, from_deg, s2, f2 = [], [], [], []
    for (wn, we), c in zip(w, covs):
        params, rep = to_reported(np.array([wn, we]), c)
        speed.append(params[0])
        from_deg.append(params[1])
        s2.append(2.0 * np.sqrt(max(rep[0, 0], 0.0)))
        f2.append(2.0 * np.sqrt(max(rep[1, 1], 0.0)))
    out = {"time_s": [float(x) for x in times], "speed_mps": speed, "from_deg": from_deg,
           "speed_2sigma_mps": s2, "from_2sigma_deg": f2}
    if segs is not None:
        out["segment"] = [int(s) for s in segs]
    return out


def drift_size(track):
    """(largest change of the wind vector, m/s; of its speed, m/s; of its direction, deg)
    along a wind track."""
    speed = np.asarray(track["speed_mps"])
    ang = np.radians(track["from_deg"])
    wn, we = -speed * np.cos(ang), -speed * np.sin(ang)
    vec = np.hypot(wn[:, None] - wn, we[:, None] - we).max() if speed.size else 0.0
    turn = np.degrees(np.ptp(np.unwrap(ang))) if speed.size else 0.0
    return float(vec), float(np.ptp(speed)) if speed.size else 0.0, float(turn)


def drift_note(result, track, constant):
    """The warning of a drift that matters (the wind moves more than `DRIFT_MATTERS_MPS`, or
    the ΔV table moves by more than its 2σ against the constant-wind fit), or None."""
    vec, dspeed, turn = drift_size(track)
    rows = result.correction_table()
    vi = np.array([row["vi_kt"] for row in rows])
    band = np.array([row["dv_2sigma_kt"] for row in rows])
    shift = np.abs(np.asarray(result.delta_v_kt(vi)[0]) - np.asarray(constant.delta_v_kt(vi)[0]))
    moved = bool(np.any(shift > band)) if vi.size else False
    if vec <= DRIFT_MATTERS_MPS and not moved:
        return None
    span = track["time_s"][-1] - track["time_s"][0]
    speed0, from0 = wind_polar(*constant.internal_params[WIND])
    return (f"{result.source}: the wind drifted {vec:.1f} m/s (speed {dspeed:.1f} m/s, "
            f"direction {turn:.0f} deg) over the {span:.0f} s record; fitted as a drifting "
            f"wind (knots every {track_knot_s(result):.0f} s): a constant-wind fit "
            f"({float(speed0):.1f} m/s from {float(from0):.0f} deg) would move the airspeed "
            f"correction by up to {float(shift.max()) if shift.size else 0.0:.2f} kt")


def track_knot_s(result):
    return float(result.wind_model["knot_s"]) if result.wind_model else DEFAULT_KNOT_S
