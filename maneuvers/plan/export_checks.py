"""Where an exported mission may fly: checks made before a mission is built or a plan solved.

An autopilot flies a mission as written: alternating turns cannot be one loiter circle, and a
loiter altitude above mean sea level is only as safe as the ground's elevation at the centre.
"""

import warnings

from pitotcal.core.errors import PlanInfeasibleError
from pitotcal.core.scenario import MIN_CLEARANCE_M

__all__ = ["MIN_CLEARANCE_M", "check_exportable_turn", "check_ground_clearance"]


def check_exportable_turn(turn):
    """Refuse alternating turns for a mission, whatever the radius: checked before planning,
    so no other advice (a radius, a duration) comes first and leads here."""
    if turn == "both":
        raise PlanInfeasibleError(
            "turn both cannot be exported at any radius or duration: the mission is one "
            "loiter circle at the centre, flown one way (ArduPilot and PX4 take the direction "
            "per loiter item, not within one); export a plan with turn right or left",
            param="turn")


def check_ground_clearance(altitude_m, altitude_ref, ground_elevation_m=None):
    """Refuse loiters less than `MIN_CLEARANCE_M` above the ground at the centre, and warn
    when an altitude above mean sea level is exported without the ground's elevation (an
    autopilot flies it as given: PX4 SITL's default home is 488 m above mean sea level, so a
    244 m MSL loiter there is underground).

    `ground_elevation_m`: the ground at the centre, m above mean sea level, or None (unknown).
    """
    if altitude_ref == "agl":
        if altitude_m < MIN_CLEARANCE_M:
            raise PlanInfeasibleError(
                f"altitude_m {altitude_m:g} m above home is less than {MIN_CLEARANCE_M:g} m "
                f"above the ground: plan altitude_m at least {MIN_CLEARANCE_M:g} m",
                param="altitude_m")
        return
    if ground_elevation_m is None:
        warnings.warn(
            f"the mission's loiters are at {altitude_m:g} m above mean sea level and the "
            "ground's elevation at the centre is not given: check they clear it (give "
            "`ground_elevation_m`); an altitude above the ground "
            "is the ground's elevation plus the height wanted", stacklevel=3)
        return
    above = altitude_m - ground_elevation_m
    if above < MIN_CLEARANCE_M:
        where = f"{abs(above):g} m {'above' if above >= 0 else 'below'}"
        raise PlanInfeasibleError(
            f"altitude_m {altitude_m:g} m MSL is {where} the ground at the centre "
            f"({ground_elevation_m:g} m MSL): plan altitude_m at least "
            f"{ground_elevation_m + MIN_CLEARANCE_M:g} m (the ground plus {MIN_CLEARANCE_M:g} m)",
            param="altitude_m", mentions=("ground_elevation_m",))
