"""On the ground or in the air: the autopilot's own flight state, and the take-off/landing gate.

A log runs from power-on to power-off: taxi, take-off roll, landing roll and the time on the
ground after it are no calibration data (a pitot on the ground roll at 5-10 m/s reads through
ground effect and propeller wash, and the correction table would start at taxi speed).

Two cuts, both computed over the whole log (so a window cannot make them differ):

- the autopilot's state, where the log has it: ArduPilot ``STAT.isFlying`` and ``STAT.Armed``;
  PX4 ``vehicle_land_detected.landed`` and ``vehicle_status.arming_state``. Held from one
  state message to the next (`pitotcal.io.resample`); before the first one, the first state.
- an airspeed gate at both ends of each flying span: from the start of the span until the
  indicated airspeed first reaches the gate, and after it last falls below it (the take-off
  roll, the flare and the landing roll, which the autopilots still count as flying). Slow
  flight in between (the slow end of a speed sweep) is kept. The gate is the autopilot's own
  minimum airspeed parameter (ArduPilot ``ARSPD_FBW_MIN`` / ``AIRSPEED_MIN``, PX4
  ``FW_AIRSPD_MIN``), or `min_airspeed_mps` given to `pitotcal.io.logs.load_log`. A log with
  neither state nor parameter gets neither cut (the 20 Pa and 5 m/s floors still apply).
"""

import numpy as np

from pitotcal.core.units import incompressible_cas_mps

from .resample import hold
from .timebase import clean

__all__ = ["airspeed_gate", "flight_state_cuts", "gate_ends"]


def flight_state_cuts(s, t, qci_pa, min_airspeed_mps=None):
    """{reason: mask} of the samples at times `t` that are not flight (module notes).

    Parameters
    ----------
    s : LogStreams
        With ``airborne_t``/``airborne`` (the autopilot's state) and ``min_airspeed_mps``.
    t, qci_pa : ndarray, shape (N,)
        The pressure samples' times, s, and impact pressures, Pa.
    min_airspeed_mps : float, optional
        The gate instead of the log's parameter; 0 turns it off.

    Returns
    -------
    dict
        Reason text -> boolean mask, in the order to apply them; empty when the log has
        neither state nor gate.
    """
    cuts = {}
    airborne = np.ones(t.size, bool)
    if s.airborne_t is not None and s.airborne_t.size:
        ts, state = clean(np.asarray(s.airborne_t, float), np.asarray(s.airborne, float))
        held, valid = hold(ts, state, t)
        airborne = np.where(valid, held, state[0]) > 0.5
        cuts[f"autopilot not flying ({s.airborne_source})"] = ~airborne
    gate, source = airspeed_gate(s, min_airspeed_mps)
    if gate:
        fast = incompressible_cas_mps(qci_pa) >= gate
        cuts[f"take-off or landing: IAS < {gate:g} m/s ({source})"] = gate_ends(airborne, fast)
    return cuts


def airspeed_gate(s, min_airspeed_mps=None):
    """(gate, source): `min_airspeed_mps` if given, else the log's parameter; (0, "") if none."""
    if min_airspeed_mps is not None:
        return min_airspeed_mps, "given"
    return (s.min_airspeed_mps or 0.0), s.min_airspeed_source


def gate_ends(airborne, fast):
    """Samples of each run of `airborne` before its first `fast` sample and after its last.

    A run that is never fast is cut whole.
    """
    out = np.zeros(airborne.size, bool)
    edges = np.flatnonzero(np.diff(np.r_[0, airborne.astype(np.int8), 0]))
    for a, b in zip(edges[::2], edges[1::2]):
        hit = np.flatnonzero(fast[a:b])
        if hit.size == 0:
            out[a:b] = True
        else:
            out[a:a + hit[0]] = True
            out[a + hit[-1] + 1:b] = True
    return out
