"""`pitotcal study NAME [--runs N] [--out DIR] [--scheduler ADDRESS] [--data DIR]`
(docs/interfaces.md)."""

import sys

from pitotcal.studies.names import STUDY_NAMES


def add_parser(subparsers):
    names = STUDY_NAMES
    p = subparsers.add_parser(
        "study", help="run a study: Monte Carlo, real flight, peers (table, summary, figures)",
        description="Run one named study on a local Dask cluster (all cores), an existing "
                    "scheduler (--scheduler), or in process (--workers 0); write DIR/NAME.csv "
                    "(one row per run), DIR/NAME.json (summary) and DIR/NAME*.png, and print "
                    "its result. Ctrl-C keeps the finished runs (NAME.csv marked partial).")
    p.add_argument("name", choices=names, metavar="NAME", help=", ".join(names))
    p.add_argument("--runs", type=int, default=None,
                   help="Monte Carlo replicates per case (coverage: number of flights); "
                        "default: the study's own")
    p.add_argument("--out", dest="out_dir", default=".", metavar="DIR",
                   help="output folder (default: %(default)s)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="address of an existing Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: all cores; 0: run in this process)")
    p.add_argument("--seed", type=int, default=0,
                   help="base seed; run i uses the table's seed (default %(default)s)")
    p.add_argument("--quick", action="store_true", help="small grid (smoke runs, CI)")
    p.add_argument("--data", dest="data_dir", default=None, metavar="DIR",
                   help="real-alfa: folder of the ALFA flight CSVs (default: "
                        "${alfa_env}, else ./{alfa_dir}); jets: folder of the CLASS*.csv "
                        "test points (with WB.txt, the radiosonde, when present)")
    p.add_argument("--engine", default="own", choices=("own", "jsbsim"),
                   help="flight model of the simulated runs: own (default) or jsbsim "
                        "(JSBSim's {aircraft}; the coverage and noise studies)")
    p.add_argument("--run-index", type=int, default=None, metavar="I",
                   help="repeat run I alone (same --runs/--seed/--quick as the study); "
                        "prints its rows as JSON")
    p.help_from(_help_constants)
    p.set_defaults(run=run)


def _help_constants():
    """The constants `study --help` quotes."""
    from pitotcal.io.alfa import ALFA_DATA_ENV, ALFA_DIR_NAME
    from pitotcal.maneuvers.fly.jsbsim_engine import DEFAULT_AIRCRAFT

    return {"alfa_env": ALFA_DATA_ENV, "alfa_dir": ALFA_DIR_NAME, "aircraft": DEFAULT_AIRCRAFT}


def run(args):
    from pitotcal.studies.catalog import StudyInterrupted, rerun, run_study

    if args.run_index is not None:
        return _repeat(args, rerun)
    try:
        summary = run_study(args.name, runs=args.runs, out_dir=args.out_dir, seed=args.seed,
                            workers=args.workers, scheduler=args.scheduler, quick=args.quick,
                            progress=_progress(args.name), data_dir=args.data_dir,
                            engine=args.engine)
    except StudyInterrupted as stop:
        s = stop.summary
        if sys.stderr.isatty():
            print(file=sys.stderr)          # end the progress bar's line
        print(f"pitotcal study: {args.name} {s['headline']}", file=sys.stderr)
        for path in s["files"]:
            print(f"  wrote {path}", file=sys.stderr)
        return 130
    n = summary["n_runs"]
    print(f"study {args.name}: {n} run{'' if n == 1 else 's'}, {summary['n_failed']} failed, "
          f"{summary['elapsed_s']} s")
    print(f"  result: {summary['headline']}")
    for key in ("coverage_2sigma", "coverage_2sigma_uncorrected"):
        if summary.get(key) is not None:
            print(f"  {key}: {summary[key]:.3f}")
    for path in summary["files"]:
        print(f"  wrote {path}")
    return 0


def _repeat(args, rerun):
    import json

    from pitotcal.io.jsonfile import json_ready

    rows = rerun(args.name, args.run_index, runs=args.runs, seed=args.seed, quick=args.quick,
                 data_dir=args.data_dir, engine=args.engine)
    # strict JSON (NaN as null) that any parser reads; what json cannot hold as text
    print(json.dumps(json_ready(rows), indent=2, default=str, allow_nan=False))
    return 1 if any(r.get("error") for r in rows) else 0


def _progress(name):
    return _Bar(name) if sys.stderr.isatty() else _Counter(name)


class _Bar:
    """A one-line progress bar on stderr (redrawn in place)."""

    def __init__(self, name, width=30):
        self.name, self.width = name, width

    def __call__(self, done, total):
        filled = int(self.width * done / total)
        end = "\n" if done == total else ""
        sys.stderr.write(f"\r{self.name} [{'#' * filled}{'.' * (self.width - filled)}] "
                         f"{done}/{total}{end}")
        sys.stderr.flush()


class _Counter:
    """Progress for logs and pipes: a line every 10% of the runs."""

    def __init__(self, name):
        self.name = name

    def __call__(self, done, total):
        if done == total or done % max(1, total // 10) == 0:
            sys.stderr.write(f"{self.name}: {done}/{total} runs\n")
