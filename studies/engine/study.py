"""The one shape of a study: `Study`, what every named study provides, and `MonteCarloStudy`,
the Monte Carlo kind (all but `real-alfa`).

A study *collects* the rows of its table (running its runs; Ctrl-C stops it with
`studies.engine.runner.RunsInterrupted` carrying the finished ones), then *reports*: its summary and its
figures from those rows. `studies.catalog.run_study` does the rest for every study alike: the
output folder, the table, the common summary keys, the headline, the JSON.
"""

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

from .runner import run_cases, run_one

__all__ = ["Collected", "MonteCarloStudy", "Study", "StudySettings"]


@dataclass(frozen=True)
class StudySettings:
    """What the user asked of one study run.

    Attributes
    ----------
    runs : int or None
        Monte Carlo replicates per case (the study's default when None).
    seed : int
        Base seed; run i uses ``seed + i`` (or the case's ``seed_offset``).
    quick : bool
        A small grid for tests and smoke runs.
    workers, scheduler, progress :
        Where the runs go (`studies.engine.runner.run_cases`).
    data_dir : str or None
        Folder of real flight data (`real-alfa`; see `pitotcal.io.alfa.find_alfa_data`).
    engine : str
        The flight model of a simulating study: "own" (pitotcal's) or "jsbsim" (the study's
        `engines` says which it offers).
    """

    runs: int | None = None
    seed: int = 0
    quick: bool = False
    workers: int | None = None
    scheduler: str | None = None
    progress: Callable | None = None
    data_dir: str | None = None
    engine: str = "own"


@dataclass(frozen=True)
class Collected:
    """The runs of a study, done: the table `rows`, the number of runs, what the report needs
    (`details`, the study's own), common summary keys of the study's kind (`info`) and the
    table's leading `columns` (the others follow in first-seen order)."""

    rows: list
    n_runs: int
    details: Any = None
    info: dict = field(default_factory=dict)
    columns: tuple = ()


@runtime_checkable
class Study(Protocol):
    """What every named study provides (`studies.catalog.STUDIES`)."""

    name: str            # on the command line (`pitotcal study NAME`) and of the output files
    description: str

    def collect(self, settings: StudySettings) -> Collected:
        """Run the study's runs; raise `RunsInterrupted` with the finished rows on Ctrl-C."""

    def report(self, collected: Collected, out_dir) -> tuple[dict, list]:
        """The study's own summary keys and the files it wrote into `out_dir` (figures...)."""

    def headline(self, summary: dict) -> str:
        """The study's result in one line, from its summary."""

    def repeat(self, settings: StudySettings, run_index: int) -> list:
        """The rows of run `run_index` alone, in process (the same as inside the study)."""


@dataclass(frozen=True)
class MonteCarloStudy:
    """A study of seeded runs of one task over a grid of cases (on Dask or in process).

    Attributes
    ----------
    name, description : str
    task : callable
        Module-level ``task(seed=..., **case) -> dict or list of dict`` (it goes to workers).
    cases : callable
        ``cases(runs, quick) -> list of dict``; `runs` is the number of Monte Carlo replicates
        per case; `quick` shrinks the grid.
    summarize : callable
        ``summarize(rows, cases) -> dict`` (JSON-ready).
    plot : callable
        ``plot(rows, summary, out_dir) -> list of paths`` of the `NAME*.png` figures.
    headline : callable
        ``headline(summary) -> str``.
    default_runs, quick_runs : int
        Replicates per case when `runs` is not given.
    columns : tuple of str
        Leading columns of the table, in order (default: run index, seed, the case's settings,
        then the task's, as first seen).
    """

    name: str
    description: str
    task: Callable
    cases: Callable
    summarize: Callable
    plot: Callable
    headline: Callable
    default_runs: int = 10
    quick_runs: int = 1
    columns: tuple = ()
    engines: tuple = ("own",)

    def replicates(self, settings):
        """Replicates per case: the asked `runs`, else the study's default."""
        if settings.runs is not None:
            return int(settings.runs)
        return self.quick_runs if settings.quick else self.default_runs

    def with_engine(self, cases, settings):
        """The cases flown by `settings.engine`: each gets an ``engine`` key unless it is the
        own model (`studies.catalog` checks that the study offers it)."""
        if settings.engine == "own":
            return cases
        return [{**case, "engine": settings.engine} for case in cases]

    def collect(self, settings):
        n_rep = self.replicates(settings)
        cases = self.with_engine(self.cases(n_rep, settings.quick), settings)
        rows = run_cases(self.task, cases, base_seed=settings.seed, workers=settings.workers,
                         scheduler=settings.scheduler, progress=settings.progress)
        return Collected(rows, len(cases), details=cases, info={"replicates": n_rep},
                         columns=self.columns)

    def report(self, collected, out_dir):
        summary = self.summarize(collected.rows, collected.details)
        return summary, self.plot(collected.rows, summary, out_dir)

    def repeat(self, settings, run_index):
        cases = self.with_engine(self.cases(self.replicates(settings), settings.quick), settings)
        return run_one(self.task, cases, run_index, base_seed=settings.seed)
