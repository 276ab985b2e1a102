"""What a plan becomes for the people and machines that fly it.

- pilot card, plain text and PNG: time, target KCAS +-5, bank / heading cues, in knots and feet;
- auto-throttle setpoints CSV: time, CAS command, acceleration feed-forward;
- plan figure: ground track inside the circle with the wind arrow, CAS against time, and the
  histogram of q on a uniform time grid (it should be flat for the continuous profile).

Figures use `matplotlib.figure.Figure` directly (no pyplot state, no GUI backend), so the
library can be used from scripts, tests and worker processes alike.
"""

import csv
import json
import os
from pathlib import Path

import numpy as np
from .card import PNG_OPTIONS, calibration_lines, design_lines, kias_targets, turn_text

from pitotcal.core.errors import PitotcalError
from pitotcal.core.processes import EarlyChild, side_by_side
from pitotcal.core.scenario import ALT_TOLERANCE_FT, CAS_TOLERANCE_KT
from pitotcal.core.units import m_to_ft, mps_to_kt
from pitotcal.io.atomic import atomic_open, save_figure
from pitotcal.io.jsonfile import json_ready
from pitotcal.io.plan_csv import write_plan
from pitotcal.io.resample import hold

# Bank cues are to be held within this, degrees: the track, not the exact bank, matters.
BANK_TOLERANCE_DEG = 5.0

__all__ = [
    "autothrottle_setpoints",
    "check_output_paths",
    "output_paths",
    "pilot_card_text",
    "plot_plan",
    "start_figures",
    "write_autothrottle_csv",
    "write_pilot_card",
    "write_plan_outputs",
]


def _cue_indices(plan, cue_s):
    """Nodes every `cue_s` seconds, plus every ramp start / end (where the speed law bends)."""
    t = plan.time_s
    marks = set(np.searchsorted(t, np.arange(t[0], t[-1] + 1e-9, cue_s)).clip(0, plan.n - 1))
    accel = np.diff(plan.tas_mps) / np.diff(t)
    bends = np.flatnonzero(np.abs(np.diff(accel)) > 0.05) + 1
    marks.update(int(b) for b in bends)
    marks.add(plan.n - 1)
    return np.array(sorted(marks))


def _heading_cue(plan, k):
    """Heading at node k, degrees true, rounded to 5° (the plan's heading is unwrapped)."""
    return (round(plan.heading_deg[k] / 5.0) * 5) % 360


def _bearing_deg(plan, k):
    """Bearing of the aircraft from the test-area centre at node k, degrees true."""
    return float(np.degrees(np.arctan2(plan.east_m[k], plan.north_m[k])) % 360.0)


def _bank_cue(bank_deg):
    if abs(bank_deg) < 0.5:
        return "level"
    return f"{'R' if bank_deg > 0 else 'L'}{abs(bank_deg):.0f}°"


def _speed_cue(plan, k, accel, kcas_rate):
    """What the throttle hand does from node k on: hold, accelerate to a level, or a trend."""
    if k >= accel.size:
        return "end"
    if abs(accel[k]) < 1e-3:
        return "hold"
    if abs(accel[k]) > 0.3:
        # a ramp: name the speed at its end
        end = k
        while end < accel.size and abs(accel[end] - accel[k]) < 1e-3:
            end += 1
        verb = "accelerate" if accel[k] > 0 else "decelerate"
        return f"{verb} to {mps_to_kt(plan.cas_mps[end]):.0f}"
    return f"{kcas_rate[k]:+.2f} kt/s"


def _magnetic_deg(plan, true_deg):
    return (true_deg - plan.settings["magvar_deg"]) % 360.0     # variation east positive


