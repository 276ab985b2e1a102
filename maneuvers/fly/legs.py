"""Simulated leg flights with known truth, for the classic GPS leg methods.

At each calibration point the aircraft holds an indicated airspeed V_ic at a pressure altitude
and flies constant-TAS legs on given ground tracks through a constant wind. The truth is
compressible and consistent with `pitotcal.estimation.legs.points`: q_ci = q_c(V_ic) by the CAS law,
q_c = q_ci / (1 − f(q_ci; k)), the static port reads p_s,ind = p_s + (q_c − q_ci) (the
position error is static-source error), V_t = a(T) M(q_c, p_s). Each leg's mean ground velocity
gets GPS/leg error N(0, σ²) per component; the CSV holds p_s,ind as `pressure_alt_ft`.
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core import airdata
from pitotcal.core.checks import integer, number
from pitotcal.core.dynamics import ground_speed_on_track_mps
from pitotcal.core.measurement import StaticAir
from pitotcal.core.models import get_model
from pitotcal.core.units import FT_TO_M, KT_TO_MPS, isa_temperature_k, wind_vector_mps
from pitotcal.io.legs_csv import LegData

__all__ = ["LEGS_TRUE_K", "LegTruth", "simulate_leg_flight", "simulate_legs"]

# A light aircraft's pressure error, Δp/q_c = 0.03 − 40 Pa / q_ci: ΔV ≈ −0.9 kt at 70 kt,
# +1.6 kt at 160 kt (the classic leg data's speed range).
LEGS_TRUE_K = (0.03, -40.0)


@dataclass(frozen=True)
class LegTruth:
    """What the simulated legs were flown with: per point V_ic, TAS, ΔV_pc; the wind; the model."""

    model: str
    k: tuple
    ias_kt: np.ndarray
    tas_mps: np.ndarray
    dv_kt: np.ndarray
    wind_n_mps: float
    wind_e_mps: float


def _tas_mps(qc_pa, ps_pa, oat_k):
    """The true airspeed of a true impact pressure at the true static air: the measurement
    model's inverse (`pitotcal.core.measurement.StaticAir`)."""
    return np.sqrt(StaticAir(ps_pa, oat_k).tas_sq(qc_pa))


