"""Fly a plan with JSBSim, an independent six-degree-of-freedom flight model (`--engine jsbsim`).

pitotcal's own simulator shares the estimator's physics (a point mass, the same air-data
relations, Dryden gusts made the way the noise model expects). Here JSBSim flies the plan
instead: its aircraft (the Cessna 172 `c172x` by default), its standard atmosphere, its steady
wind and its MIL-F-8785C ("Milspec") turbulence, its isentropic total pressure. Sideslip, load
factor, the real engine and speed loop are all there. pitotcal supplies only what an autopilot
and the sensors would:

- guidance: `maneuvers.fly.guidance.guidance_law` turns the plan's ground track into a bank
  reference (same law and limits as the own simulator);
- inner loops written here: roll (aileron), altitude hold through pitch (elevator) and a PI
  auto-throttle on the plan's true airspeed (throttle), each with anti-windup;
- sensors: `maneuvers.fly.sensors` turns JSBSim's impact pressure q_c = p_t − p_s and ground
  velocity into the logged q_ci and GPS velocity, exactly as for the own simulator.

JSBSim steps at `JSBSIM_RATE_HZ`; the controls are updated at the own simulator's dynamics
rate (`maneuvers.fly.simulator.DYNAMICS_RATE_HZ`).
"""

import math

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import FT_TO_M, wind_vector_mps

__all__ = ["DEFAULT_AIRCRAFT", "GAINS", "JSBSIM_RATE_HZ", "aircraft_names", "milspec_setting",
           "new_fdm", "run_closed_loop", "set_turbulence", "start"]

DEFAULT_AIRCRAFT = "c172x"
# JSBSim's own default rate is 120 Hz; 150 Hz is three steps per 50 Hz control step.
JSBSIM_RATE_HZ = 150.0
# Where the test area is put on the earth when the plan has no --center (JSBSim flies on a
# WGS-84 earth; the plan's local north/east are offsets from here).
DEFAULT_CENTER_DEG = (37.0, -122.0)

PSF_TO_PA = 47.880258980335840      # lbf/ft^2 (JSBSim's pressures)
SLUGFT3_TO_KGM3 = 515.378818        # slug/ft^3 (JSBSim's densities)
RANKINE_TO_K = 5.0 / 9.0

# MIL-F-8785C figure 7 (the table JSBSim's Milspec model interpolates): horizontal turbulence
# sigma, ft/s, by probability-of-exceedance index (rows, 1 = 2e-1 ... 4 = 1e-3 "moderate")
# and altitude (columns, ft). Used above 2000 ft; below 1000 ft the intensity follows the wind
# at 20 ft instead (sigma_w = 0.1 W20).
_POE_ALT_FT = (500.0, 1750.0, 3750.0, 7500.0, 15000.0)
_POE_SIGMA_FPS = {1: (3.2, 2.2, 1.5, 0.0, 0.0), 2: (4.2, 3.6, 3.3, 1.6, 0.0),
                  3: (6.6, 6.9, 7.4, 6.7, 4.6), 4: (8.6, 9.6, 10.6, 10.1, 8.0)}

# Inner-loop gains (normalised surface or throttle per rad, rad/s, m, m/s), tuned on c172x
# at 70-105 KCAS. The rudder on sideslip coordinates the turns: on the T-2 plan (180 s) it
# took the largest sideslip from 3.4 deg (no rudder) to 1.1 deg (measured).
GAINS = {"roll": 2.0, "roll_i": 0.5, "roll_rate": 0.3,
         "pitch": 4.0, "pitch_rate": 1.0,
         "alt": 0.01, "alt_i": 0.0005, "climb": 0.02,
         "speed": 0.15, "speed_i": 0.03, "sideslip": -10.0}


def aircraft_names():
    """The aircraft JSBSim ships (folders of its `aircraft` directory), sorted."""
    import os

    import jsbsim

    root = os.path.join(jsbsim.get_default_root_dir(), "aircraft")
    return sorted(d for d in os.listdir(root) if os.path.isdir(os.path.join(root, d)))


