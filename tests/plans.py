"""Hand-made plans for the tests, independent of the planner."""

import numpy as np

from pitotcal.core.plan import Plan
from pitotcal.core.airdata import cas_from_qc_mps, qc_from_cas_pa
from pitotcal.core.speeds import tas_from_qc_mps
from pitotcal.core.units import G0_MPS2, kt_to_mps


def circle_plan(duration_s=240.0, cas_kt=(70.0, 100.0), radius_m=600.0, altitude_m=244.0,
                wind_speed_mps=5.0, wind_from_deg=270.0, step_s=0.5, sweeps=None):
    """A hand-made plan: a ground circle about the centre flown in the wind, CAS uniform in q
    (the standard CAS law and the isentropic q_c at the ISA altitude, as the planner writes).
    `sweeps` (a number): q goes up and down that many times instead of once up, as an
    everyday flight's long loiter varies its speed.

    (Independent of the planner, so the simulator tests do not depend on it.)
    """
    t = np.arange(0.0, duration_s + 1e-9, step_s)
    qlo, qhi = (float(qc_from_cas_pa(kt_to_mps(v))) for v in cas_kt)
    phase = t / duration_s if sweeps is None else \
        1.0 - np.abs(1.0 - 2.0 * ((sweeps * t / duration_s) % 1.0))
    qc = qlo + (qhi - qlo) * phase
    cas = cas_from_qc_mps(qc)
    tas = tas_from_qc_mps(qc, altitude_m)
    a = np.radians(wind_from_deg)
    w = np.array([-wind_speed_mps * np.cos(a), -wind_speed_mps * np.sin(a)])

    def ground_speed(theta, v):
        tau = np.array([-np.sin(theta), np.cos(theta)])
        tw = tau @ w
        return tw + np.sqrt(v * v - w @ w + tw * tw)

    theta = np.zeros(t.size)
    for i in range(1, t.size):
        s1 = ground_speed(theta[i - 1], tas[i - 1])
        s2 = ground_speed(theta[i - 1] + step_s * s1 / radius_m, tas[i])
        theta[i] = theta[i - 1] + step_s * 0.5 * (s1 + s2) / radius_m
    s = np.array([ground_speed(th, v) for th, v in zip(theta, tas)])
    air = s[:, None] * np.column_stack([-np.sin(theta), np.cos(theta)]) - w
    heading = np.unwrap(np.arctan2(air[:, 1], air[:, 0]))
    bank = np.degrees(np.arctan(tas * np.gradient(heading, t) / G0_MPS2))
    settings = {"profile": "test-circle", "cas_min_kt": cas_kt[0], "cas_max_kt": cas_kt[1],
                "radius_m": radius_m, "altitude_m": altitude_m, "duration_s": duration_s,
                "bank_max_deg": 30.0, "wind_speed_mps": wind_speed_mps,
                "wind_from_deg": wind_from_deg}
    return Plan(time_s=t, north_m=radius_m * np.cos(theta), east_m=radius_m * np.sin(theta),
                alt_m=np.full(t.size, altitude_m), heading_deg=np.degrees(heading),
                bank_deg=bank, tas_mps=tas, cas_mps=cas, qc_pa=qc, settings=settings)
