"""``drakecreep sweep SPEC.yaml``: run a parameter sweep (grid or random) and write its table (and map)."""

from drakecreep.cli._common import existing_path, print_json, workers
from drakecreep.errors import InputError
from drakecreep.processes import usable_cpus

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    p = subparsers.add_parser(
        "sweep",
        help="parameter sweep over a grid or random sample; a tidy table of metrics per case",
        description=(
            "Run the sweep described by SPEC.yaml (base parameters, axes, scenario defaults, metrics; see "
            "drakecreep.sim.sweep.load_spec). Finished cases are cached in OUT/cache, so a rerun resumes; the table "
            "is written to OUT/results.parquet and OUT/results.csv, and a stability map to OUT/map.png when "
            "the spec has a plot section. Local processes by default, a Dask cluster with --scheduler."
        ),
    )
    p.add_argument("spec", metavar="SPEC.yaml", help="sweep spec (YAML)")
    p.add_argument("--workers", type=workers, metavar="N",
                   help=f"local worker processes (default, and the most started: the {usable_cpus()} CPUs this process "
                        f"may use); 1 runs in this process")
    p.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address, e.g. tcp://host:8786")
    p.add_argument("--out", default="out/sweep", metavar="DIR", help="output folder (default out/sweep)")
    p.add_argument("--retries", type=int, default=2, metavar="N", help="extra attempts of a failed case (default 2, at most 10)")
    p.add_argument("--batch", type=int, default=200, metavar="N",
                   help="simulate up to N compatible cases together in one Drake system (default 200; "
                        "1 = one case at a time)")
    p.add_argument("--max-cases", type=int, default=None, metavar="N",
                   help="refuse sweeps of more cases than N (default 100000; raise it deliberately)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=run)
    return p


def run(args):
    from drakecreep.files import check_output_dir
    from drakecreep.report.plots import plot_stability_map
    from drakecreep.sim.sweep import DEFAULT_MAP_COLOR, MAX_CASES, MAX_RETRIES, connect_dask, load_spec, run_sweep

    if args.scheduler is not None and args.workers:
        raise InputError("--workers", args.workers, "not with --scheduler (the cluster has its workers)")
    if not 0 <= args.retries <= MAX_RETRIES:
        raise InputError("--retries", args.retries, f"an integer in [0, {MAX_RETRIES}]")
    if args.batch is not None and args.batch < 1:
        raise InputError("--batch", args.batch, "an integer >= 1")
    if args.max_cases is not None and args.max_cases < 1:
        raise InputError("--max-cases", args.max_cases, "an integer >= 1")
    # everything is checked before the first case runs: the spec, the output folder, the scheduler
    spec_path = existing_path("SPEC.yaml", args.spec)
    check_output_dir(args.out)  # before the spec's cases are built (a 100 x 1000 grid: 27 s before '--out' was refused)
    spec = load_spec(spec_path, max_cases=args.max_cases or MAX_CASES)
    scheduler = connect_dask(args.scheduler) if args.scheduler is not None else None
    if scheduler is not None:
        executor = "dask"
    elif args.workers == 1:
        executor = "serial"
    else:
        executor = "processes"
    extra = {}
    if spec.plot:  # its colour is a column of the table (load_spec)
        def write_map(table, path):
            plot_stability_map(table, spec.plot["x"], path, y=spec.plot.get("y", "feed"),
                               color=spec.plot.get("color", DEFAULT_MAP_COLOR), base=spec.base)
        extra["map.png"] = write_map
    try:
        result = run_sweep(
            spec.base, spec.points, scenario=spec.scenario, executor=executor, workers=args.workers,
            scheduler=scheduler, out_dir=args.out, progress=not (args.no_progress or args.quiet), retries=args.retries,
            columns=spec.metrics, batch_size=args.batch if args.batch > 1 else None, extra_outputs=extra,
        )
    finally:
        if scheduler is not None:
            scheduler.close()
    paths = {k: str(v) for k, v in result.paths.items()}
    print_json(dict(cases=len(result.table), computed=result.computed, cached=result.cached, failed=result.failed,
                    retried=result.retried, wall_time_s=round(result.wall_time, 3), executor=executor, **paths))
    return 0 if result.failed == 0 else 1
