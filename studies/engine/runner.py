"""Monte Carlo engine: run many seeded cases of a task on Dask (or in process) into table rows.

A *case* is a dict of keyword arguments for a task function ``task(seed=..., **case)`` that
returns a dict (one table row) or a list of dicts (several rows of one run). Run ``i`` gets the
seed ``base_seed + case.get("seed_offset", i)`` and every row carries ``run_index`` and ``seed``,
so any run can be repeated alone: ``run_one(task, cases, i, base_seed)`` or
``pitotcal study NAME --run-index i --seed S``. Studies that want common random numbers across
the levels of a sweep give their cases the same ``seed_offset``.

A run that raises becomes a row with its error text (``error`` column) instead of stopping the
study; Ctrl-C stops it with `RunsInterrupted`, which carries the rows of the runs that finished.
Where the runs go:

- ``workers=0``, or fewer than ``SERIAL_BELOW`` runs with no scheduler given: in this process
  (a LocalCluster costs seconds to start, more than a few runs of ~0.2 s);
- ``scheduler="tcp://host:8786"``: an existing Dask scheduler (``Client(address)``); its
  workers must have pitotcal installed;
- otherwise a ``LocalCluster`` of ``workers`` processes (default: all cores), one thread each,
  no dashboard, quiet logs.
"""

import contextlib
import csv
import logging
import math
import os
import time
import traceback
from pathlib import Path

from pitotcal.core.checks import integer
from pitotcal.core.errors import PitotcalError
from pitotcal.io.atomic import atomic_open

__all__ = [
    "SERIAL_BELOW",
    "RunsInterrupted",
    "case_seed",
    "count_errors",
    "echo_task",
    "output_folder",
    "read_table",
    "run_cases",
    "run_one",
    "write_table",
]

log = logging.getLogger(__name__)

# Seconds to reach an existing scheduler (--scheduler) before giving up.
CONNECT_TIMEOUT_S = 15.0

# Below this many runs the serial path wins: LocalCluster start ~3-5 s vs ~0.2 s per run.
SERIAL_BELOW = 16


class RunsInterrupted(KeyboardInterrupt):
    """Ctrl-C during `run_cases`: `rows` of the `n_done` runs that finished, of `n_runs`."""

    def __init__(self, rows, n_done, n_runs):
        super().__init__(f"interrupted after {n_done} of {n_runs} runs")
        self.rows, self.n_done, self.n_runs = rows, n_done, n_runs


def case_seed(base_seed, run_index, case):
    """Seed of run `run_index`: base_seed + the case's `seed_offset` (default: the run index)."""
    return int(base_seed) + int(case.get("seed_offset", run_index))


def count_errors(rows):
    """{error text with its numbers masked: count}: one entry per cause of failed runs (the
    table keeps each run's full text)."""
    import re

    errors = {}
    for row in rows:
        if row.get("error"):
            key = re.sub(r"\d+(\.\d+)?", "#", row["error"])
            errors[key] = errors.get(key, 0) + 1
    return errors


def run_cases(task, cases, *, base_seed=0, workers=None, scheduler=None, progress=None):
    """Run `task(seed=..., **case)` for every case; return all rows in run order.

    Parameters
    ----------
    task : callable
        A module-level function (picklable) returning a dict or a list of dicts.
    cases : sequence of dict
        Keyword arguments of each run; `seed_offset` (optional) is consumed for the seed.
    base_seed : int
        Seed of run 0; run i uses ``case_seed(base_seed, i, case)``.
    workers : int or None
        0: in process. None: all cores (``os.cpu_count()``). n > 0: n worker processes.
    scheduler : str or None
        Address of an existing Dask scheduler; overrides `workers`.
    progress : callable or None
        ``progress(done, total)`` after each finished run (the CLI draws a bar on stderr);
        by default progress is logged at INFO every 10%.

    Returns
    -------
    list of dict
        Rows with ``run_index``, ``seed``, ``error`` ("" on success), ``elapsed_s`` and the
        task's columns.

    Raises
    ------
    RunsInterrupted
        On Ctrl-C, with the rows of the runs that had finished (in run order).
    """
    cases = [dict(c) for c in cases]
    if workers is not None:
        workers = integer("workers", workers, 0)
    if not callable(task):
        raise PitotcalError("task must be callable")
    progress = progress or _log_progress
    total = len(cases)
    jobs = [(task, case, i, case_seed(base_seed, i, case)) for i, case in enumerate(cases)]
    if total == 0:
        return []
    if scheduler is None and (workers == 0 or total < SERIAL_BELOW):
        results = []
        try:
            for done, job in enumerate(jobs, 1):
                results.append(_call(*job))
                progress(done, total)
        except KeyboardInterrupt:
            raise RunsInterrupted(_flatten(results), len(results), total) from None
        return _flatten(results)
    return _flatten(_run_dask(jobs, workers, scheduler, progress))


