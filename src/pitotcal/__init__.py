"""pitotcal: in-flight GPS calibration of pitot-static systems.

One namespace, python-control style::

    import pitotcal
    plan = pitotcal.plan_maneuver()                 # the paper's T-2 maneuver
    flight, truth = pitotcal.simulate(plan, seed=1)
    result = pitotcal.identify(flight)              # or pitotcal.read_flight("flight.csv")

Layers, each importing only those before it: `pitotcal.core` (units, errors, checks, models,
`Flight`, `Plan`, dynamics, scenario defaults) → `pitotcal.io` (flight CSV, autopilot logs,
plan CSV) → `pitotcal.maneuvers` (planning, simulation) and `pitotcal.estimation`
(identification, calibration summary) → `pitotcal.studies` → the command line
(`pitotcal.cli`). The names below are loaded on first use, so `import pitotcal` stays cheap.
"""

from pitotcal.core.lazy import lazy_exports

__version__ = "0.1.0"

_EXPORTS = {
    "identify": "pitotcal.estimation",
    "OutputErrorProblem": "pitotcal.estimation",
    "IdentificationResult": "pitotcal.estimation",
    "read_flight": "pitotcal.io",
    "write_flight_csv": "pitotcal.io",
    "read_plan": "pitotcal.io",
    "write_plan": "pitotcal.io",
    "plan_maneuver": "pitotcal.maneuvers",
    "PlanRequest": "pitotcal.maneuvers",
    "simulate": "pitotcal.maneuvers",
    "SimulationOptions": "pitotcal.maneuvers",
    "Flight": "pitotcal.core.flight",
    "Plan": "pitotcal.core.plan",
    "MODELS": "pitotcal.core.models",
    "get_model": "pitotcal.core.models",
    "PitotcalError": "pitotcal.core.errors",
    "FlightDataError": "pitotcal.core.errors",
    "ObservabilityError": "pitotcal.core.errors",
    "PlanInfeasibleError": "pitotcal.core.errors",
}

__all__ = list(_EXPORTS) + ["__version__"]  # noqa: PLE0604


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