def _geo_lines(plan):
    """With --center: the centre and start in coordinates, and the magnetic variation."""
    from pitotcal.core.geo import latlon_from_offset_m, latlon_text

    s = plan.settings
    lat0, lon0 = s["center_lat_deg"], s["center_lon_deg"]
    start = latlon_from_offset_m(lat0, lon0, float(plan.north_m[0]), float(plan.east_m[0]))
    lines = [f"Centre {latlon_text(lat0, lon0)} | start {latlon_text(*start)} (WGS-84)"]
    if "magvar_deg" in s:
        var = s["magvar_deg"]
        lines.append(f"Magnetic variation {abs(var):g}°{'E' if var >= 0 else 'W'}: start "
                     f"heading {_magnetic_deg(plan, _heading_cue(plan, 0)):03.0f}°M, MAG "
                     f"column = heading °magnetic")
    return lines


def pilot_card_text(plan, cue_s=15.0):
    """The pilot card as plain text (knots, feet, degrees true).

    With ``center_lat_deg``/``center_lon_deg`` in the settings (`pitotcal plan --center`):
    the centre and start in coordinates, ``altitude_ref`` (MSL/AGL) and, with ``magvar_deg``
    (east positive), magnetic headings.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
    cue_s : float
        Interval of the cue rows, s (ramp starts and ends are always cued).

    Returns
    -------
    str
    """
    s = plan.settings
    geo = "center_lat_deg" in s
    magnetic = geo and "magvar_deg" in s
    kias = kias_targets(plan)
    alt_ft = float(m_to_ft(np.mean(plan.alt_m)))
    alt_ref = f" {str(s.get('altitude_ref', 'msl')).upper()}" if geo else ""
    wind_kt = float(mps_to_kt(s.get("wind_speed_mps", 0.0)))
    # a direction means nothing without wind: "270° / 0 kt" read as a westerly
    wind = (f"{s.get('wind_from_deg', 0):03.0f}° / {wind_kt:.0f} kt" if round(wind_kt) > 0
            else "calm")
    lines = [
        f"PITOT-STATIC CALIBRATION - {str(s.get('profile', '?')).upper()} "
        f"{mps_to_kt(plan.cas_mps.min()):.0f}-{mps_to_kt(plan.cas_mps.max()):.0f} KCAS, "
        f"{plan.time_s[-1] - plan.time_s[0]:.0f} s",
        f"Altitude {alt_ft:.0f} ft{alt_ref} +-{ALT_TOLERANCE_FT:.0f} ft | airspeed target "
        f"+-{CAS_TOLERANCE_KT:.0f} KCAS | "
        f"stay within {m_to_ft(s.get('radius_m', np.nan)):.0f} ft of centre",
        f"{turn_text(s)}, bank max {s.get('bank_max_deg', '?')}° | "
        f"expected wind {wind}",
        f"Start {m_to_ft(np.hypot(plan.north_m[0], plan.east_m[0])):.0f} ft from centre on "
        f"bearing {_bearing_deg(plan, 0):03.0f}°, heading {_heading_cue(plan, 0):03.0f}°, "
        f"{_bank_cue(plan.bank_deg[0])}, {mps_to_kt(plan.cas_mps[0]):.0f} KCAS",
        *(_geo_lines(plan) if geo else []),
        *design_lines(s),
        ("HDG: heading flown, °true | FROM CTR: distance and bearing from the centre | "
         f"BANK: within {BANK_TOLERANCE_DEG:.0f}° of the cue"),
        *calibration_lines(s),
        "",
        (f"{'TIME':>5}  {'KCAS':>9}  {'KIAS  ' if kias is not None else ''}{'BANK':>5}  {'HDG':>4}  "
         f"{'MAG  ' if magnetic else ''}{'FROM CTR':>14}  SPEED CUE"),
    ]
    accel = np.diff(plan.tas_mps) / np.diff(plan.time_s)
    kcas_rate = np.diff(mps_to_kt(plan.cas_mps)) / np.diff(plan.time_s)
    for k in _cue_indices(plan, cue_s):
        t = plan.time_s[k] - plan.time_s[0]
        kcas = float(mps_to_kt(plan.cas_mps[k]))
        dist_ft = float(m_to_ft(np.hypot(plan.north_m[k], plan.east_m[k])))
        lines.append(f"{int(t // 60):2d}:{int(t % 60):02d}  {kcas:5.1f}±{CAS_TOLERANCE_KT:.0f}  "
                     + (f"{kias[k]:5.1f} " if kias is not None else "")
                     + f"{_bank_cue(plan.bank_deg[k]):>5}  {_heading_cue(plan, k):03.0f}°  "
                     + (f"{_magnetic_deg(plan, _heading_cue(plan, k)):03.0f}M  " if magnetic
                        else "")
                     + f"{dist_ft:6.0f} ft {_bearing_deg(plan, k):03.0f}°  "
                     f"{_speed_cue(plan, k, accel, kcas_rate)}")
    return "\n".join(lines) + "\n"


