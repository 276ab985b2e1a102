"""Studies: Monte Carlo over simulated flights (on Dask), the paper's figures reproduced, the
real ALFA flight, the autopilots' calibrators compared, and `pitotcal demo`. Every study is one
`studies.engine.study.Study` in the table `studies.catalog.STUDIES`, each in its own module
(`studies.accuracy.coverage`...).

Example
-------
>>> from pitotcal.studies import run_study
>>> summary = run_study("coverage", runs=4, out_dir="out", workers=0, quick=True)  # doctest: +SKIP
"""

from pitotcal.core.lazy import lazy_exports

from .names import STUDY_NAMES  # noqa: F401  (public, light: the CLI builds its parser from it)

# Loaded on first use, so that `pitotcal.studies.names` (the command line's parser) does not
# import every study.
_EXPORTS = {
    "STUDIES": ".catalog",
    "StudyInterrupted": ".catalog",
    "get_study": ".catalog",
    "rerun": ".catalog",
    "run_study": ".catalog",
    "study_names": ".catalog",
    "run_demo": ".demo",
    "read_table": ".engine.runner",
    "run_cases": ".engine.runner",
    "run_one": ".engine.runner",
    "write_table": ".engine.runner",
}

__all__ = sorted([*_EXPORTS, "STUDY_NAMES"])  # noqa: PLE0605


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
