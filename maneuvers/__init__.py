"""pitotcal.maneuvers: planning a calibration maneuver and flying it in simulation.

Planning: `profiles` (the q(t) schedules), `ocp` (the lateral-path optimal-control problem),
`planner` (`plan_maneuver`), `outputs` (plan CSV companions: pilot card, setpoints, figure),
`missions` (the plan as an autopilot mission: loiter circles and speed changes), `design`
(information-optimal speed schedules, `plan_maneuver(design="optimal")`), `card` (pilot-card
parts and picture).
Flying: `simulator` (`simulate`), `autopilot` (guidance, auto-throttle, the stepping loop),
`autothrottle` (the PI speed loop and its check), `turbulence`, `sensors`, `truth`.

The names below load their module on first use, so that `pitotcal plan` does not import the
simulator and `pitotcal simulate` does not import the planner.
"""

from pitotcal.core.lazy import lazy_exports

_EXPORTS = {
    "PROFILES": ".profiles",
    "AutothrottleCheck": ".autothrottle",
    "SpeedLoop": ".autothrottle",
    "autothrottle_report": ".autothrottle",
    "check_autothrottle": ".autothrottle",
    "tune_autothrottle": ".autothrottle",
    "plot_plan": ".outputs",
    "write_plan_outputs": ".outputs",
    "ManeuverProblem": ".ocp",
    "Mission": ".missions",
    "build_mission": ".missions",
    "export_mission": ".missions",
    "loiter_plan": ".missions",
    "plan_maneuver": ".planner",
    "DesignOptions": ".design_request",
    "predict_plan_band_kt": ".design",
    "simulate": ".simulator",
    "Tracking": ".truth",
    "Truth": ".truth",
    "tracking_warnings": ".truth",
    "truth_path_for": ".truth",
    "write_truth_json": ".truth",
    "DrydenScales": ".turbulence",
    "dryden_gusts": ".turbulence",
    "dryden_scales": ".turbulence",
}

__all__ = sorted(_EXPORTS)  # noqa: PLE0605


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
