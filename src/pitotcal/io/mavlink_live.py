"""A live MAVLink stream as a growing `Flight` (pymavlink): `pitotcal monitor udp:...` and
`pitotcal identify --live udp:...` read it.

Messages used (common MAVLink, as ArduPilot and PX4 send them):

* ``SCALED_PRESSURE`` — `press_diff` (hPa, the airspeed sensor's differential pressure: q_ci),
  `press_abs` (hPa, static pressure), `temperature` (cdegC; the sensor's own, so a measured
  OAT, `oat_k`, is better); each one is a sample;
* ``GLOBAL_POSITION_INT`` — `vx`, `vy`, `vz` (cm/s, north/east/down), `alt` (mm): the latest
  one is held for the pressure samples that follow it (causal sample-and-hold).

Times are the messages' `time_boot_ms`. A sample older than the previous one (out of order on
UDP) is dropped and counted; pressure before the first GPS velocity is dropped and counted.
The stream ends when nothing arrives for `idle_timeout_s`; Ctrl-C ends it too; either way what
was received is kept.
"""

import contextlib
import socket
import time

import numpy as np

from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.core.flight import Flight
from pitotcal.core.units import density_kgm3

__all__ = ["CONNECTION_PREFIXES", "FIRST_MESSAGE_TIMEOUT_S", "IDLE_TIMEOUT_S",
           "LISTENING_PREFIXES", "MavlinkFlightBuffer", "check_connection", "is_connection",
           "read_stream"]

CONNECTION_PREFIXES = ("udp:", "udpin:", "udpout:", "tcp:", "tcpin:")
# pymavlink's connections that wait for the sender (the others connect to it)
LISTENING_PREFIXES = ("udp:", "udpin:", "tcpin:")
# How long a stream may take to send its first message, s, before reading gives up
FIRST_MESSAGE_TIMEOUT_S = 30.0
# A stream has ended when nothing arrives for this long after its first message, s
IDLE_TIMEOUT_S = 3.0
_MESSAGES = ["SCALED_PRESSURE", "GLOBAL_POSITION_INT"]
_RECEIVE_BUFFER_BYTES = 8 << 20


def is_connection(source):
    """True for a MAVLink connection string (``udp:127.0.0.1:14550``...), not a file."""
    return str(source).startswith(CONNECTION_PREFIXES)


class MavlinkFlightBuffer:
    """Samples from MAVLink messages; `flight()` is what has arrived, as a `Flight`."""

    def __init__(self, source, oat_k=None):
        self.source, self.oat_k = str(source), oat_k
        self.rows = []                 # (t, qci, vn, ve, vd, alt, ps, temp_k)
        self.gps = None
        self.n_no_gps = self.n_out_of_order = self.n_pressure = self.n_gps = 0

    def add(self, msg):
        """Take one pymavlink message (others are ignored)."""
        kind = msg.get_type()
        if kind == "GLOBAL_POSITION_INT":
            self.n_gps += 1
            self.gps = (msg.vx / 100.0, msg.vy / 100.0, msg.vz / 100.0, msg.alt / 1000.0)
        elif kind == "SCALED_PRESSURE":
            self.n_pressure += 1
            t = msg.time_boot_ms / 1000.0
            if self.gps is None:
                self.n_no_gps += 1
            elif self.rows and t <= self.rows[-1][0]:
                self.n_out_of_order += 1
            else:
                self.rows.append((t, msg.press_diff * 100.0, *self.gps, msg.press_abs * 100.0,
                                  msg.temperature / 100.0 + 273.15))

    @property
    def n(self):
        return len(self.rows)

    def warnings(self):
        """What the stream lacked or got wrong, one sentence each."""
        out = []
        if self.n_no_gps:
            out.append(f"{self.source}: {self.n_no_gps} pressure samples before the first GPS "
                       f"velocity (GLOBAL_POSITION_INT) dropped")
        if self.n_out_of_order:
            out.append(f"{self.source}: {self.n_out_of_order} out-of-order samples dropped")
        if self.rows and self.oat_k is None:
            out.append(f"{self.source}: density from the pressure sensor's own temperature "
                       f"(not OAT; give the outside air temperature, `oat_k`)")
        return out

    def flight(self):
        """The samples so far as a `Flight`; FlightDataError naming what is missing."""
        if not self.rows:
            missing = ("no airspeed (SCALED_PRESSURE)" if not self.n_pressure else
                       "no GPS velocity (GLOBAL_POSITION_INT)" if not self.n_gps else
                       "no usable sample")
            raise FlightDataError(f"{self.source}: {missing} received ({self.n_pressure} "
                                  f"SCALED_PRESSURE, {self.n_gps} GLOBAL_POSITION_INT)")
        a = np.array(self.rows)
        temp = a[:, 7] if self.oat_k is None else np.full(a.shape[0], float(self.oat_k))
        return Flight(time_s=a[:, 0], qci_pa=a[:, 1], gps_vn_mps=a[:, 2], gps_ve_mps=a[:, 3],
                      rho_kgm3=density_kgm3(a[:, 6], temp), gps_vd_mps=a[:, 4], alt_m=a[:, 5],
                      ps_pa=a[:, 6], oat_k=temp, source=self.source, meta={"generator": "pitotcal mavlink_live"},
                      warnings=tuple(self.warnings()))