def write_pilot_card(plan, png_path=None, txt_path=None, cue_s=15.0):
    """Write the pilot card as plain text and/or PNG; returns the paths written."""
    text = pilot_card_text(plan, cue_s)
    written = []
    if txt_path is not None:
        with atomic_open(txt_path, "w") as fh:
            fh.write(text)
        written.append(Path(txt_path))
    if png_path is not None:
        from .card import draw_card

        draw_card(plan, text, png_path)
        written.append(Path(png_path))
    return written


def autothrottle_setpoints(plan, rate_hz=None):
    """Auto-throttle setpoints: CAS command and the acceleration feed-forward.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
    rate_hz : float, optional
        Resample to this rate; default: the plan's own nodes.

    Returns
    -------
    dict of ndarray
        ``time_s``, ``cas_cmd_kt``, ``cas_cmd_mps``, ``tas_cmd_mps``, ``accel_ff_mps2``.

    Notes
    -----
    The feed-forward is the true-airspeed acceleration of the interval that starts at each
    time (TAS is linear inside a planner interval), held to the end.
    """
    t, tas, cas = plan.time_s, plan.tas_mps, plan.cas_mps
    accel = np.diff(tas) / np.diff(t)
    if rate_hz is None:
        time_s = t
    else:
        time_s = np.arange(t[0], t[-1] + 0.5 / rate_hz, 1.0 / rate_hz)
    # the interval starting at or before each time (the last one from the final node on)
    accel_ff, _ = hold(t[:-1], accel, time_s)
    cas_cmd = np.interp(time_s, t, cas)
    return {"time_s": time_s, "cas_cmd_kt": mps_to_kt(cas_cmd), "cas_cmd_mps": cas_cmd,
            "tas_cmd_mps": np.interp(time_s, t, tas), "accel_ff_mps2": accel_ff}


def write_autothrottle_csv(plan, path, rate_hz=None):
    """Write `autothrottle_setpoints` as CSV with the plan settings as `#` comments."""
    sp = autothrottle_setpoints(plan, rate_hz)
    path = Path(path)
    with atomic_open(path, "w", newline="") as fh:
        for key in ("profile", "cas_min_kt", "cas_max_kt", "altitude_m", "accel_max_mps2"):
            if key in plan.settings:
                value = json.dumps(json_ready(plan.settings[key]), allow_nan=False)
                fh.write(f"# {key}: {value}\n")
        writer = csv.writer(fh)
        writer.writerow(list(sp))
        for row in zip(*sp.values()):
            writer.writerow([f"{row[0]:.3f}"] + [f"{v:.6g}" for v in row[1:]])
    return path


