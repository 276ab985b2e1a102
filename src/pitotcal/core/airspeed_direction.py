"""The direction of the airspeed vector in north-east-down axes, from attitude and the sideslip
vane, for the methods that compare the airspeed with GPS as a vector (the self-survey, the
Mach-dependent output error).

As the Test Pilot School's self-survey does (Jurado & McGehee 2019): the angle of attack is
taken as pitch minus the GPS flight-path angle, α = θ − γ, γ = asin(−V_d / V_h) (the vane's
upwash error never enters), and the sideslip vane is corrected to the wind axes by
β = atan(cos α tan β_vane). The unit vector is then the body-to-NED rotation (heading ψ,
pitch θ, roll φ; Z-Y-X) of the wind axes' x direction (cos α cos β, sin β, sin α cos β).
"""

import numpy as np

from pitotcal.core.errors import PitotcalError

__all__ = ["ATTITUDE_FIELDS", "airspeed_direction", "aligned_attitude", "heading_rate_rps",
           "rotated_horizontal"]

ATTITUDE_FIELDS = ("roll_rad", "pitch_rad", "heading_rad")


def aligned_attitude(attitude, time_s):
    """The attitude arrays (`ATTITUDE_FIELDS`, and `sideslip_rad` or zeros) at the samples
    `time_s`, matched by time (within a millisecond)."""
    missing = [k for k in ("time_s", *ATTITUDE_FIELDS) if k not in attitude]
    if missing:
        raise PitotcalError(f"`attitude` lacks {', '.join(missing)}", param="attitude")
    t = np.asarray(attitude["time_s"], dtype=float)
    idx = np.clip(np.searchsorted(t, time_s), 0, t.size - 1)
    back = np.clip(idx - 1, 0, t.size - 1)
    idx = np.where(np.abs(t[back] - time_s) < np.abs(t[idx] - time_s), back, idx)
    far = np.abs(t[idx] - time_s) > 1e-3
    if np.any(far):
        first = float(np.asarray(time_s)[far][0])
        raise PitotcalError(f"`attitude` has no sample at the flight's time {first:g} s",
                            param="attitude")
    out = {k: np.asarray(attitude[k], dtype=float)[idx] for k in ATTITUDE_FIELDS}
    beta = attitude.get("sideslip_rad")
    out["sideslip_rad"] = (np.zeros(idx.size) if beta is None
                           else np.asarray(beta, dtype=float)[idx])
    return out


def airspeed_direction(att, v_ned):
    """Unit vectors (N, 3) of the airspeed in NED axes (module notes); `v_ned` the GPS
    velocity (N, 3), for the flight-path angle."""
    gamma = np.arcsin(np.clip(-v_ned[:, 2] / np.hypot(v_ned[:, 0], v_ned[:, 1]), -1.0, 1.0))
    alpha = att["pitch_rad"] - gamma
    beta = np.arctan(np.cos(alpha) * np.tan(att["sideslip_rad"]))
    wind_axes = np.column_stack([np.cos(alpha) * np.cos(beta), np.sin(beta),
                                 np.sin(alpha) * np.cos(beta)])
    return _body_to_ned(att["heading_rad"], att["pitch_rad"], att["roll_rad"], wind_axes)


def _body_to_ned(psi, theta, phi, v):
    """R_z(ψ) R_y(θ) R_x(φ) v, row by row."""
    cp, sp = np.cos(phi), np.sin(phi)
    ct, st = np.cos(theta), np.sin(theta)
    cs, ss = np.cos(psi), np.sin(psi)
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    y1, z1 = cp * y - sp * z, sp * y + cp * z                  # roll about x
    x2, z2 = ct * x + st * z1, -st * x + ct * z1                # pitch about y
    return np.column_stack([cs * x2 - ss * y1, ss * x2 + cs * y1, z2])   # heading about z


def heading_rate_rps(heading_rad, time_s):
    """dψ/dt (rad/s) of a heading that may wrap at ±π, by central differences."""
    t = np.asarray(time_s, dtype=float)
    if t.size < 2:
        return np.zeros(t.size)
    return np.gradient(np.unwrap(np.asarray(heading_rad, dtype=float)), t)


def rotated_horizontal(u, angle_rad):
    """The horizontal part of the directions `u` (N, 3), made unit and turned by `angle_rad`
    (scalar or (N,), clockwise seen from above, as heading grows): (N, 2) north, east."""
    h = u[:, :2] / np.linalg.norm(u[:, :2], axis=1)[:, None]
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.column_stack([c * h[:, 0] - s * h[:, 1], s * h[:, 0] + c * h[:, 1]])
