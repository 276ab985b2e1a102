"""Simulated whole-flight logs with known truth: taxi, climb, calibration parts, dives, taxi,
one after another, written as ArduPilot DataFlash logs (tests/logwriters.py)."""

import numpy as np
from logwriters import PS_PA, write_dataflash_bin
from synthetic import synthetic_flight, wind_vector

from pitotcal.core.flight import Flight
from pitotcal.core.models import get_model, qci_from_qc_pa
from pitotcal.core.units import R_AIR_JKGK

RATE_HZ, RHO, K = 10.0, 1.196, (0.02, -15.0)
WIND = wind_vector(5.0, 270.0)


def straight(duration_s, tas_mps, path_deg, heading_deg=90.0):
    """(qci, vn, ve, vd) of straight flight at this true airspeed and flight-path angle."""
    n = int(duration_s * RATE_HZ)
    vd = np.full(n, -tas_mps * np.sin(np.radians(path_deg)))
    vh = tas_mps * np.cos(np.radians(path_deg))
    vn = np.full(n, vh * np.cos(np.radians(heading_deg)) + WIND[0])
    ve = np.full(n, vh * np.sin(np.radians(heading_deg)) + WIND[1])
    qci = qci_from_qc_pa(get_model("inverse"), K, np.full(n, 0.5 * RHO * tas_mps ** 2))
    return qci, vn, ve, vd


def calibration(duration_s, seed):
    f, _ = synthetic_flight(seed=seed, n=int(duration_s * RATE_HZ), rate_hz=RATE_HZ, k=K,
                            cas_kt=(60.0, 90.0), turns=duration_s / 100.0, rho_kgm3=RHO)
    return f.qci_pa, f.gps_vn_mps, f.gps_ve_mps, np.zeros(f.n)


def whole_flight(parts):
    """A Flight of the parts [(name, (qci, vn, ve, vd))] one after another, and each part's
    (start, end) time, s."""
    cols = [np.concatenate([p[1][i] for p in parts]) for i in range(4)]
    t = np.arange(cols[0].size) / RATE_HZ
    spans, i = {}, 0
    for name, p in parts:
        spans.setdefault(name, []).append((t[i], t[i + p[0].size - 1]))
        i += p[0].size
    flight = Flight(time_s=t, qci_pa=cols[0], gps_vn_mps=cols[1], gps_ve_mps=cols[2],
                    rho_kgm3=np.full(t.size, RHO), gps_vd_mps=cols[3])
    return flight, spans


def write_log(tmp_path, parts, **kw):
    """The DataFlash log of the parts (STAT flying between the first and last "ground" part,
    ARSPD_FBW_MIN 15 m/s), and each part's spans."""
    flight, spans = whole_flight(parts)
    ground = spans["ground"]
    path = write_dataflash_bin(tmp_path / "whole.bin", flight, flying=(ground[0][1], ground[-1][0]),
                               min_airspeed=15.0, **kw)
    return path, spans


OAT_K = PS_PA / (R_AIR_JKGK * RHO)        # the temperature the test logs carry


