"""The self-survey: static position error from GPS height by the hydrostatic equation."""

from .self_survey import SelfSurveyResult, self_survey

__all__ = ["SelfSurveyResult", "self_survey"]
