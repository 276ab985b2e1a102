"""A fixed-threshold airspeed check in the style of the autopilots, beside `pitotcal monitor`.

Re-implemented from PX4's `AirspeedValidator` (innovation check and data-stuck check): the true
airspeed innovation |TAS − |v_gps − w|| above a fixed threshold (ASPD_FS_INNOV, 5 m/s by
default; 2 m/s is the tighter gate PX4 users raise it to) is integrated, the check fails when
the integral exceeds ASPD_FS_INTEG (10 m) and resets to zero whenever the innovation is below
the threshold; the airspeed is declared invalid once the check has failed for
ASPD_FS_T_STOP (2 s) in a row. Data stuck: the raw reading unchanged for 2 s.

For a like-for-like comparison the check gets the same calibration (TAS from q_ci through the
identified pressure error) and the same wind the monitor tracked; PX4's own wind and scale
estimator would follow a slow fault and see less.
"""

import numpy as np

from pitotcal.core.models import get_model, qc_from_qci_pa

__all__ = ["PX4_DEFAULTS", "fixed_threshold_alarms"]

PX4_DEFAULTS = {"innov_mps": 5.0, "integ_m": 10.0, "fail_delay_s": 2.0, "stuck_s": 2.0}


def fixed_threshold_alarms(result, flight, cal, *, innov_mps=5.0, integ_m=10.0,
                           fail_delay_s=2.0, stuck_s=2.0, warmup_s=0.0):
    """Start times, s, at which the fixed-threshold check declares the airspeed invalid.

    Parameters
    ----------
    result : estimation.monitor.monitoring.MonitorResult
        The monitor's run on `flight` (its tracked wind is used).
    flight : Flight
    cal : estimation.monitor.model.Calibration
    innov_mps, integ_m, fail_delay_s, stuck_s : float
        PX4's ASPD_FS_INNOV, ASPD_FS_INTEG, ASPD_FS_T_STOP and the data-stuck time.
    warmup_s : float
        No alarm before this many seconds (the monitor's warm-up, for equal footing).
    """
    t = flight.time_s
    b = result.blocks
    j = np.clip(np.searchsorted(b["time_s"], t), 0, b["time_s"].size - 1)
    vd2 = 0.0 if flight.gps_vd_mps is None else flight.gps_vd_mps ** 2
    v_pred = np.sqrt((flight.gps_vn_mps - b["wind_n_mps"][j]) ** 2
                     + (flight.gps_ve_mps - b["wind_e_mps"][j]) ** 2 + vd2)
    # 1 Pa floor: a drained reading would divide by zero in the inverse model
    qc = qc_from_qci_pa(get_model(cal.model), cal.k, np.maximum(flight.qci_pa, 1.0))
    tas = np.sqrt(2.0 * qc / flight.rho_kgm3)
    innov = np.abs(tas - v_pred)
    dt = np.clip(np.diff(t, prepend=t[0]), 0.01, 0.2)
    over = innov > innov_mps
    integ = _run_sum(np.where(over, dt * (innov - innov_mps), 0.0), over)
    same = np.concatenate([[False], np.diff(flight.qci_pa) == 0.0])
    stuck = _run_sum(np.where(same, dt, 0.0), same) > stuck_s
    failing = (integ > integ_m) | stuck
    bad = _run_sum(np.where(failing, dt, 0.0), failing) >= fail_delay_s
    rising = bad & ~np.concatenate([[False], bad[:-1]]) & (t - t[0] >= warmup_s)
    return [float(x) for x in t[rising]]


def _run_sum(x, on):
    """Sum of `x` over the current run of `on` (0 where `on` is false): PX4's integrators,
    which reset whenever their condition lapses."""
    total = np.cumsum(x)
    base = np.maximum.accumulate(np.where(on, 0.0, total))
    return np.where(on, total - base, 0.0)