def simulate_legs(ias_kt=(70, 85, 100, 115, 130, 145, 160), tracks_deg=(0, 90, 180, 270),
                  pressure_alt_ft=3000.0, oat_c=None, wind_speed_kt=15.0, wind_from_deg=250.0,
                  model="inverse", k=LEGS_TRUE_K, leg_sd_kt=0.5, state_sd=True,
                  duration_s=60.0, seed=0):
    """Fly legs on `tracks_deg` at every indicated airspeed of `ias_kt`.

    Parameters
    ----------
    ias_kt : sequence of float
        Indicated airspeed of each calibration point, kt.
    tracks_deg : sequence of float
        Ground tracks of the legs at every point, deg true.
    pressure_alt_ft : float
        True pressure altitude of every point, ft.
    oat_c : float, optional
        Outside air temperature, degC (default: ISA at the altitude).
    wind_speed_kt, wind_from_deg : float
        Constant wind, blowing from `wind_from_deg`.
    model, k :
        True pressure-error structure and coefficients.
    leg_sd_kt : float
        Standard deviation of each leg's mean ground-velocity error, per component, kt.
    state_sd : bool
        Write `leg_sd_kt` as the legs' `groundspeed_sd_kt` (else leave it unstated).
    duration_s : float
        Each leg's duration, s (recorded only).
    seed : int

    Returns
    -------
    (LegData, LegTruth)
    """
    pe = get_model(model)
    leg_sd = number("leg_sd_kt", leg_sd_kt, 0.0, 50.0) * KT_TO_MPS
    rng = np.random.default_rng(integer("seed", seed, 0))
    ias = np.asarray(ias_kt, dtype=float)
    tracks = np.asarray(tracks_deg, dtype=float)
    alt_m = number("pressure_alt_ft", pressure_alt_ft) * FT_TO_M
    ps = float(airdata.static_pressure_pa(alt_m))
    oat_k = isa_temperature_k(alt_m) if oat_c is None else number("oat_c", oat_c) + 273.15
    qci = airdata.qc_from_cas_pa(ias * KT_TO_MPS)
    qc = qci / (1.0 - pe(k, qci))
    tas = _tas_mps(qc, ps, oat_k)
    ps_ind = ps + (qc - qci)
    wn, we = wind_vector_mps(wind_speed_kt * KT_TO_MPS, wind_from_deg)
    w = np.array([float(wn), float(we)])
    u = np.column_stack([np.cos(np.radians(tracks)), np.sin(np.radians(tracks))])
    # ground speed of each point (rows) on each track (columns)
    gs = ground_speed_on_track_mps(np.radians(tracks)[None, :], tas[:, None], *w)
    rows = {"point": [], "g": [], "ias": [], "alt": []}
    for p in range(tas.size):
        g = gs[p][:, None] * u + rng.normal(0.0, leg_sd, size=u.shape)
        rows["point"] += [str(p + 1)] * len(tracks)
        rows["g"].append(g)
        rows["ias"] += [ias[p]] * len(tracks)
        rows["alt"] += [float(airdata.pressure_altitude_m(ps_ind[p]))] * len(tracks)
    g = np.vstack(rows["g"])
    n = len(rows["point"])
    legs = LegData(point=tuple(rows["point"]), ias_kt=np.array(rows["ias"]),
                   qci_pa=airdata.qc_from_cas_pa(np.array(rows["ias"]) * KT_TO_MPS),
                   pressure_alt_m=np.array(rows["alt"]), oat_k=np.full(n, oat_k),
                   groundspeed_mps=np.hypot(*g.T),
                   track_deg=np.degrees(np.arctan2(g[:, 1], g[:, 0])) % 360.0,
                   duration_s=np.full(n, float(duration_s)),
                   groundspeed_sd_mps=np.full(n, leg_sd if state_sd else np.nan),
                   source="simulated legs")
    vc = airdata.cas_from_qc_mps(qc)
    truth = LegTruth(model=pe.name, k=tuple(k), ias_kt=ias, tas_mps=tas,
                     dv_kt=(vc - ias * KT_TO_MPS) / KT_TO_MPS, wind_n_mps=w[0], wind_e_mps=w[1])
    return legs, truth


def _schedule(ias_kt, headings_deg, leg_s, turn_rate_dps, accel_kt_s):
    """Pieces (duration s, heading start, heading change, IAS start, IAS end, point or None):
    a straight leg per heading and point, joined by constant-rate turns; between points the
    turn also changes the speed (at `accel_kt_s`, the turn slowed to last as long)."""
    pieces, heading, speed = [], float(headings_deg[0]), float(ias_kt[0])
    for p, ias in enumerate(ias_kt):
        for j, target in enumerate(headings_deg):
            change = (float(target) - heading + 180.0) % 360.0 - 180.0
            if change == -180.0:
                change = 180.0                      # a reversal turns right
            dur = max(abs(change) / turn_rate_dps, abs(float(ias) - speed) / accel_kt_s)
            if dur > 0:
                pieces.append((dur, heading, change, speed, float(ias), None))
            heading, speed = float(target) % 360.0, float(ias)
            pieces.append((float(leg_s), heading, 0.0, speed, speed, str(p + 1)))
    return pieces


