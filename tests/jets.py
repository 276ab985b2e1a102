"""The column mapping of the shared USAF TPS jet exports (jmoss/CLASS*.csv), for the tests."""

JMOSS_MAP = """\
time              = { column = "time_s",          unit = "s" }
gps_vn            = { column = "north_vel_fps",   unit = "ft/s" }
gps_ve            = { column = "east_vel_fps",    unit = "ft/s" }
gps_vd            = { column = "down_vel_fps",    unit = "ft/s" }
total_pressure    = { column = "total_pres_psi",  unit = "psi" }
static_pressure   = { column = "static_pres_psi", unit = "psi" }
total_temperature = { column = "total_temp_K",    unit = "K" }
gps_height        = { column = "height_ft",       unit = "ft" }
"""
# the attitude and sideslip vane, for the self-survey's vector airspeed
JMOSS_ATTITUDE_MAP = JMOSS_MAP + """\
roll              = { column = "roll_angle_rad",   unit = "rad" }
pitch             = { column = "pitch_angle_rad",  unit = "rad" }
true_heading      = { column = "true_heading_rad", unit = "rad" }
sideslip          = { column = "aos_rad",          unit = "rad" }
"""
