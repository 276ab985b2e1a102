"""pitotcal.maneuvers: planning a calibration maneuver and flying it in simulation.

Planning: `profiles` (the q(t) schedules), `ocp` (the lateral-path optimal-control problem),
`request` (`PlanRequest`, what to plan), `planner` (`plan_maneuver(PlanRequest(...))`),
`outputs` (plan CSV companions: pilot card, setpoints, figure),
`missions` (the plan as an autopilot mission: loiter circles and speed changes), `design`
(information-optimal speed schedules, `plan_maneuver(design="optimal")`), `card` (pilot-card
parts and picture).
Flying: `simulator` (`simulate(plan, SimulationOptions(...))`; `options.engine` picks pitotcal's
point-mass model or JSBSim's), `autopilot` (guidance, auto-throttle, the stepping loop),
`autothrottle` (the PI speed loop and its check), `turbulence`, `sensors`, `truth`;
`everyday` (seeded 15-minute survey/loiter flights with speed changes in a constant or
drifting wind, and the default plan flown).

The names below load their module on first use, so that `pitotcal plan` does not import the
simulator and `pitotcal simulate` does not import the planner.
"""

from pitotcal.core.lazy import lazy_exports

_EXPORTS = {
    "PROFILES": ".plan.profiles",
    "AutothrottleCheck": ".plan.autothrottle",
    "SpeedLoop": ".plan.autothrottle",
    "autothrottle_report": ".plan.autothrottle",
    "check_autothrottle": ".plan.autothrottle",
    "tune_autothrottle": ".plan.autothrottle",
    "plot_plan": ".plan.outputs",
    "write_plan_outputs": ".plan.outputs",
    "ManeuverProblem": ".plan.ocp",
    "Mission": ".plan.missions",
    "build_mission": ".plan.missions",
    "export_mission": ".plan.missions",
    "loiter_plan": ".plan.missions",
    "plan_maneuver": ".plan.planner",
    "PlanRequest": ".plan.request",
    "DesignOptions": ".plan.design_request",
    "predict_plan_band_kt": ".plan.design",
    "simulate": ".fly.simulator",
    "simulate_jsbsim": ".fly.simulator",
    "default_plan_flight": ".fly.everyday",
    "everyday_flight": ".fly.everyday",
    "everyday_plan": ".fly.everyday",
    "SimulationOptions": ".fly.options",
    "AirSensors": ".fly.options",
    "Fault": ".fly.faults",
    "apply_fault": ".fly.faults",
    "parse_fault": ".fly.faults",
    "Tracking": ".fly.truth",
    "Truth": ".fly.truth",
    "tracking_warnings": ".fly.truth",
    "truth_path_for": ".fly.truth",
    "write_truth_json": ".fly.truth",
    "DrydenScales": ".turbulence",
    "dryden_gusts": ".turbulence",
    "dryden_scales": ".turbulence",
}

__all__ = sorted(_EXPORTS)  # noqa: PLE0605


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
