"""The self-survey: static position error from GPS height by the hydrostatic equation."""

from .self_survey import SelfSurveyResult, hydrostatic_pressure_pa, self_survey

__all__ = ["SelfSurveyResult", "hydrostatic_pressure_pa", "self_survey"]