def _low_altitude_sigma_u_fps(w20_fps, h_ft):
    """MIL-F-8785C below 1000 ft: sigma_w = 0.1 W20, sigma_u = sigma_w / (0.177 + 0.000823 h)^0.4."""
    return 0.1 * w20_fps / (0.177 + 0.000823 * max(h_ft, 10.0)) ** 0.4


def _poe_sigma_fps(severity, h_ft):
    return float(np.interp(h_ft, _POE_ALT_FT, _POE_SIGMA_FPS[severity]))


def milspec_setting(turbulence_mps, alt_agl_m):
    """JSBSim Milspec settings for a horizontal turbulence sigma at a height above ground.

    Returns
    -------
    (w20_fps, severity, sigma_mps) : (float, int, float)
        The wind at 20 ft that gives `turbulence_mps` below 1000 ft exactly; the probability-
        of-exceedance index whose sigma is nearest above 2000 ft (the table is discrete); and
        the sigma JSBSim will make with them (interpolated between 1000 and 2000 ft, as JSBSim
        does). (0, 0, 0) for no turbulence.
    """
    if turbulence_mps <= 0:
        return 0.0, 0, 0.0
    h_ft = alt_agl_m / FT_TO_M
    target_fps = turbulence_mps / FT_TO_M
    w20 = target_fps / _low_altitude_sigma_u_fps(1.0, min(h_ft, 1000.0))
    severity = min(_POE_SIGMA_FPS, key=lambda s: abs(_poe_sigma_fps(s, max(h_ft, 2000.0))
                                                     - target_fps))
    low = _low_altitude_sigma_u_fps(w20, min(h_ft, 1000.0))
    high = _poe_sigma_fps(severity, max(h_ft, 2000.0))
    frac = min(max((h_ft - 1000.0) / 1000.0, 0.0), 1.0)
    return w20, severity, ((1.0 - frac) * low + frac * high) * FT_TO_M


def new_fdm(aircraft, dt_s, scratch_dir):
    """A quiet JSBSim instance with `aircraft` loaded (PitotcalError naming the choices).

    The aircraft's own <output> file (c172x: JSBout172B.csv, opened at run_ic whatever
    disable_output says) goes to `scratch_dir`, never the user's working folder.
    """
    import jsbsim

    jsbsim.FGJSBBase().debug_lvl = 0           # no banner, no per-model chatter
    fdm = jsbsim.FGFDMExec(None)
    fdm.set_debug_level(0)
    fdm.set_output_path(str(scratch_dir))
    if aircraft not in aircraft_names() or not fdm.load_model(aircraft):
        raise PitotcalError(f"aircraft {aircraft!r} is not one JSBSim ships; e.g. "
                            f"{', '.join(n for n in aircraft_names() if n.startswith('c1'))}",
                            param="aircraft")
    fdm.set_dt(dt_s)
    return fdm


def start(fdm, plan, refs, opts, center_deg, alt_agl_m):
    """Put the aircraft at the plan's first point, in the wind and turbulence, and trim it.

    Returns the trimmed (throttle, pitch attitude rad).
    """
    from pitotcal.core.geo import latlon_from_offset_m

    lat, lon = latlon_from_offset_m(*center_deg, float(refs.north_m[0]), float(refs.east_m[0]))
    wn, we = map(float, wind_vector_mps(opts.wind_speed_mps, opts.wind_from_deg))
    tas, psi = float(refs.tas_mps[0]), math.radians(float(refs.heading_deg[0]))
    settings = {
        "ic/lat-geod-deg": lat, "ic/long-gc-deg": lon,
        "ic/h-sl-ft": float(refs.alt_m[0]) / FT_TO_M,
        "ic/terrain-elevation-ft": (float(refs.alt_m[0]) - alt_agl_m) / FT_TO_M,
        # the wind through the initial condition, so that the trim flies in it (the trim
        # resets atmosphere/wind-*); ic/vw-dir-deg is the direction it blows TO. The airspeed
        # through the ground velocity = air velocity + wind: JSBSim's ic/vt-fps does not
        # give the asked airspeed once an initial wind is set (measured).
        "ic/vw-mag-fps": opts.wind_speed_mps / FT_TO_M,
        "ic/vw-dir-deg": (opts.wind_from_deg + 180.0) % 360.0,
        "ic/psi-true-deg": math.degrees(psi) % 360.0,
        "ic/vn-fps": (tas * math.cos(psi) + wn) / FT_TO_M,
        "ic/ve-fps": (tas * math.sin(psi) + we) / FT_TO_M}
    for name, value in settings.items():
        fdm[name] = value
    fdm.run_ic()
    fdm["propulsion/set-running"] = -1
    fdm["fcs/mixture-cmd-norm"] = 1.0
    if not _trimmed(fdm):
        raise PitotcalError(f"JSBSim could not trim the {fdm.get_model_name()} at "
                            f"{refs.tas_mps[0]:.1f} m/s TAS and {refs.alt_m[0]:.0f} m; "
                            "choose speeds this aircraft can fly")
    return fdm["fcs/throttle-cmd-norm"], fdm["attitude/theta-rad"]