def plot_plan(plan, path=None):
    """Plan figure: ground track + circle + wind arrow, CAS vs time, histogram of q.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
    path : path-like, optional
        Save the figure there (PNG).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    s = plan.settings
    # fixed margins: a constrained layout took half of the figure's 0.3 s (`pitotcal plan`)
    fig = Figure(figsize=(13, 4.2))
    ax_track, ax_cas, ax_q = fig.subplots(1, 3, gridspec_kw={
        "width_ratios": [1.35, 1.25, 0.95], "left": 0.06, "right": 0.99, "bottom": 0.11,
        "top": 0.93, "wspace": 0.3})
    radius = float(s.get("radius_m", np.hypot(plan.north_m, plan.east_m).max()))
    theta = np.linspace(0, 2 * np.pi, 361)
    ax_track.plot(radius * np.sin(theta), radius * np.cos(theta), "k--", lw=1,
                  label=f"radius {radius:.0f} m")
    sc = ax_track.scatter(plan.east_m, plan.north_m, c=plan.time_s, s=4, cmap="viridis")
    ax_track.plot(plan.east_m[0], plan.north_m[0], "go", ms=6, label="start")
    ax_track.plot(plan.east_m[-1], plan.north_m[-1], "rs", ms=6, label="end")
    wind = float(s.get("wind_speed_mps", 0.0))
    if wind > 0:
        # arrow drawn the way the air moves, entering from the side the wind comes from
        from_rad = np.radians(float(s.get("wind_from_deg", 0.0)))
        d_e, d_n = -np.sin(from_rad), -np.cos(from_rad)
        start = -0.95 * radius * np.array([d_e, d_n])
        ax_track.annotate("", xy=start + 0.45 * radius * np.array([d_e, d_n]), xytext=start,
                          arrowprops={"arrowstyle": "-|>", "color": "tab:red", "lw": 2})
        ax_track.text(0.02, 0.98, f"wind {wind:g} m/s from {s.get('wind_from_deg', 0):.0f}°",
                      transform=ax_track.transAxes, color="tab:red", fontsize=8, va="top")
    ax_track.set_aspect("equal")
    ax_track.set_xlabel("east, m")
    ax_track.set_ylabel("north, m")
    # y given: where matplotlib would put it (nothing above the axes), without measuring every
    # tick label to find out (a quarter of the figure's drawing time)
    ax_track.set_title("ground track", y=1.0)
    ax_track.legend(loc="lower right", fontsize=7)
    fig.colorbar(sc, ax=ax_track, label="time, s", shrink=0.8)

    kt = mps_to_kt(plan.cas_mps)
    ax_cas.fill_between(plan.time_s, kt - CAS_TOLERANCE_KT, kt + CAS_TOLERANCE_KT, alpha=0.2,
                        label=f"±{CAS_TOLERANCE_KT:.0f} KCAS")
    ax_cas.plot(plan.time_s, kt, label="target CAS")
    ax_cas.set_xlabel("time, s")
    ax_cas.set_ylabel("CAS, kt")
    ax_cas.set_title(f"{s.get('profile', '')} schedule", y=1.0)
    ax_cas.grid(alpha=0.3)
    ax_cas.legend(fontsize=8)

    # the estimator sees samples at a fixed rate: weigh q by time, not by (non-uniform) node
    t_uniform = np.arange(plan.time_s[0], plan.time_s[-1], 0.1)
    ax_q.hist(np.interp(t_uniform, plan.time_s, plan.qc_pa), bins=24, color="tab:green")
    ax_q.set_xlabel("target q_c, Pa")
    ax_q.set_ylabel("samples at 10 Hz")
    ax_q.set_title("distribution of impact pressure", y=1.0)
    if path is not None:
        save_figure(fig, path, **PNG_OPTIONS)
    return fig


def output_paths(plan_csv):
    """Where the companions of PLAN.csv go: card (txt, png), auto-throttle CSV, figure."""
    plan_csv = Path(plan_csv)
    stem = plan_csv.with_suffix("") if plan_csv.suffix.lower() == ".csv" else plan_csv
    return {"plan": plan_csv,
            "card_txt": Path(f"{stem}.card.txt"),
            "card_png": Path(f"{stem}.card.png"),
            "autothrottle": Path(f"{stem}.autothrottle.csv"),
            "figure": Path(f"{stem}.png")}


def check_output_paths(plan_csv, *, figures=True):
    """Refuse, before any work, a plan CSV path whose files could not be written.

    The plan CSV and its companions (`output_paths`) must not be folders, their folder must
    exist and be writable, and an existing file must be writable. The error names the
    parameter ``output`` (the command line's ``--output``).

    Returns
    -------
    dict
        `output_paths(plan_csv)` (without the PNGs when `figures` is false).
    """
    paths = output_paths(plan_csv)
    if not figures:
        del paths["card_png"], paths["figure"]
    if paths["plan"].is_dir():
        raise PitotcalError(f"output {plan_csv} is a folder: name the plan CSV, e.g. "
                            f"{paths['plan'] / 'plan.csv'}", param="output")
    folder = paths["plan"].parent
    if not folder.is_dir():
        raise PitotcalError(f"output {plan_csv}: folder {folder} does not exist",
                            param="output")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PitotcalError(f"output {plan_csv}: folder {folder} is not writable",
                            param="output")
    for path in paths.values():
        if path.is_dir():
            raise PitotcalError(f"output {plan_csv}: {path} is a folder, the file beside the "
                                f"plan cannot be written", param="output")
        if path.exists() and not os.access(path, os.W_OK):
            raise PitotcalError(f"output {plan_csv}: {path} is not writable", param="output")
    return paths


def _import_figure():
    """Load matplotlib's figure module (0.1-0.2 s of CPU beyond `import matplotlib`)."""
    import matplotlib.figure  # noqa: F401


def _draw_figures(plan, paths):
    """The card PNG in a forked child while the plan figure is drawn here."""
    side_by_side(lambda: write_pilot_card(plan, paths["card_png"]),
                 lambda: plot_plan(plan, paths["figure"]))


def start_figures(plan_csv):
    """Start, before the plan exists, the process that will draw its two PNGs.

    A forked child (`pitotcal.core.processes.EarlyChild`) imports matplotlib's figure module
    while this process plans, and draws the card and plan figure of the plan that
    `write_plan_outputs(plan, plan_csv, early=...)` sends it. Use it as a context manager
    around the planning: an error before the plan is written stops the child.

    Parameters
    ----------
    plan_csv : path-like
        The plan CSV the PNGs go beside (`output_paths`); the same as `write_plan_outputs`'.

    Returns
    -------
    pitotcal.core.processes.EarlyChild
    """
    paths = output_paths(plan_csv)
    return EarlyChild(_import_figure, lambda plan: _draw_figures(plan, paths))


def write_plan_outputs(plan, plan_csv, *, figures=True, early=None):
    """Write the plan CSV and its companions beside it; returns {kind: path}.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
    plan_csv : path-like
        The plan CSV (docs/interfaces.md §4); the others take its stem: ``.card.txt``, ``.card.png``,
        ``.autothrottle.csv`` and ``.png``.
    figures : bool
        Write the PNGs (matplotlib is the slow part).
    early : pitotcal.core.processes.EarlyChild, optional
        `start_figures(plan_csv)`, started before planning: it draws the PNGs (sent the plan
        here unless the caller already did) while the text files are written here. Without
        it, or if it could not draw them, they are drawn here.
    """
    paths = output_paths(plan_csv)
    sent = figures and early is not None and (early.sent or early.send(plan))
    write_plan(plan, paths["plan"])
    write_pilot_card(plan, None, paths["card_txt"])
    write_autothrottle_csv(plan, paths["autothrottle"])
    if not figures:
        del paths["card_png"], paths["figure"]
    elif not (sent and early.join()):
        # the two PNGs are most of a default `pitotcal plan` (0.15-0.2 s each): drawn at once;
        # matplotlib's figure module is loaded before the fork so that the child inherits it
        # instead of importing it again (on a busy machine the two imports compete for a core)
        _import_figure()
        _draw_figures(plan, paths)
    return paths
