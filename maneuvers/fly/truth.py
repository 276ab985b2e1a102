"""`Truth`: what the simulator really flew, for scoring an identification against it, and its
JSON file (FLIGHT.truth.json, docs/interfaces.md)."""

from dataclasses import asdict, dataclass
from pathlib import Path

from pitotcal.core.scenario import CAS_TOLERANCE_KT
from pitotcal.io.jsonfile import write_json

__all__ = ["Tracking", "Truth", "tracking_warnings", "truth_path_for", "write_truth_json"]

# The planner keeps its 1 m radius margin at the nodes only: a flown track may ride the boundary.
_RADIUS_SLACK_M = 1.0


@dataclass(frozen=True)
class Tracking:
    """How closely the simulated aircraft followed the plan (maxima over the record).

    The CAS errors compare the calibrated airspeed flown, by the standard law at the altitude
    flown (`pitotcal.core.speeds.cas_from_tas_mps`), with the plan's `cas_mps`: the card's KCAS.
    """

    max_cas_error_kt: float
    rms_cas_error_kt: float
    max_path_error_m: float       # distance to the nearest point of the plan's path
    max_radius_m: float
    max_bank_deg: float
    max_alt_error_m: float


@dataclass(frozen=True)
class Truth:
    """The true calibration and wind of a simulated flight.

    Attributes
    ----------
    model : str
        True pressure-error structure.
    k : tuple of float
        Its true coefficients.
    parameters : dict
        {k1.., "wind_speed_mps", "wind_from_deg"}: the wind is the time-average of the wind
        flown through, turbulence included (what an identification of a constant wind finds).
    wind_n_mps, wind_e_mps : float
        That average as the air-mass velocity (the way it blows TO).
    wind_mean_process : dict
        {"speed_mps", "from_deg", "drift_mps2"}: the mean wind asked for and its drift.
    seed : int
    options : dict
        Every simulation option.
    tracking : Tracking
    speed_loop : dict
        The auto-throttle's gains and plant.
    plan : dict
        The plan's settings.
    history : dict or None
        The true time histories (numpy arrays) with ``keep_history=True``; never written.
    air_data : str
        How the true impact pressure followed from the true airspeed: "incompressible"
        (½ρV_t², the paper's eq. 2) or "compressible" (isentropic, pitotcal.core.airdata).
    """

    model: str
    k: tuple
    parameters: dict
    wind_n_mps: float
    wind_e_mps: float
    wind_mean_process: dict
    seed: int
    options: dict
    tracking: Tracking
    speed_loop: dict
    plan: dict
    history: dict | None = None
    air_data: str = "incompressible"

    def to_dict(self):
        """The JSON content: every field but `history`."""
        out = asdict(self)
        out.pop("history")
        out["k"] = list(self.k)
        return out


def tracking_warnings(truth):
    """What a simulated flight did outside the paper's tolerances or the plan's test area.

    Parameters
    ----------
    truth : Truth

    Returns
    -------
    list of str
        One sentence per breach (empty when none): the airspeed left the ±5 KCAS band
        (`pitotcal.core.scenario.CAS_TOLERANCE_KT`), or the track left the plan's `radius_m`.
    """
    tr, out = truth.tracking, []
    if tr.max_cas_error_kt > CAS_TOLERANCE_KT:
        out.append(f"the simulated auto-throttle left the ±{CAS_TOLERANCE_KT:g} KCAS band (max "
                   f"{tr.max_cas_error_kt:.1f} kt): the paper's criterion is not met in this "
                   f"turbulence")
    radius = truth.plan.get("radius_m")
    if isinstance(radius, (int, float)) and tr.max_radius_m > radius + _RADIUS_SLACK_M:
        out.append(f"the simulated track left the {radius:g} m test area (max "
                   f"{tr.max_radius_m:.0f} m)")
    return out


def truth_path_for(flight_path):
    """FLIGHT.truth.json beside FLIGHT.csv (the suffix replaced)."""
    p = Path(flight_path)
    return p.with_name(p.stem + ".truth.json") if p.suffix else p.with_name(p.name + ".truth.json")


def write_truth_json(truth, path):
    """Write a `Truth` as JSON; returns the path written.

    `path` ending in `.json` is used as is; any other (e.g. the flight CSV's path) is turned
    into FLIGHT.truth.json beside it. The time histories are left out.
    """
    p = Path(path)
    if p.suffix != ".json":
        p = truth_path_for(p)
    write_json(p, truth.to_dict())
    return p