def run_one(task, cases, run_index, base_seed=0):
    """Repeat run `run_index` alone, in process; the same rows it gave inside the study."""
    cases = list(cases)
    run_index = integer("run_index", run_index, 0, len(cases) - 1)
    case = dict(cases[run_index])
    return _flatten([_call(task, case, run_index, case_seed(base_seed, run_index, case))])


def _call(task, case, run_index, seed):
    """One run; an exception becomes a row carrying its text (a failed run is not fatal)."""
    kwargs = {k: v for k, v in case.items() if k != "seed_offset"}
    head = {"run_index": run_index, "seed": seed}
    start = time.perf_counter()
    try:
        out = task(seed=seed, **kwargs)
        error = ""
    except Exception as exc:        # noqa: BLE001 - any failure is recorded, not raised
        log.debug("run %d failed:\n%s", run_index, traceback.format_exc())
        out, error = {}, f"{type(exc).__name__}: {exc}".splitlines()[0]
    elapsed = time.perf_counter() - start
    rows = out if isinstance(out, list) else [out]
    if not rows:
        rows = [{}]
    return [{**head, **_scalar_case(kwargs), **row, "error": row.get("error", error),
             "elapsed_s": round(elapsed, 4)} for row in rows]


def _scalar_case(case):
    """The case's scalar settings as columns (tuples/dicts stay out of the table)."""
    return {k: v for k, v in case.items() if isinstance(v, (int, float, str, bool)) or v is None}


def _flatten(results):
    return [row for rows in results for row in rows]


def _log_progress(done, total):
    step = max(1, total // 10)
    if done == total or done % step == 0:
        log.info("%d/%d runs done", done, total)


def _run_dask(jobs, workers, scheduler, progress):
    """Submit every job to a Dask cluster; collect rows as they finish, keep run order."""
    from distributed import Client, LocalCluster, as_completed

    # The scheduler lives in this process: its INFO/WARNING chatter at shutdown ("Lost all
    # workers", "Nanny closed") is not news to a user of a finished study.
    quiet = logging.getLogger("distributed")
    level = quiet.level
    quiet.setLevel(logging.ERROR)
    try:
        return _submit_all(jobs, workers, scheduler, progress, Client, LocalCluster,
                           as_completed)
    finally:
        quiet.setLevel(level)


def _connect(Client, scheduler):
    """A Client of the Dask scheduler at `scheduler`, or one line saying why not.

    The connection runs in a daemon thread with a deadline: a port that answers with something
    other than Dask's protocol can make distributed wait forever (or try to allocate what a
    garbage length header asks for), whatever its own timeout says.
    """
    import threading

    outcome, timeout_s = {}, CONNECT_TIMEOUT_S

    def connect():
        try:
            outcome["client"] = Client(scheduler, timeout=f"{timeout_s}s")
        except BaseException as exc:        # noqa: BLE001 - reported below, in one line
            outcome["error"] = exc

    thread = threading.Thread(target=connect, name="dask-connect", daemon=True)
    thread.start()
    thread.join(timeout_s + 5.0)
    if "client" in outcome:
        return outcome["client"]
    exc = outcome.get("error")
    if thread.is_alive():
        text = f"no Dask answer within {timeout_s:g} s"
    elif isinstance(exc, KeyboardInterrupt):
        raise exc
    else:
        text = (str(exc).splitlines() or [""])[0] or type(exc).__name__
    # a typo'd address is bad input: one line, exit 2 (not a distributed traceback)
    raise PitotcalError(f"`scheduler` {scheduler!r}: cannot connect to a Dask scheduler "
                        f"({text}); expected e.g. tcp://HOST:8786 with `dask scheduler` "
                        "running there")


def _submit_all(jobs, workers, scheduler, progress, Client, LocalCluster, as_completed):
    cluster = None
    if scheduler is not None:
        client = _connect(Client, scheduler)
    else:
        n = workers or os.cpu_count() or 1
        # processes, one thread each: CasADi/IPOPT and numpy work best unshared; no dashboard.
        with _workers_ignore_ctrl_c():
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.ERROR)
        client = Client(cluster)
    try:
        futures = {}
        for job in jobs:
            # pure=False: two runs with equal arguments are still two runs.
            futures[client.submit(_call, *job, pure=False)] = job
        results = {}
        try:
            for done, future in enumerate(as_completed(futures), 1):
                _, case, index, seed = futures[future]
                results[index] = _collect(future, case, index, seed)
                progress(done, len(jobs))
        except KeyboardInterrupt:
            finished = _flatten(results[i] for i in sorted(results))
            raise RunsInterrupted(finished, len(results), len(jobs)) from None
        return [results[i] for i in sorted(results)]
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


