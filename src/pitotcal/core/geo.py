"""Local flat-earth (ENU) positions around a reference point on the WGS-84 ellipsoid.

A maneuver spans a few kilometres: north/east offsets convert to latitude/longitude with the
ellipsoid's radii of curvature at the reference latitude (error ~ (d/R)^2, under a millimetre
at 2 km).
"""

import math

from .checks import number

__all__ = ["WGS84_A_M", "WGS84_F", "check_lat_lon", "latlon_from_offset_m", "latlon_text",
           "offset_m_from_latlon", "radii_of_curvature_m"]

WGS84_A_M = 6378137.0              # semi-major axis
WGS84_F = 1.0 / 298.257223563      # flattening
_E2 = WGS84_F * (2.0 - WGS84_F)    # first eccentricity squared


def check_lat_lon(lat_deg, lon_deg):
    """(lat, lon) as floats, latitude in [-90, 90] and longitude in [-180, 180) degrees
    (PitotcalError naming `lat_deg` or `lon_deg` otherwise)."""
    return (number("lat_deg", lat_deg, -90.0, 90.0),
            number("lon_deg", lon_deg, -180.0, 180.0, hi_open=True))


def latlon_text(lat_deg, lon_deg):
    """'47.39774°N 8.54559°E': degrees to 5 decimals (about a metre), hemisphere letters."""
    return (f"{abs(lat_deg):.5f}°{'N' if lat_deg >= 0 else 'S'} "
            f"{abs(lon_deg):.5f}°{'E' if lon_deg >= 0 else 'W'}")


def radii_of_curvature_m(lat_deg):
    """(meridian M, prime vertical N) radii of curvature at `lat_deg`, metres.

    Notes
    -----
    M = a (1 - e^2) / (1 - e^2 sin^2 lat)^(3/2),  N = a / sqrt(1 - e^2 sin^2 lat).
    """
    s2 = math.sin(math.radians(lat_deg)) ** 2
    w = math.sqrt(1.0 - _E2 * s2)
    return WGS84_A_M * (1.0 - _E2) / w ** 3, WGS84_A_M / w


def latlon_from_offset_m(lat0_deg, lon0_deg, north_m, east_m):
    """The latitude and longitude (degrees) `north_m`, `east_m` from (lat0, lon0).

    Example
    -------
    >>> lat, lon = latlon_from_offset_m(0.0, 0.0, 110574.3, 0.0)
    >>> round(lat, 4), lon
    (1.0, 0.0)
    """
    m, n = radii_of_curvature_m(lat0_deg)
    lat = lat0_deg + math.degrees(north_m / m)
    lon = lon0_deg + math.degrees(east_m / (n * math.cos(math.radians(lat0_deg))))
    return lat, (lon + 180.0) % 360.0 - 180.0


def offset_m_from_latlon(lat0_deg, lon0_deg, lat_deg, lon_deg):
    """(north, east) metres of (lat, lon) from (lat0, lon0): the inverse of
    `latlon_from_offset_m`."""
    m, n = radii_of_curvature_m(lat0_deg)
    dlon = (lon_deg - lon0_deg + 180.0) % 360.0 - 180.0
    return (math.radians(lat_deg - lat0_deg) * m,
            math.radians(dlon) * n * math.cos(math.radians(lat0_deg)))
