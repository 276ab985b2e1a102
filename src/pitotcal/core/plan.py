"""`Plan`: a planned calibration maneuver on a time grid (the plan CSV's content), and the names
a plan's request is made of (profiles, turn directions).

No numpy at import: the command line builds its choices from here before any heavy import.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

__all__ = ["ALTITUDE_RANGE_M", "PLAN_COLUMNS", "PLAN_RANGES", "PROFILES", "TURNS", "Plan"]

PLAN_COLUMNS = ("time_s", "north_m", "east_m", "alt_m", "heading_deg", "bank_deg",
                "tas_mps", "cas_mps", "qc_pa")
# Airspeed schedules (maneuvers/profiles.py, paper section IV) and turn directions.
PROFILES = ("continuous", "step-pause", "two-speed")
TURNS = ("right", "left")

# The altitudes `pitotcal plan` plans for, m: the ISA where the air data hold, up to the top of
# its layers (`pitotcal.core.units.ISA_TOP_M`, a test checks they agree; numpy-free here).
ALTITUDE_RANGE_M = (-400.0, 32000.0)
# What a plan's columns can hold (a plan CSV read back is checked against these), SI: a test
# area of at most 100 km, banks the planner allows (<= 75 deg), airspeeds up to the CAS the
# planner takes (661 kt) and the true airspeed that is at 32 km (the heading is unwrapped,
# so any finite value).
PLAN_RANGES = {
    "north_m": (-1e5, 1e5), "east_m": (-1e5, 1e5), "alt_m": ALTITUDE_RANGE_M,
    "bank_deg": (-75.0, 75.0),
    "tas_mps": (0.0, 1000.0), "cas_mps": (0.0, 350.0), "qc_pa": (0.0, 1e5),
}


@dataclass(frozen=True)
class Plan:
    """A maneuver on a time grid, SI, positions relative to the test-area centre.

    Attributes
    ----------
    time_s, north_m, east_m, alt_m, heading_deg, bank_deg, tas_mps, cas_mps, qc_pa : ndarray (N,)
        The columns of the plan CSV; `qc_pa` is the target impact pressure, `heading_deg` is
        the unwrapped air-relative heading.
    settings : dict
        The request: profile, cas_min_kt, cas_max_kt, radius_m, altitude_m, duration_s,
        bank_max_deg, wind_speed_mps, wind_from_deg, ... (written as `#` comment lines).
    success, message, iterations :
        The solver's outcome (scipy naming).
    """

    time_s: np.ndarray
    north_m: np.ndarray
    east_m: np.ndarray
    alt_m: np.ndarray
    heading_deg: np.ndarray
    bank_deg: np.ndarray
    tas_mps: np.ndarray
    cas_mps: np.ndarray
    qc_pa: np.ndarray
    settings: dict = field(default_factory=dict)
    success: bool = True
    message: str = ""
    iterations: int = 0

    @property
    def n(self):
        return int(self.time_s.size)

    def column(self, name):
        return getattr(self, name)

    def summary(self):
        """Two lines: profile, length and solver effort; how far out the track goes, the bank
        and the airspeed range."""
        import numpy as np

        s = self.settings
        reach = float(np.max(np.hypot(self.north_m, self.east_m)))
        bank = float(np.max(np.abs(self.bank_deg)))
        radius = s.get("radius_m")
        within = f" (radius {radius:g} m)" if isinstance(radius, (int, float)) else ""
        return (f"{s.get('profile', 'plan')} plan: {self.time_s[-1]:.0f} s, {self.n} nodes, "
                f"{self.iterations} IPOPT iterations\n"
                f"  track within {reach:.0f} m of the centre{within}, bank up to {bank:.0f}°, "
                f"{s.get('cas_min_kt', float('nan')):g}-{s.get('cas_max_kt', float('nan')):g} "
                f"KCAS")
