"""Autopilot mission files: the QGC WPL 110 text format (ArduPilot, Mission Planner) and the
QGroundControl ``.plan`` JSON (PX4), written from a list of MAVLink mission items.

Formats: https://mavlink.io/en/file_formats/ (plain text, tab separated, first line
``QGC WPL 110``, item 0 the home position) and
https://docs.qgroundcontrol.com/master/en/qgc-dev-guide/file_formats/plan.html (home in
``plannedHomePosition``, the items as ``SimpleItem`` objects).
"""

import json
from dataclasses import dataclass

from .atomic import atomic_open

__all__ = ["FRAME_GLOBAL", "FRAME_GLOBAL_RELATIVE_ALT", "FRAME_MISSION", "MAV_CMD",
           "MissionItem", "write_qgc_plan", "write_qgc_wpl"]

# MAV_CMD ids (MAVLink common.xml)
MAV_CMD = {"NAV_WAYPOINT": 16, "NAV_LOITER_TURNS": 18, "NAV_LOITER_TIME": 19,
           "DO_CHANGE_SPEED": 178}
# MAV_FRAME: altitude above mean sea level, a command without a position, altitude above home
FRAME_GLOBAL, FRAME_MISSION, FRAME_GLOBAL_RELATIVE_ALT = 0, 2, 3
# QGroundControl's AltitudeMode for each frame: relative 1, AMSL 2
_QGC_ALT_MODE = {FRAME_GLOBAL: 2, FRAME_GLOBAL_RELATIVE_ALT: 1}


@dataclass(frozen=True)
class MissionItem:
    """One MAVLink mission item: `command` (MAV_CMD id), `frame` (MAV_FRAME), `params` (the
    four command parameters), position `lat_deg`, `lon_deg`, `alt_m` (zeros for a command
    without one, FRAME_MISSION)."""

    command: int
    frame: int
    params: tuple = (0.0, 0.0, 0.0, 0.0)
    lat_deg: float = 0.0
    lon_deg: float = 0.0
    alt_m: float = 0.0


def _num(x):
    return format(float(x), ".12g")


def write_qgc_wpl(path, home, items):
    """Write `home` (item 0) and `items` as a QGC WPL 110 file; returns the path.

    Each line: index, current (1 for home), frame, command, param1-4, latitude, longitude,
    altitude, autocontinue (1), tab separated.
    """
    lines = ["QGC WPL 110"]
    for seq, item in enumerate([home, *items]):
        fields = [seq, int(seq == 0), item.frame, item.command,
                  *(_num(p) for p in item.params),
                  _num(item.lat_deg), _num(item.lon_deg), _num(item.alt_m), 1]
        lines.append("\t".join(str(f) for f in fields))
    with atomic_open(path, "w", encoding="ascii", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    return path


def _plan_item(seq, item):
    positioned = item.frame != FRAME_MISSION
    params = [float(p) for p in item.params]
    params += [item.lat_deg, item.lon_deg, item.alt_m] if positioned else [0.0, 0.0, 0.0]
    out = {"autoContinue": True, "command": item.command, "doJumpId": seq, "frame": item.frame,
           "params": params, "type": "SimpleItem"}
    if positioned:
        out.update({"AMSLAltAboveTerrain": None, "Altitude": item.alt_m,
                    "AltitudeMode": _QGC_ALT_MODE[item.frame]})
    return out


def write_qgc_plan(path, home, items, *, cruise_speed_mps, firmware_type=12, vehicle_type=1):
    """Write a QGroundControl ``.plan`` file (version 1, mission version 2); returns the path.

    Parameters
    ----------
    home : MissionItem
        The planned home position (``plannedHomePosition``: latitude, longitude, altitude).
    items : list of MissionItem
        The mission, in order (``doJumpId`` from 1).
    cruise_speed_mps : float
        The mission's ``cruiseSpeed``.
    firmware_type, vehicle_type : int
        MAV_AUTOPILOT (12: PX4) and MAV_TYPE (1: fixed wing).
    """
    modes = {_QGC_ALT_MODE[i.frame] for i in items if i.frame != FRAME_MISSION}
    plan = {
        "fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
        "geoFence": {"circles": [], "polygons": [], "version": 2},
        "rallyPoints": {"points": [], "version": 2},
        "mission": {
            "version": 2, "firmwareType": firmware_type, "vehicleType": vehicle_type,
            "cruiseSpeed": float(cruise_speed_mps), "hoverSpeed": 5.0,
            "globalPlanAltitudeMode": modes.pop() if len(modes) == 1 else 1,
            "plannedHomePosition": [home.lat_deg, home.lon_deg, home.alt_m],
            "items": [_plan_item(seq, item) for seq, item in enumerate(items, start=1)],
        },
    }
    with atomic_open(path, "w", encoding="utf-8") as f:
        json.dump(plan, f, indent=2, allow_nan=False)     # strict JSON, as QGC parses it
        f.write("\n")
    return path