@contextlib.contextmanager
def _workers_ignore_ctrl_c():
    """Start worker processes with Ctrl-C ignored: a terminal sends it to the whole process
    group, and each worker would print its own traceback; this process stops them instead."""
    import signal
    try:
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:               # not the main thread: leave the signals alone
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _collect(future, case, index, seed):
    """The rows of one finished future; a run lost on the cluster becomes a row with its error."""
    try:
        return future.result()
    except Exception as exc:  # noqa: BLE001 - e.g. a worker died (KilledWorker)
        return [{"run_index": index, "seed": seed, **_scalar_case(case),
                 "error": f"{type(exc).__name__}: {exc}".splitlines()[0],
                 "elapsed_s": float("nan")}]


def output_folder(out_dir, contents):
    """`out_dir` as an existing folder (created when missing). When it, or a folder above it,
    is a file: a one-line error saying the folder receives `contents`, before any work."""
    out = Path(out_dir)
    for place in (out, *out.parents):
        if place.exists():
            if not place.is_dir():
                raise PitotcalError(f"out_dir must be a folder (it receives {contents}); "
                                    f"{place} is a file", param="out_dir")
            break
    out.mkdir(parents=True, exist_ok=True)
    return out


def write_table(rows, path, comments=(), columns=()):
    """Write rows as a CSV: `columns` first (those present), then the rest of the union of the
    rows' columns in first-seen order; missing cells empty.

    Each of `comments` becomes a ``# ...`` line before the header (e.g. ``partial: 3 of 10
    runs (interrupted)``). (Parquet would need pyarrow, which pitotcal does not depend on.)
    """
    present = {k for row in rows for k in row}
    columns = [c for c in columns if c in present]
    for row in rows:
        columns.extend(k for k in row if k not in columns)
    with atomic_open(path, "w", newline="") as fh:
        fh.writelines(f"# {line}\n" for line in comments)
        writer = csv.DictWriter(fh, fieldnames=columns, restval="")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: _cell(v) for k, v in row.items()})
    return path


def read_table(path):
    """Read a table written by `write_table`: numbers as float, empty cells as NaN (the
    ``error`` column stays text: "" for a run that succeeded); ``#`` comment lines skipped."""
    with open(path, newline="") as fh:
        lines = (line for line in fh if not line.startswith("#"))
        return [{k: (v if k == "error" else _parse(v)) for k, v in row.items()}
                for row in csv.DictReader(lines)]


def _cell(value):
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return value


def _parse(text):
    if text == "":
        return float("nan")
    try:
        return float(text)
    except ValueError:
        return text


def echo_task(seed, value=0.0, fail=False, sleep_s=0.0, stop=False):
    """A trivial task for testing the engine: echoes its seed; raises when `fail`; acts as if
    the user pressed Ctrl-C when `stop`."""
    if sleep_s:
        time.sleep(sleep_s)
    if stop:
        raise KeyboardInterrupt
    if fail:
        raise RuntimeError(f"run with seed {seed} failed on purpose")
    return {"value": value, "twice_seed": 2 * seed}
