"""Point-mass aircraft over flat earth, shared by the planner and the simulator.

State x = [north_m, east_m, alt_m, heading_rad, tas_mps]; controls u = [bank_rad, accel_mps2,
climb_mps]; wind w = [wind_n_mps, wind_e_mps], the air-mass velocity (the way it blows TO).
Heading is the air-relative heading, unwrapped (never wrapped inside the model).

    north' = V cos(psi) + w_n        east' = V sin(psi) + w_e        alt' = climb
    psi'   = g tan(phi) / V          (coordinated turn)              V'   = accel
"""

from dataclasses import dataclass

import numpy as np

from .scenario import ALT_TOLERANCE_FT, CAS_TOLERANCE_KT
from .units import FT_TO_M, G0_MPS2

__all__ = ["CONTROL_NAMES", "STATE_NAMES", "Limits", "ground_speed_on_track_mps", "rhs"]

STATE_NAMES = ("north_m", "east_m", "alt_m", "heading_rad", "tas_mps")
CONTROL_NAMES = ("bank_rad", "accel_mps2", "climb_mps")


@dataclass(frozen=True)
class Limits:
    """Flight limits shared by planner and simulator (defaults: the paper's T-2 case)."""

    bank_max_deg: float = 30.0
    roll_rate_max_dps: float = 10.0
    accel_max_mps2: float = 1.0
    climb_max_mps: float = 2.0
    alt_tolerance_m: float = ALT_TOLERANCE_FT * FT_TO_M     # paper section IV
    cas_tolerance_kt: float = CAS_TOLERANCE_KT


def rhs(x, u, w, lib=np):
    """Time derivative of the state; `lib` is numpy, math or casadi (arrays, floats or MX/SX).

    Returns a tuple of the five derivatives (stack them with the library's own function).
    """
    # plain indexing: the simulator calls this twice per step in a scalar loop
    psi, v = x[3], x[4]
    phi, accel, climb = u[0], u[1], u[2]
    return (v * lib.cos(psi) + w[0], v * lib.sin(psi) + w[1], climb,
            G0_MPS2 * lib.tan(phi) / v, accel)


def ground_speed_on_track_mps(track_rad, tas_mps, wind_n_mps, wind_e_mps):
    """Ground speed along the track angle `track_rad` (rad from north) of an aircraft at true
    airspeed `tas_mps` in the wind (wind_n, wind_e; the way it blows TO): the air velocity
    closes the wind triangle, V_g = w_along + sqrt(V^2 - w_across^2); arrays broadcast."""
    cos, sin = np.cos(track_rad), np.sin(track_rad)
    along = wind_n_mps * cos + wind_e_mps * sin
    across = wind_e_mps * cos - wind_n_mps * sin
    return along + np.sqrt(tas_mps ** 2 - across ** 2)
