"""The simulated aircraft's autopilot and the loop that steps it through the shared dynamics.

Two tracking controllers fly the plan (maneuvers.fly.simulator prepares their references):

- lateral guidance (`guidance_law`): the plan's ground track becomes bank commands, limited
  in bank and roll rate;
- the PI auto-throttle of maneuvers.plan.autothrottle (`autothrottle_law`): thrust on the plan's
  airspeed schedule (the true airspeed of its KCAS by the standard law, `planned_tas_mps`),
  through an engine lag, against quadratic drag;

and a proportional altitude hold. `integrate_closed_loop` integrates pitotcal.core.dynamics.rhs
with Heun's method, the controls and the wind held over each step.

The loop is scalar Python over plain floats (16,000 steps for 320 s at 50 Hz are cheaper so than
numpy calls on length-1 arrays); the controller steps are closures over plain lists so that a
call costs little more than the inlined code did.
"""

import math
import warnings

import numpy as np

from pitotcal.core.dynamics import rhs
from pitotcal.core.errors import PitotcalError
from pitotcal.core.speeds import tas_from_cas_mps
from pitotcal.core.units import G0_MPS2, mps_to_kt

__all__ = ["GUIDANCE_GAINS", "TAS_MISMATCH_WARN_KT", "autothrottle_law", "guidance_law",
           "integrate_closed_loop", "planned_tas_mps"]

# Lateral guidance: desired ground track = the path's direction + K_pos * distance to the path
# (1/s); heading loop K_psi (1/s). K_pos is slow (time constant 20 s) so turbulence does not make
# the bank busy; K_psi keeps a 10 deg heading error below a 20 deg bank correction at 45 m/s.
# Altitude hold: climb = the plan's climb + K_alt * altitude error (1/s).
GUIDANCE_GAINS = {"k_pos_per_s": 1.0 / 20.0, "k_psi_per_s": 0.4, "k_alt_per_s": 0.2}

# A plan whose tas_mps differs more than this from the TAS of its cas_mps (standard law) was
# written with another speed law (½ρ0 V² for KCAS, i.e. equivalent airspeed): say so.
TAS_MISMATCH_WARN_KT = 0.05


def planned_tas_mps(plan):
    """The true airspeed of the plan's KCAS at its altitude, m/s (`core.speeds`), warning when
    the plan's own tas_mps column disagrees by more than TAS_MISMATCH_WARN_KT."""
    try:
        tas = tas_from_cas_mps(plan.cas_mps, plan.alt_m)
    except PitotcalError as exc:
        raise PitotcalError(f"plan columns cas_mps, alt_m: {exc}") from None
    worst_kt = float(mps_to_kt(np.max(np.abs(tas - plan.tas_mps))))
    if worst_kt > TAS_MISMATCH_WARN_KT:
        warnings.warn(
            f"the plan's tas_mps differs by up to {worst_kt:.2f} kt from the true airspeed of "
            "its cas_mps by the standard CAS law (a plan whose KCAS was equivalent airspeed): "
            "flying cas_mps as calibrated airspeed; re-plan for consistent columns",
            stacklevel=4)
    return tas


def guidance_law(refs, limits):
    """The lateral guidance step for the references `refs` (maneuvers.fly.simulator.References).

    Returns
    -------
    step(north, east, psi, v, bank, wn, we, j) -> (bank, j)
        From the state (m, m, rad, m/s), the bank flown (rad), the process wind the autopilot
        knows (m/s, blowing TO) and the index `j` of the path point last tracked: the bank
        after one step of the roll-rate limit, and the new path index.

    Notes
    -----
    Guidance follows the plan's path, not its clock: in another wind the ground speed differs
    and a time-indexed reference would be chased across the circle, so the reference point
    slides forward along the path to the nearest point. The desired ground track (the path's
    direction plus a pull toward it) is solved through the wind triangle for the heading whose
    air velocity gives it; the heading error plus the plan's turn rate gives the bank command.
    """
    nr, er = refs.north_m.tolist(), refs.east_m.tolist()
    vgn, vge, turn_ff = refs.vn_mps.tolist(), refs.ve_mps.tolist(), refs.turn_rate_rps.tolist()
    k_pos, k_psi = GUIDANCE_GAINS["k_pos_per_s"], GUIDANCE_GAINS["k_psi_per_s"]
    bank_max = math.radians(limits.bank_max_deg)
    dbank_max = math.radians(limits.roll_rate_max_dps) * refs.dt_s
    last = len(nr) - 1
    two_pi, pi = 2.0 * math.pi, math.pi
    atan, atan2, hypot, sqrt = math.atan, math.atan2, math.hypot, math.sqrt

    def step(north, east, psi, v, bank, wn_c, we_c, j):
        d_j = (nr[j] - north) ** 2 + (er[j] - east) ** 2
        while j < last:
            d_next = (nr[j + 1] - north) ** 2 + (er[j + 1] - east) ** 2
            if d_next > d_j:
                break
            j, d_j = j + 1, d_next
        gn = vgn[j] + k_pos * (nr[j] - north)
        ge = vge[j] + k_pos * (er[j] - east)
        g_norm = hypot(gn, ge) or 1.0
        gn, ge = gn / g_norm, ge / g_norm
        dw = gn * wn_c + ge * we_c
        gs = dw + sqrt(max(v * v - wn_c * wn_c - we_c * we_c + dw * dw, 0.0))
        dpsi = (atan2(gs * ge - we_c, gs * gn - wn_c) - psi + pi) % two_pi - pi
        bank_cmd = atan(v * (turn_ff[j] + k_psi * dpsi) / G0_MPS2)
        bank_cmd = min(max(bank_cmd, -bank_max), bank_max)
        return bank + min(max(bank_cmd - bank, -dbank_max), dbank_max), j

    return step


