"""Test helper: a `Flight` as the MAVLink messages an autopilot sends (SCALED_PRESSURE and
GLOBAL_POSITION_INT), over UDP with pymavlink, and the flight as those messages carry it."""

import socket
import threading
import time
from dataclasses import replace

import numpy as np

from pitotcal.core.units import R_AIR_JKGK, density_kgm3, isa_pressure_pa


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def as_sent(flight):
    """The flight quantised as the messages carry it: cm/s velocities, float32 hPa pressures,
    cdegC temperature, ms times; returns (flight, static pressure Pa, temperature cdegC)."""
    ps = isa_pressure_pa(flight.alt_m)
    temp_c = np.round((ps / (R_AIR_JKGK * flight.rho_kgm3) - 273.15) * 100.0).astype(int)
    ps32 = (ps / 100.0).astype(np.float32)
    qci32 = (flight.qci_pa / 100.0).astype(np.float32)
    cms = [np.round(v * 100.0).astype(int) for v in (flight.gps_vn_mps, flight.gps_ve_mps,
                                                     flight.gps_vd_mps)]
    alt_mm = np.round(flight.alt_m * 1000.0).astype(int)
    sent = replace(flight, time_s=np.round(flight.time_s * 1000.0) / 1000.0,
                   qci_pa=qci32.astype(float) * 100.0, gps_vn_mps=cms[0] / 100.0,
                   gps_ve_mps=cms[1] / 100.0, gps_vd_mps=cms[2] / 100.0,
                   alt_m=alt_mm / 1000.0,
                   rho_kgm3=density_kgm3(ps32.astype(float) * 100.0, temp_c / 100.0 + 273.15),
                   ps_pa=ps32.astype(float) * 100.0, oat_k=temp_c / 100.0 + 273.15)
    return sent, ps32, temp_c, cms, alt_mm


def send_flight(flight, port, *, order=None, skip_gps=False, skip_pressure=False, delay_s=0.3):
    """Send `flight` to udp 127.0.0.1:port in a thread (started after `delay_s`); `order`
    permutes the samples (out-of-order tests). Returns the thread."""
    from pymavlink import mavutil

    sent, ps32, temp_c, cms, alt_mm = as_sent(flight)
    index = np.arange(flight.n) if order is None else np.asarray(order)

    def run():
        time.sleep(delay_s)
        conn = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=1)
        for k, i in enumerate(index):
            ms = int(np.rint(sent.time_s[i] * 1000.0))
            if not skip_gps:
                conn.mav.global_position_int_send(ms, 0, 0, int(alt_mm[i]), 0, int(cms[0][i]),
                                                  int(cms[1][i]), int(cms[2][i]), 0)
            if not skip_pressure:
                conn.mav.scaled_pressure_send(ms, float(ps32[i]),
                                              float(sent.qci_pa[i] / 100.0), int(temp_c[i]))
            if k % 50 == 49:
                time.sleep(0.005)          # paced: a real link is slower than memory
        conn.close()

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread
