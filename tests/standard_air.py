"""An independent standard atmosphere and airspeed chain for the tests: flightcondition."""

import numpy as np

EARTH_RADIUS_M = 6356766.0      # geopotential to geometric height, as the ISA defines it


def reference(alt_m, **speed_kt):
    """flightcondition's FlightCondition at geopotential `alt_m` (m) and one airspeed in knots
    (``CAS=``, ``EAS=`` or ``TAS=``, scalar or array)."""
    from flightcondition import FlightCondition, unit

    h_m = EARTH_RADIUS_M * alt_m / (EARTH_RADIUS_M - alt_m)
    (name, value), = speed_kt.items()
    return FlightCondition(h=h_m * unit("m"), **{name: np.asarray(value) * unit("knots")})
