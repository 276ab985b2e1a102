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