def _trimmed(fdm):
    """Trim for steady level flight: full, else longitudinal only (in a crosswind the full
    trim can fail on yaw acceleration; the controllers take the rest). JSBSim's trim prints:
    its text is caught."""
    from pitotcal.io.streams import captured_output

    for mode in (1, 0):                       # tFull, tLongitudinal
        try:
            with captured_output():
                fdm.do_trim(mode)
            return True
        except Exception:                     # noqa: BLE001, S112 - TrimFailureException
            continue
    return False


def set_turbulence(fdm, opts, alt_agl_m, seed):
    """Switch JSBSim's Milspec turbulence on at `opts.turbulence_mps`; the sigma it will make."""
    w20, severity, sigma = milspec_setting(opts.turbulence_mps, alt_agl_m)
    if severity:
        fdm["atmosphere/turb-type"] = 3                      # ttMilspec (Dryden spectrum)
        fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20
        fdm["atmosphere/turbulence/milspec/severity"] = severity
        fdm["simulation/randomseed"] = int(seed) % (2 ** 31)
    return sigma


def _clip(x, lo, hi):
    return min(max(x, lo), hi)


def control_law(refs, trim, dt_s):
    """The inner loops: step(fdm, i, bank_ref) sets the controls for dynamics step `i`."""
    g = GAINS
    thr0, theta0 = trim
    alt_r, climb_r, tas_r = refs.alt_m.tolist(), refs.climb_mps.tolist(), refs.tas_mps.tolist()
    state = {"roll_i": 0.0, "alt_i": 0.0, "speed_i": 0.0}

    def step(fdm, i, bank_ref):
        phi, p = fdm["attitude/phi-rad"], fdm["velocities/p-rad_sec"]
        e_phi = bank_ref - phi
        ail = g["roll"] * e_phi + g["roll_i"] * state["roll_i"] - g["roll_rate"] * p
        if abs(ail) < 1.0:
            state["roll_i"] += e_phi * dt_s
        e_h = alt_r[i] - fdm["position/h-sl-ft"] * FT_TO_M
        climb = -fdm["velocities/v-down-fps"] * FT_TO_M
        theta_ref = (theta0 + g["alt"] * e_h + g["alt_i"] * state["alt_i"]
                     + g["climb"] * (climb_r[i] - climb))
        state["alt_i"] += e_h * dt_s
        elev = -(g["pitch"] * (theta_ref - fdm["attitude/theta-rad"])
                 - g["pitch_rate"] * fdm["velocities/q-rad_sec"])
        e_v = tas_r[i] - fdm["velocities/vtrue-fps"] * FT_TO_M
        thr = thr0 + g["speed"] * e_v + g["speed_i"] * state["speed_i"]
        if 0.0 < thr < 1.0 or (thr >= 1.0) == (e_v < 0):     # anti-windup
            state["speed_i"] += e_v * dt_s
        fdm["fcs/aileron-cmd-norm"] = _clip(ail, -1.0, 1.0)
        fdm["fcs/elevator-cmd-norm"] = _clip(elev, -1.0, 1.0)
        fdm["fcs/throttle-cmd-norm"] = _clip(thr, 0.0, 1.0)
        fdm["fcs/rudder-cmd-norm"] = _clip(g["sideslip"] * fdm["aero/beta-rad"], -1.0, 1.0)

    return step


