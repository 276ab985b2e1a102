"""The airspeed monitor: a calibration's prediction tested block by block against the live or logged record."""
