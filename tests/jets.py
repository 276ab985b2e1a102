"""The column mapping of the shared USAF TPS jet exports (jmoss/CLASS*.csv), for the tests."""

from pitotcal.studies.jets.study import TPS_EXPORT_MAP as JMOSS_MAP

# the attitude and sideslip vane, for the self-survey's vector airspeed
JMOSS_ATTITUDE_MAP = JMOSS_MAP + """\
roll              = { column = "roll_angle_rad",   unit = "rad" }
pitch             = { column = "pitch_angle_rad",  unit = "rad" }
true_heading      = { column = "true_heading_rad", unit = "rad" }
sideslip          = { column = "aos_rad",          unit = "rad" }
"""
