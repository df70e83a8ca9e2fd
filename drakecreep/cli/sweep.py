"""``drakecreep sweep SPEC.yaml``: run a parameter sweep (grid or random) and write its table (and map)."""

import os

from drakecreep.cli._common import print_json, workers
from drakecreep.errors import InputError

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
                   help=f"local worker processes (default: all cores, {os.cpu_count()}); 1 runs in this process")
    p.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address, e.g. tcp://host:8786")
    p.add_argument("--out", default="out/sweep", metavar="DIR", help="output folder (default out/sweep)")
    p.add_argument("--retries", type=int, default=2, metavar="N", help="extra attempts of a failed case (default 2)")
    p.add_argument("--batch", type=int, default=200, metavar="N",
                   help="simulate up to N compatible cases together in one Drake system (default 200; "
                        "1 = one case at a time)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=run)
    return p


def run(args):
    from drakecreep.report.plots import plot_stability_map
    from drakecreep.sim.sweep import load_spec, run_sweep

    if args.scheduler and args.workers:
        raise InputError("--workers", args.workers, "not with --scheduler (the cluster has its workers)")
    if args.retries < 0:
        raise InputError("--retries", args.retries, "an integer >= 0")
    if args.batch is not None and args.batch < 1:
        raise InputError("--batch", args.batch, "an integer >= 1")
    spec = load_spec(args.spec)
    if args.scheduler:
        executor = "dask"
    elif args.workers == 1:
        executor = "serial"
    else:
        executor = "processes"
    result = run_sweep(
        spec.base, spec.points, scenario=spec.scenario, executor=executor, workers=args.workers,
        scheduler=args.scheduler, out_dir=args.out, progress=not (args.no_progress or args.quiet), retries=args.retries,
        columns=spec.metrics, batch_size=args.batch if args.batch > 1 else None,
    )
    paths = {k: str(v) for k, v in result.paths.items()}
    if spec.plot:
        color = spec.plot.get("color", "fluctuation_rate_percent")
        if color in result.table.columns:
            paths["map"] = str(plot_stability_map(
                result.table, spec.plot["x"], os.path.join(args.out, "map.png"), y=spec.plot.get("y", "feed"),
                color=color, base=spec.base,
            ))
    print_json(dict(cases=len(result.table), computed=result.computed, cached=result.cached, failed=result.failed,
                    retried=result.retried, wall_time_s=round(result.wall_time, 3), executor=executor, **paths))
    return 0 if result.failed == 0 else 1