def simulate_leg_flight(ias_kt=(70, 100, 130, 160), headings_deg=(0, 90, 180, 270),
                        leg_s=60.0, turn_rate_dps=3.0, accel_kt_s=1.0, pressure_alt_ft=3000.0,
                        wind_speed_kt=15.0, wind_from_deg=250.0, model="inverse",
                        k=LEGS_TRUE_K, turbulence_mps=0.5, turbulence_length_m=300.0,
                        gps_noise_mps=0.05, qc_noise_pa=0.5, rate_hz=10.0, seed=0):
    """A leg flight as a time series: straight legs on `headings_deg` at every IAS, joined by
    turns, logged like a flight CSV (compressible air data; the static port's reading `ps_pa`).

    The pilot holds the indicated airspeed and the heading; the ground velocity is the air
    velocity plus the wind plus horizontal gusts (first-order Gauss-Markov per component, time
    constant L/V, rms `turbulence_mps`) plus white GPS noise. The truth is that of
    `simulate_legs` (ISA at `pressure_alt_ft`, all the position error in the static source).

    Returns
    -------
    (Flight, LegTruth, windows)
        `windows`: list of (start_s, end_s, point label) of the straight legs.
    """
    from pitotcal.core.flight import Flight
    from pitotcal.core.units import density_kgm3

    pe = get_model(model)
    rate = number("rate_hz", rate_hz, 0.5, 1000.0)
    rng = np.random.default_rng(integer("seed", seed, 0))
    pieces = _schedule(ias_kt, headings_deg, number("leg_s", leg_s, 5.0, 3600.0),
                       number("turn_rate_dps", turn_rate_dps, 0.1, 30.0),
                       number("accel_kt_s", accel_kt_s, 0.05, 20.0))
    starts = np.cumsum([0.0] + [p[0] for p in pieces])
    t = np.arange(0.0, starts[-1], 1.0 / rate)
    piece = np.searchsorted(starts, t, side="right") - 1
    frac = (t - starts[piece]) / np.array([p[0] for p in pieces])[piece]
    col = np.array([p[1:5] for p in pieces])[piece]
    heading = np.radians(col[:, 0] + frac * col[:, 1])
    ias = col[:, 2] + frac * (col[:, 3] - col[:, 2])
    alt_m = number("pressure_alt_ft", pressure_alt_ft) * FT_TO_M
    ps = float(airdata.static_pressure_pa(alt_m))
    oat_k = isa_temperature_k(alt_m)
    qci = airdata.qc_from_cas_pa(ias * KT_TO_MPS)
    qc = qci / (1.0 - pe(k, qci))
    tas = _tas_mps(qc, ps, oat_k)
    wn, we = wind_vector_mps(wind_speed_kt * KT_TO_MPS, wind_from_deg)
    phi = np.exp(-np.mean(tas) / (rate * turbulence_length_m))
    gust = np.zeros((t.size, 2))
    shocks = rng.normal(0.0, turbulence_mps * np.sqrt(1.0 - phi ** 2), size=gust.shape)
    gust[0] = rng.normal(0.0, turbulence_mps, size=2)
    for i in range(1, t.size):
        gust[i] = phi * gust[i - 1] + shocks[i]
    noise = rng.normal(0.0, gps_noise_mps, size=(t.size, 2))
    vn = tas * np.cos(heading) + float(wn) + gust[:, 0] + noise[:, 0]
    ve = tas * np.sin(heading) + float(we) + gust[:, 1] + noise[:, 1]
    ps_ind = ps + (qc - qci)
    flight = Flight(time_s=t, qci_pa=qci + rng.normal(0.0, qc_noise_pa, t.size),
                    gps_vn_mps=vn, gps_ve_mps=ve, rho_kgm3=density_kgm3(ps_ind, oat_k),
                    alt_m=airdata.pressure_altitude_m(ps_ind), ps_pa=ps_ind,
                    oat_k=np.full(t.size, oat_k), source="simulated leg flight")
    windows = [(float(starts[i]), float(starts[i + 1]), p[5]) for i, p in enumerate(pieces)
               if p[5] is not None]
    ias_pts = np.asarray(ias_kt, dtype=float)
    qci_pts = airdata.qc_from_cas_pa(ias_pts * KT_TO_MPS)
    qc_pts = qci_pts / (1.0 - pe(k, qci_pts))
    truth = LegTruth(model=pe.name, k=tuple(k), ias_kt=ias_pts,
                     tas_mps=_tas_mps(qc_pts, ps, oat_k),
                     dv_kt=(airdata.cas_from_qc_mps(qc_pts) - ias_pts * KT_TO_MPS) / KT_TO_MPS,
                     wind_n_mps=float(wn), wind_e_mps=float(we))
    return flight, truth, windows
