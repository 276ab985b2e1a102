"""pitotcal estimation: read a calibration flight, identify the pressure error and the wind.

The public names; everything else is an implementation detail of its module.
"""

from .errors import FlightDataError, ObservabilityError, PitotcalError
from .flight import Flight, read_flight, write_flight_csv
from .identification import identify
from .models import MODELS, get_model
from .oe import OutputErrorProblem
from .result import IdentificationResult

__all__ = [
    "identify", "OutputErrorProblem", "IdentificationResult",
    "Flight", "read_flight", "write_flight_csv",
    "MODELS", "get_model",
    "PitotcalError", "FlightDataError", "ObservabilityError",
]