def autothrottle_law(refs, loop, feedforward, thrust_max):
    """The auto-throttle step: PI on the airspeed schedule plus feed-forward, engine lag.

    Parameters
    ----------
    refs : maneuvers.fly.simulator.References
    loop : maneuvers.plan.autothrottle.SpeedLoop
    feedforward : ndarray (n_dyn,)
        Thrust feed-forward per unit mass at each dynamics step, m/s^2.
    thrust_max : float
        Thrust limit per unit mass, m/s^2 (the lower limit is 0).

    Returns
    -------
    step(i, v, thrust, integ) -> (thrust, integ)
        The thrust after one engine-lag step toward the command at step `i` and true airspeed
        `v`, and the PI integrator (updated only when the command is not saturated).
    """
    tas_r, ff = refs.tas_mps.tolist(), feedforward.tolist()
    kp, ki, dt = loop.kp, loop.ki, refs.dt_s
    alpha_e = 1.0 - math.exp(-dt / loop.engine_lag_s)

    def step(i, v, thrust, integ):
        err = tas_r[i] - v
        cmd = ff[i] + kp * err + ki * integ
        if cmd > thrust_max:
            cmd = thrust_max
            if err < 0:
                integ += err * dt
        elif cmd < 0.0:
            cmd = 0.0
            if err > 0:
                integ += err * dt
        else:
            integ += err * dt                               # anti-windup: only when unsaturated
        return thrust + (cmd - thrust) * alpha_e, integ

    return step


def integrate_closed_loop(refs, wind, loop, limits):
    """Integrate the shared dynamics under the autopilot through the wind field.

    Parameters
    ----------
    refs : maneuvers.fly.simulator.References
        The plan on the dynamics grid.
    wind : maneuvers.fly.simulator.WindField
        Process wind and gusts on the same grid.
    loop : maneuvers.plan.autothrottle.SpeedLoop
        Auto-throttle gains and the drag / engine model.
    limits : pitotcal.core.dynamics.Limits

    Returns
    -------
    states : ndarray (n, 8)
        north_m, east_m, alt_m, heading_rad, tas_mps, bank_rad, wind_n_mps, wind_e_mps at each
        sample time (`refs.sample_time_s`).
    path_index : list of int
        The guidance's path point at each sample time (an index into the references).

    Notes
    -----
    Heun (RK2): at 50 Hz and turn rates of ~0.1 rad/s its position error over 320 s is below a
    millimetre, and it halves the cost of RK4 (the loop's largest). The records are the states
    themselves, so GPS and q_c stay exactly consistent either way. An along-path gust changes
    the airspeed at once (the inertial speed cannot jump); the drag and the auto-throttle then
    restore it: hence -d(u_g)/dt in the speed equation, with the drift's along-path part.
    """
    n_dyn, dt = refs.time_s.size, refs.dt_s
    d_coef = G0_MPS2 / loop.lift_to_drag / loop.trim_tas_mps ** 2     # drag D = d_coef V^2
    thrust_max = d_coef * refs.tas_max_mps ** 2 + limits.accel_max_mps2
    # Thrust feed-forward D(V_ref) + V_ref', read one engine lag ahead: the schedule is known
    # in advance, and the engine delivers the command about tau_e later.
    lead = round(loop.engine_lag_s / dt)
    ahead = np.minimum(np.arange(n_dyn) + lead, n_dyn - 1)
    feedforward = d_coef * refs.tas_mps[ahead] ** 2 + refs.tas_rate_mps2[ahead]
    guidance = guidance_law(refs, limits)
    throttle = autothrottle_law(refs, loop, feedforward, thrust_max)
    k_alt, climb_max = GUIDANCE_GAINS["k_alt_per_s"], limits.climb_max_mps
    hr, clr = refs.alt_m.tolist(), refs.climb_mps.tolist()
    wnp, wep = wind.wind_n_mps.tolist(), wind.wind_e_mps.tolist()
    ug, vg, dug = wind.gust_u_mps.tolist(), wind.gust_v_mps.tolist(), wind.gust_u_rate_mps2.tolist()
    drift_n, drift_e = wind.drift_mps2
    x = [refs.north_m[0].item(), refs.east_m[0].item(), hr[0],
         math.radians(float(refs.heading_deg[0])), refs.tas_mps[0].item()]
    bank = math.radians(float(refs.bank_deg[0]))
    thrust = d_coef * x[4] ** 2 + refs.tas_rate_mps2[0].item()
    integ, j = 0.0, 0
    cos, sin = math.cos, math.sin
    rows, path_index = [], []
    for i in range(n_dyn):
        north, east, alt, psi, v = x
        cpsi, spsi = cos(psi), sin(psi)
        wn = wnp[i] + cpsi * ug[i] - spsi * vg[i]          # v_g points to the right wing
        we = wep[i] + spsi * ug[i] + cpsi * vg[i]
        rows.append((north, east, alt, psi, v, bank, wn, we))
        # the autopilot knows the process wind, not the gusts
        bank, j = guidance(north, east, psi, v, bank, wnp[i], wep[i], j)
        path_index.append(j)
        thrust, integ = throttle(i, v, thrust, integ)
        accel = thrust - d_coef * v * v - dug[i] - cpsi * drift_n - spsi * drift_e
        climb = min(max(clr[i] + k_alt * (hr[i] - alt), -climb_max), climb_max)
        u, w = (bank, accel, climb), (wn, we)
        k1 = rhs(x, u, w, math)
        k2 = rhs([a + dt * b for a, b in zip(x, k1)], u, w, math)
        x = [a + 0.5 * dt * (b1 + b2) for a, b1, b2 in zip(x, k1, k2)]
    every = refs.steps_per_sample
    return np.array(rows[::every]), path_index[::every]
