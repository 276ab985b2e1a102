"""The column mapping of the shared USAF TPS jet exports (jmoss/CLASS*.csv), and a seeded
synthetic jet test point with known truth, for the tests."""

import numpy as np

from pitotcal.core.airdata import mach_from_qc, qc_from_mach_pa
from pitotcal.core.flight import Flight
from pitotcal.core.units import isa_pressure_pa
from pitotcal.studies.jets.study import TPS_ATTITUDE_MAP
from pitotcal.studies.jets.study import TPS_EXPORT_MAP as JMOSS_MAP

# the attitude and sideslip vane, for the vector airspeed
JMOSS_ATTITUDE_MAP = JMOSS_MAP + TPS_ATTITUDE_MAP


WIND = (12.0, -5.0)            # m/s, the air mass's velocity north, east
OAT_K, RECOVERY = 255.0, 0.97


def true_dpp_ps(mach_ic):
    """A jet's static error: a slow rise, a transonic peak near M_ic 0.95, falling through 1."""
    return 0.008 + 0.02 * (mach_ic - 0.5) + 0.03 * np.exp(-((mach_ic - 0.95) / 0.03) ** 2)


TURN_S = 380.0


def true_heading(time_s):
    """The airspeed's heading of `jet_point`: a turn at 1°/s, then a run at 40°."""
    return np.where(time_s < TURN_S, np.radians(time_s), np.radians(40.0))


def jet_point(seed, alt_m=6000.0, hz=10.0):
    """A level turn at Mach 0.55 (380 s), then a run at constant heading from Mach 0.55 to 1.05
    and back (200 s); GPS velocity noise 0.1 m/s, pressures 20 Pa, probe 0.1 K."""
    rng = np.random.default_rng(seed)
    t_turn, t_run = np.arange(0, TURN_S, 1 / hz), np.arange(0, 200, 1 / hz)
    mach = np.r_[np.full(t_turn.size, 0.55), 0.55 + 0.5 * np.sin(np.pi * t_run / 200.0)]
    heading = true_heading(np.arange(t_turn.size + t_run.size) / hz)
    n = mach.size
    h = alt_m + rng.normal(0.0, 5.0, n)
    ps = isa_pressure_pa(h)
    tas = mach * np.sqrt(1.4 * 287.05287 * OAT_K)
    pt = ps + qc_from_mach_pa(mach, ps)
    psi = ps.copy()
    for _ in range(50):         # p_si with (p_si - p_s)/p_si = g(M_ic(p_T, p_si))
        psi = ps / (1.0 - true_dpp_ps(mach_from_qc(pt - psi, psi)))
    tat = OAT_K * (1.0 + 0.2 * RECOVERY * mach ** 2)
    noise = rng.normal(0.0, 1.0, (6, n))
    return Flight(time_s=np.arange(n) / hz,
                  qci_pa=pt - psi + 20.0 * noise[0], ps_pa=psi + 20.0 * noise[1],
                  gps_vn_mps=tas * np.cos(heading) + WIND[0] + 0.1 * noise[2],
                  gps_ve_mps=tas * np.sin(heading) + WIND[1] + 0.1 * noise[3],
                  gps_vd_mps=0.1 * noise[4], rho_kgm3=ps / (287.05287 * OAT_K), alt_m=h,
                  tat_k=tat + 0.1 * noise[5])