# What is recorded at each sample time (JSBSim property, scale to SI).
RECORD = {
    "lat_deg": ("position/lat-geod-deg", 1.0), "lon_deg": ("position/long-gc-deg", 1.0),
    "alt_m": ("position/h-sl-ft", FT_TO_M), "heading_rad": ("attitude/psi-rad", 1.0),
    "tas_mps": ("velocities/vtrue-fps", FT_TO_M), "bank_rad": ("attitude/phi-rad", 1.0),
    "wind_n_mps": ("atmosphere/total-wind-north-fps", FT_TO_M),
    "wind_e_mps": ("atmosphere/total-wind-east-fps", FT_TO_M),
    "vn_mps": ("velocities/v-north-fps", FT_TO_M), "ve_mps": ("velocities/v-east-fps", FT_TO_M),
    "vd_mps": ("velocities/v-down-fps", FT_TO_M),
    "pt_pa": ("propulsion/pt-lbs_sqft", PSF_TO_PA), "ps_pa": ("atmosphere/P-psf", PSF_TO_PA),
    "oat_k": ("atmosphere/T-R", RANKINE_TO_K), "rho_kgm3": ("atmosphere/rho-slugs_ft3",
                                                            SLUGFT3_TO_KGM3),
    "beta_rad": ("aero/beta-rad", 1.0), "alpha_rad": ("aero/alpha-rad", 1.0),
    "stall_warning": ("systems/stall-warn-norm", 1.0),
}


def run_closed_loop(fdm, refs, limits, opts, trim, center_deg, steps_per_control):
    """Fly the references with JSBSim; the records at the sample times and the path indices."""
    from pitotcal.core.geo import offset_m_from_latlon

    from .guidance import guidance_law

    guidance = guidance_law(refs, limits)
    control = control_law(refs, trim, refs.dt_s)
    wn0, we0 = map(float, wind_vector_mps(opts.wind_speed_mps, opts.wind_from_deg))
    drift_n, drift_e = opts.wind_drift_mps2
    t_mid = 0.5 * float(refs.time_s[0] + refs.time_s[-1])
    names = [(key, prop, scale) for key, (prop, scale) in RECORD.items()]
    rows, path_index = [], []
    bank_ref, j = fdm["attitude/phi-rad"], 0
    for i, t in enumerate(refs.time_s.tolist()):
        # the process wind (mean + drift about the middle), which the autopilot knows
        wn, we = wn0 + drift_n * (t - t_mid), we0 + drift_e * (t - t_mid)
        if drift_n or drift_e:
            fdm["atmosphere/wind-north-fps"] = wn / FT_TO_M
            fdm["atmosphere/wind-east-fps"] = we / FT_TO_M
        if i % refs.steps_per_sample == 0:
            rows.append([fdm[prop] * scale for _, prop, scale in names])
            path_index.append(j)
        north, east = offset_m_from_latlon(*center_deg, fdm["position/lat-geod-deg"],
                                           fdm["position/long-gc-deg"])
        bank_ref, j = guidance(north, east, fdm["attitude/psi-rad"],
                               fdm["velocities/vtrue-fps"] * FT_TO_M, bank_ref, wn, we, j)
        control(fdm, i, bank_ref)
        for _ in range(steps_per_control):
            fdm.run()
        if not math.isfinite(fdm["position/h-sl-ft"]) or fdm["position/h-agl-ft"] < 0:
            raise PitotcalError(f"the JSBSim {fdm.get_model_name()} left controlled flight at "
                                f"t = {t:.1f} s: the plan asks more than it can "
                                "fly (speeds, bank) in this turbulence")
    record = {key: np.array(col) for (key, _, _), col in zip(names, zip(*rows))}
    north, east = np.array([offset_m_from_latlon(*center_deg, la, lo) for la, lo in
                            zip(record["lat_deg"], record["lon_deg"])]).T
    record.update(north_m=north, east_m=east, qc_pa=record["pt_pa"] - record["ps_pa"])
    return record, path_index
