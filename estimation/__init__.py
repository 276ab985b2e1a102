"""pitotcal.estimation: identify the pressure error and the wind from a flight.

The public names; everything else is an implementation detail of its module.
"""

from .identification.identify import identify
from .identification.multi_sensor import identify_sensors
from .identification.oe import OutputErrorProblem
from .identification.result import IdentificationResult

__all__ = ["IdentificationResult", "OutputErrorProblem", "identify", "identify_sensors"]
