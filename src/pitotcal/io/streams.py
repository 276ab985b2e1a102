"""What the log format readers hand to `pitotcal.io.logs`: the raw streams of one log, and a
guard that catches what the log libraries print."""

import contextlib
import io
import os
import re
import sys
import tempfile
import warnings
from dataclasses import dataclass, field

import numpy as np

__all__ = ["LOG_EXTENSIONS", "MAVLINK_READ_ERRORS", "LogStreams", "captured_output",
           "skipped_bytes"]

# The autopilot log formats pitotcal reads (anything else is read as a flight CSV).
LOG_EXTENSIONS = (".ulg", ".bin", ".log", ".tlog")
# What pymavlink raises on an empty, truncated or mangled file: its parsers fail low down
# (ValueError, IndexError, struct.error, ...) and its DataFlash reader raises a bare Exception
# for a mangled FMT record ("Unsupported format char"), so every Exception; a reader re-raises
# its own FlightDataError before this
MAVLINK_READ_ERRORS = (Exception,)


def skipped_bytes(chatter):
    """The bad bytes pymavlink says it skipped, summed over its "Skipped N bad bytes" lines."""
    return sum(map(int, re.findall(r"Skipped (\d+) bad bytes", chatter)))


@contextlib.contextmanager
def captured_output():
    """Catch what the log libraries print (pymavlink's C indexer writes to file descriptor 2).

    Yields a StringIO that holds the text once the block ends, so a reader can summarise
    "skipped N corrupt bytes" in one warning instead of thousands of lines on the terminal.
    """
    buf = io.StringIO()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    try:
        saved = [os.dup(1), os.dup(2)]
    except OSError:                      # no real descriptors (embedded use): Python level only
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            yield buf
        return
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 1)
        os.dup2(tmp.fileno(), 2)
        try:
            with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
                yield buf
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            tmp.seek(0)
            buf.write(tmp.read().decode("utf-8", "replace"))


@dataclass
class LogStreams:
    """Raw streams of one log, times in s since log start (filled by the format readers).

    `conversions` are substitutions the reader made (warned by `pitotcal.io.logs`);
    `warnings` are the format reader's other warnings (corrupt data skipped), already issued.
    """

    log_format: str = ""
    autopilot: str = ""
    log_duration_s: float | None = None
    pressure_t: np.ndarray | None = None
    qci_pa: np.ndarray | None = None
    pressure_source: str = ""
    static_t: np.ndarray | None = None
    ps_pa: np.ndarray | None = None
    static_source: str = ""
    temp_t: np.ndarray | None = None
    temp_k: np.ndarray | None = None
    temp_source: str = ""
    gps_t: np.ndarray | None = None
    gps_vn: np.ndarray | None = None
    gps_ve: np.ndarray | None = None
    gps_vd: np.ndarray | None = None
    gps_ok: np.ndarray | None = None
    gps_alt_m: np.ndarray | None = None
    gps_source: str = ""
    wind_t: np.ndarray | None = None
    wind_n: np.ndarray | None = None
    wind_e: np.ndarray | None = None
    wind_source: str = ""
    airborne_t: np.ndarray | None = None
    airborne: np.ndarray | None = None          # the autopilot's state: flying and armed
    airborne_source: str = ""
    min_airspeed_mps: float | None = None       # the autopilot's minimum airspeed parameter
    min_airspeed_source: str = ""
    airspeed_scale: dict = field(default_factory=dict)
    # a logged outside-air temperature sensor (not a pressure chip's), K; and the throttle, 0-1
    # or percent, for the whole-flight windows (`pitotcal.io.windows`)
    oat_t: np.ndarray | None = None
    oat_k: np.ndarray | None = None
    oat_source: str = ""
    throttle_t: np.ndarray | None = None
    throttle: np.ndarray | None = None
    throttle_source: str = ""
    # airspeed sensors beyond the first, each (time s, q_ci Pa, source): `pitotcal.io.sensors`
    other_sensors: list = field(default_factory=list)
    conversions: list = field(default_factory=list)
    warnings: list = field(default_factory=list)

    def warn(self, text, stacklevel=2):
        """Issue a warning about the log now and keep it for `Flight.warnings`."""
        warnings.warn(text, stacklevel=stacklevel + 1)
        self.warnings.append(text)
