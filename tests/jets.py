"""The column mapping of the shared USAF TPS jet exports (jmoss/CLASS*.csv), for the tests."""

from pitotcal.studies.jets.study import TPS_ATTITUDE_MAP
from pitotcal.studies.jets.study import TPS_EXPORT_MAP as JMOSS_MAP

# the attitude and sideslip vane, for the vector airspeed
JMOSS_ATTITUDE_MAP = JMOSS_MAP + TPS_ATTITUDE_MAP