def check_connection(source):
    """`source` if it is a connection string with a host and a port 1-65535; a one-line
    PitotcalError naming it otherwise (the socket layer would raise OverflowError)."""
    address = str(source).split(":", 1)[1] if ":" in str(source) else ""
    host, _, port = address.rpartition(":")
    if not host or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise PitotcalError(f"{source}: not a MAVLink connection HOST:PORT with a port "
                            "1-65535 (e.g. udp:127.0.0.1:14550)", param="source")
    return source


def _connect(source):
    from pymavlink import mavutil

    check_connection(source)
    try:
        conn = mavutil.mavlink_connection(str(source))
    except (OSError, ValueError) as exc:
        raise PitotcalError(f"{source}: cannot open the MAVLink connection ({exc})") from None
    port = getattr(conn, "port", None)
    if isinstance(port, socket.socket):     # UDP: room for bursts while a tick computes
        with contextlib.suppress(OSError):
            port.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, _RECEIVE_BUFFER_BYTES)
    return conn


def read_stream(source, *, oat_k=None, idle_timeout_s=IDLE_TIMEOUT_S,
                first_timeout_s=FIRST_MESSAGE_TIMEOUT_S, every_s=1.0, on_tick=None, max_s=None):
    """Read a MAVLink stream until it stops; the `MavlinkFlightBuffer` of what arrived.

    Parameters
    ----------
    source : str
        pymavlink connection, e.g. ``udp:127.0.0.1:14550`` (listen there).
    oat_k : float, optional
        Measured outside air temperature, K (default: the pressure sensor's temperature).
    idle_timeout_s : float
        The stream has ended when nothing arrives for this long, s, after the first message.
    first_timeout_s : float
        Give up when nothing at all arrives for this long, s.
    every_s : float
        `on_tick(buffer)` is called this often (wall clock) while data arrive.
    on_tick : callable, optional
        Called with the buffer; its exceptions propagate.
    max_s : float, optional
        Stop after this many seconds of wall clock.

    Returns
    -------
    MavlinkFlightBuffer
        With `stopped` = "idle", "interrupted" or "max_s".
    """
    conn = _connect(source)
    buf = MavlinkFlightBuffer(source, oat_k)
    start = last = tick = time.monotonic()
    buf.stopped = "idle"
    try:
        while True:
            msg = conn.recv_match(type=_MESSAGES, blocking=True, timeout=0.2)
            now = time.monotonic()
            if msg is not None:
                buf.add(msg)
                last = now
            elif now - last > (idle_timeout_s if buf.n_pressure + buf.n_gps else first_timeout_s):
                break
            if on_tick is not None and now - tick >= every_s and buf.n:
                tick = now
                on_tick(buf)
            if max_s is not None and now - start > max_s:
                buf.stopped = "max_s"
                break
    except KeyboardInterrupt:
        buf.stopped = "interrupted"
    finally:
        conn.close()
    return buf
