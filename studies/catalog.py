"""The named studies, one table, and `run_study`, which runs one and writes its table, summary
and figures.

`run_study("coverage", runs=200, out_dir="out")` writes ``out/coverage.csv`` (one row per run),
``out/coverage.json`` (the summary, with a one-line ``headline``) and ``out/coverage*.png``
(docs/interfaces.md), and returns the summary. Ctrl-C keeps the runs that finished: the CSV gets
them under a ``# partial: N of M runs (interrupted)`` line, the JSON says ``"partial": true``,
and `StudyInterrupted` is raised. `rerun("coverage", 17, seed=0)` repeats run 17 alone.
"""

import logging
import time

from pitotcal.core.checks import choice, integer
from pitotcal.core.errors import PitotcalError
from pitotcal.io.jsonfile import write_json

from .accuracy.budget import STUDY as BUDGET
from .peers.study import STUDY as PEERS
from .accuracy.coverage import STUDY as COVERAGE
from .design.study import STUDY as DESIGN
from .accuracy.leak import STUDY as LEAK
from .legs.flight_study import STUDY as LEGS_FLIGHT
from .legs.study import STUDY as LEGS
from .accuracy.maneuvers import STUDY as MANEUVERS
from .monitor.study import STUDY as MONITOR
from .accuracy.noise import STUDY as NOISE
from .real_alfa.study import STUDY as REAL_ALFA
from .jets.study import STUDY as JETS
from .engine.runner import RunsInterrupted, count_errors, output_folder, write_table
from .accuracy.sample_size import STUDY as SAMPLE_SIZE
from .accuracy.sensitivity import STUDY as SENSITIVITY
from .accuracy.tails import STUDY as COVERAGE_TAILS
from .engine.study import StudySettings
from .accuracy.wind import STUDY as WIND

__all__ = ["STUDIES", "StudyInterrupted", "get_study", "rerun", "run_study", "study_names"]

log = logging.getLogger(__name__)

# Every study, by the name it has on the command line (each a `studies.engine.study.Study`).
STUDIES = {s.name: s for s in (SAMPLE_SIZE, MANEUVERS, SENSITIVITY, COVERAGE, WIND, REAL_ALFA,
                               PEERS, LEGS, DESIGN, MONITOR, BUDGET,
                               LEGS_FLIGHT, NOISE,
                               LEAK, COVERAGE_TAILS, JETS)}


class StudyInterrupted(KeyboardInterrupt):
    """Ctrl-C during a study, after its finished runs were written: `summary` (partial)."""

    def __init__(self, summary):
        super().__init__(summary["headline"])
        self.summary = summary


def study_names():
    """The names of every study, in the table's order."""
    return list(STUDIES)


def get_study(name):
    """The study called `name`; PitotcalError naming the choices otherwise."""
    if name not in STUDIES:
        raise PitotcalError(f"study {name!r} is not one of {', '.join(STUDIES)}", param="name")
    return STUDIES[name]


