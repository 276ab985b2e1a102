"""Maneuvers: the shared point-mass dynamics, the planner, the simulator."""

# Simulator, turbulence and auto-throttle (issue 3, items 4-5).
from maneuvers.autothrottle import (AutothrottleCheck, SpeedLoop, check_autothrottle,
                                    tune_autothrottle)
from maneuvers.simulator import simulate, truth_path_for, write_truth_json
from maneuvers.turbulence import DrydenScales, dryden_gusts, dryden_scales

__all__ = list(globals().get("__all__", [])) + [
    "simulate", "write_truth_json", "truth_path_for", "check_autothrottle", "tune_autothrottle",
    "SpeedLoop", "AutothrottleCheck", "dryden_scales", "dryden_gusts", "DrydenScales",
]
