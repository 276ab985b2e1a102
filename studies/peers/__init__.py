"""The `peers` study: the autopilots' own calibrators, re-implemented, against pitotcal."""