def run_study(name, *, runs=None, out_dir=".", seed=0, workers=None, scheduler=None,
              quick=False, progress=None, data_dir=None, engine="own"):
    """Run study `name` and write DIR/NAME.csv, DIR/NAME.json and DIR/NAME*.png.

    Parameters
    ----------
    name : str
        One of `study_names()`.
    runs : int or None
        Monte Carlo replicates per case (for `coverage`: the number of flights); default: the
        study's own (smaller when `quick`).
    out_dir : str or Path
        A folder, created when missing.
    seed : int
        Base seed; run i of the table used ``seed + i`` (or ``seed + seed_offset``; see the
        ``seed`` column).
    workers, scheduler, progress :
        Where runs go (`studies.engine.runner.run_cases`).
    quick : bool
        A small grid for tests and smoke runs.
    data_dir : str or Path, optional
        `real-alfa`: the folder of the ALFA CSVs (`pitotcal.io.alfa.find_alfa_data`).
    engine : {"own", "jsbsim"}
        The flight model of a simulating study that offers more than its own (`coverage`).

    Returns
    -------
    dict
        The summary (also written as NAME.json): ``study``, ``headline`` (the result in one
        line), ``n_runs``, ``n_rows``, ``n_failed``, ``errors`` (message with numbers masked as
        # -> count), ``elapsed_s``, ``partial``, ``files`` and the study's own keys.

    Raises
    ------
    StudyInterrupted
        Ctrl-C; the finished runs are in NAME.csv (marked partial) and NAME.json.
    """
    study = get_study(name)
    settings = StudySettings(runs=_check_runs(runs), seed=integer("seed", seed, 0),
                             quick=bool(quick),
                             workers=workers, scheduler=scheduler, progress=progress,
                             data_dir=None if data_dir is None else str(data_dir),
                             engine=_check_engine(study, engine))
    out = output_folder(out_dir, f"{name}.csv, {name}.json and {name}*.png")
    start = time.perf_counter()
    try:
        collected = study.collect(settings)
    except RunsInterrupted as stop:
        summary = _write_partial(study, settings, stop, out, time.perf_counter() - start)
        raise StudyInterrupted(summary) from None
    elapsed = time.perf_counter() - start
    csv_path = write_table(collected.rows, out / f"{name}.csv", columns=collected.columns)
    summary = _common_summary(study, settings, collected.rows, collected.n_runs, elapsed)
    summary.update(collected.info)
    own, files = study.report(collected, out)
    summary.update(own)
    summary["headline"] = study.headline(summary)
    json_path = out / f"{name}.json"
    summary["files"] = [str(csv_path), str(json_path), *map(str, files)]
    summary["figures"] = [str(f) for f in files if str(f).endswith(".png")]
    write_json(json_path, summary)
    log.info("%s: %d runs in %.1f s, %d failed", name, collected.n_runs, elapsed,
             summary["n_failed"])
    return summary


def rerun(name, run_index, *, runs=None, seed=0, quick=False, data_dir=None, engine="own"):
    """Repeat run `run_index` of study `name` alone, in process: its table rows.

    Give the same `runs`, `seed`, `quick` and `engine` as the study, so the cases line up.
    """
    study = get_study(name)
    settings = StudySettings(runs=_check_runs(runs), seed=integer("seed", seed, 0),
                             quick=bool(quick),
                             data_dir=None if data_dir is None else str(data_dir),
                             engine=_check_engine(study, engine))
    return study.repeat(settings, run_index)


# The most runs one study takes: its cases, futures and rows are held in memory (~10 kB a
# run), and 1e5 runs of ~0.3 s already take over 4 hours on 2 cores; split larger ones by --seed.
MAX_RUNS = 100_000


def _check_engine(study, engine):
    """`engine` if the study flies it (every study flies the own model)."""
    engine = choice("engine", engine, ("own", "jsbsim"))
    offered = getattr(study, "engines", ("own",))
    if engine not in offered:
        raise PitotcalError(f"engine {engine}: study {study.name} flies only "
                            f"{', '.join(offered)}", param="engine")
    return engine


def _check_runs(runs):
    if runs is None:
        return None
    runs = integer("runs", runs, 1)
    if runs > MAX_RUNS:
        raise PitotcalError(f"runs {runs} is more than one study takes ({MAX_RUNS}, held in "
                            "memory): run several studies, each with its own `seed`", param="runs")
    return runs


def _common_summary(study, settings, rows, n_runs, elapsed_s):
    """The summary keys every study has."""
    return {"study": study.name, "description": study.description, "headline": "",
            "n_runs": n_runs, "n_rows": len(rows),
            "n_failed": sum(1 for r in rows if r.get("error")),
            "n_not_converged": sum(1 for r in rows if r.get("success") is False),
            "errors": count_errors(rows), "seed": settings.seed, "quick": settings.quick,
            "workers": "scheduler" if settings.scheduler else settings.workers,
            "engine": settings.engine, "elapsed_s": round(elapsed_s, 2), "partial": False}


def _write_partial(study, settings, stop, out, elapsed_s):
    """NAME.csv with the finished runs under a ``# partial`` line, and NAME.json saying so."""
    note = f"partial: {stop.n_done} of {stop.n_runs} runs (interrupted)"
    csv_path = write_table(stop.rows, out / f"{study.name}.csv", comments=[note])
    json_path = out / f"{study.name}.json"
    summary = _common_summary(study, settings, stop.rows, stop.n_runs, elapsed_s)
    summary.update(partial=True, n_done=stop.n_done,
                   headline=f"interrupted: {stop.n_done} of {stop.n_runs} runs finished, kept "
                            f"in {csv_path.name} (marked partial)",
                   files=[str(csv_path), str(json_path)])
    write_json(json_path, summary)
    return summary
