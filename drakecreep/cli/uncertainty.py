"""``drakecreep uncertainty``: creep over every plausible rig (the preset's assumptions sampled in their ranges)."""

import os

from drakecreep.cli._common import (add_params_options, check_duration, comma_items, distinct, existing_path,
                                    feed_from_mm_s, params_from_args, positive_float, print_json, workers)
from drakecreep.errors import InputError, renaming
from drakecreep.processes import usable_cpus

__all__ = ["add_parser", "run", "run_study", "check_study", "share_line", "spec_from_args", "DEFAULT_FEEDS_MM_S"]

#: feeds (mm/s) of the default study: the paper's creep range and above
DEFAULT_FEEDS_MM_S = (0.05, 0.1, 0.2, 0.5, 1.0)
_DISTINCT = "distinct values (each is a column of the study)"


def _feeds(text):
    allowed = "comma-separated feeds in mm/s, e.g. 0.05,0.1,0.2"
    items = comma_items(text, "--feeds", allowed)
    try:
        values = [float(v) for v in items]
    except ValueError:
        raise InputError("--feeds", text, allowed) from None
    return distinct([feed_from_mm_s(v, "--feeds") for v in values], "--feeds", text, _DISTINCT)


def _load_cases(text, params):
    n = len(params.loads.cases)
    allowed = f"comma-separated integers in 0..{n} (0 = unloaded)"
    items = comma_items(text, "--load-cases", allowed)
    try:
        values = [int(v) for v in items]
    except ValueError:
        raise InputError("--load-cases", text, "comma-separated load case numbers, e.g. 1,2,3") from None
    if any(not 0 <= v <= n for v in values):
        raise InputError("--load-cases", text, allowed)
    return distinct(values, "--load-cases", text, _DISTINCT)


def add_parser(subparsers):
    p = subparsers.add_parser(
        "uncertainty",
        help="share of plausible rigs that creep: the preset's assumed values sampled over their ranges",
        description=(
            "Sample the preset's [assumed] parameters over their plausible ranges (presets/<preset>_uncertainty.yaml, "
            "a distribution and source per parameter; a seeded Latin hypercube), simulate every rig at every feed and "
            "load case with the sweep engine, and print per feed and load the share of rigs that creep, with a 95 % "
            "interval, the spread of the speed fluctuation, and which parameters decide it (Spearman rank "
            "correlation with the creep verdict). Writes results.csv/.parquet (one row per rig, feed, load), "
            "summary.csv, sensitivity.csv and uncertainty.json to --out."
        ),
    )
    add_params_options(p)
    p.add_argument("--spec", metavar="FILE",
                   help="uncertainty spec (YAML; default: the packaged presets/*_uncertainty.yaml that names the preset; needed with --params)")
    p.add_argument("--samples", type=int, default=200, metavar="N", help="number of plausible rigs (default 200)")
    p.add_argument("--feeds", default=",".join(f"{f:g}" for f in DEFAULT_FEEDS_MM_S), metavar="MM_S,...",
                   help="feeds in mm/s (default " + ",".join(f"{f:g}" for f in DEFAULT_FEEDS_MM_S) + ")")
    p.add_argument("--load-cases", default="3", metavar="N,...", help="load cases (default 3)")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="seed of the rig sample (default 0)")
    p.add_argument("--duration", type=positive_float, default=3.0, metavar="S",
                   help="simulated time per case in s (default 3; metrics from simulation.steady_start)")
    p.add_argument("--workers", type=workers, metavar="N",
                   help=f"local worker processes (default, and the most started: the {usable_cpus()} CPUs this process "
                        f"may use); 1 runs in this process")
    p.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address, e.g. tcp://host:8786")
    p.add_argument("--out", default="out/uncertainty", metavar="DIR", help="output folder (default out/uncertainty)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the text summary")
    p.set_defaults(func=run)
    return p


def spec_from_args(args):
    """The uncertainty spec of ``--spec``, or the packaged one of ``--preset``."""
    from drakecreep.studies.uncertainty import load_uncertainty, uncertainty_spec

    if getattr(args, "spec", None):
        # the preset's spec: one of rigid_axis's ran on paper, reported as rigid_axis's (with --params: any)
        return load_uncertainty(existing_path("--spec", args.spec), None if args.params else args.preset)
    if args.params:
        raise InputError("--spec", None, "an uncertainty spec file: with --params the preset's spec does not apply")
    # the option, not the library's name ('preset: got 'rigid_axis'')
    return renaming(lambda field: "--preset" if field == "preset" else field, uncertainty_spec, args.preset)


def check_study(params, samples, feeds, load_cases, *, seed=0, duration=3.0, out=None):
    """Everything :func:`run_study` needs, checked before the first simulation (and ``out`` created)."""
    from drakecreep.files import check_output_dir
    from drakecreep.sim.sweep import MAX_CASES

    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise InputError("--samples", samples, "an integer >= 1")
    per_rig = max(1, len(feeds) * len(load_cases))
    if samples * per_rig > MAX_CASES:  # the rig sample alone would not fit in memory (1e11 rigs: 15 TiB)
        raise InputError("--samples", samples, f"at most {MAX_CASES // per_rig} rigs ({MAX_CASES} simulations "
                                               f"of {len(feeds)} feed(s) x {len(load_cases)} load case(s))")
    if not 0 <= seed < 2**63:  # as a sweep spec's seed
        raise InputError("--seed", seed, "an integer in [0, 2**63)")
    from drakecreep.sim.simulation import check_window

    # the metrics window's samples and the run's, named as the option ('duration: got 1.001' came from the sweep)
    check_window(params, check_duration(duration), "--duration")
    if out is not None:
        check_output_dir(out)


def run_study(params, spec, samples, feeds, load_cases, *, seed=0, duration=3.0, n_workers=None, scheduler=None,
              out=None, progress=True):
    """Validate, run :func:`drakecreep.studies.uncertainty.run_uncertainty`, write its tables; return the result."""
    from drakecreep.files import write_atomic, write_json
    from drakecreep.studies.uncertainty import run_uncertainty

    check_study(params, samples, feeds, load_cases, seed=seed, duration=duration, out=out)
    if scheduler:
        executor = "dask"
    elif n_workers == 1:
        executor = "serial"
    else:
        executor = "processes"
    result = run_uncertainty(params, spec, samples, feeds, load_cases, seed=seed, duration=duration, executor=executor,
                             workers=n_workers if executor == "processes" else None, scheduler=scheduler,
                             out_dir=out, progress=progress)
    if out is not None:
        write_atomic(os.path.join(out, "summary.csv"), lambda tmp: result.summary.to_csv(tmp, index=False))
        write_atomic(os.path.join(out, "sensitivity.csv"), lambda tmp: result.sensitivity.to_csv(tmp, index=False))
        write_json(os.path.join(out, "uncertainty.json"), _json(result))
    return result


def _json(result):
    return dict(
        spec=result.spec.source, preset=result.spec.preset, samples=result.samples, seed=result.seed,
        sampled=result.spec.paths, fixed=result.spec.fixed, wall_time_s=round(result.wall_time, 3),
        failed=result.failed, summary=result.summary.to_dict(orient="records"),
        sensitivity=result.sensitivity.to_dict(orient="records"),
    )


def share_line(row):
    """One summary row as ``creeps in N % of plausible rigs (95 % interval a-b %, n rigs)``."""
    if row["rigs"] == 0:
        return "no case finished"
    return (f"creeps in {row['creep_percent']:.0f} % of plausible rigs "
            f"(95 % interval {row['creep_low_percent']:.0f}-{row['creep_high_percent']:.0f} %, {int(row['rigs'])} rigs)")


def run(args):
    params = params_from_args(args)
    spec = spec_from_args(args)
    feeds = _feeds(args.feeds)
    load_cases = _load_cases(args.load_cases, params)
    if args.scheduler and args.workers:
        raise InputError("--workers", args.workers, "not with --scheduler (the cluster has its workers)")
    result = run_study(params, spec, args.samples, feeds, load_cases, seed=args.seed, duration=args.duration,
                       n_workers=args.workers, scheduler=args.scheduler, out=args.out, progress=not args.no_progress)
    if args.json:
        print_json(dict(_json(result), out=args.out))
        return 0 if result.failed == 0 else 1
    law = params.friction.law
    print(f"{result.samples} plausible rigs ({spec.source}: {len(spec.paths)} assumed parameters sampled, "
          f"{len(spec.fixed)} held fixed), {law} friction, seed {result.seed}: "
          f"{len(result.table)} simulations in {result.wall_time:.1f} s")
    for _, row in result.summary.iterrows():
        spread = (f"fluctuation p5/p50/p95 {row['fluctuation_p5_mm_s']:.3g}/{row['fluctuation_p50_mm_s']:.3g}/"
                  f"{row['fluctuation_p95_mm_s']:.3g} mm/s")
        print(f"  feed {row['feed_mm_s']:g} mm/s, load case {int(row['load_case'])}: {share_line(row)}; {spread}")
    top = result.sensitivity.dropna(subset=["rho_creep"]).head(4)
    if len(top):
        print("  what decides it (Spearman rho with creep; creep share in the lower / upper half of the range):")
        for _, s in top.iterrows():
            print(f"    {s['parameter']:<34} rho {s['rho_creep']:+.2f}   "
                  f"{s['creep_low_half_percent']:.0f} % / {s['creep_high_half_percent']:.0f} %")
    if result.failed:
        print(f"  {result.failed} cases failed (see status in results.csv); they are left out of the shares")
    print(f"wrote {args.out}/results.csv, summary.csv, sensitivity.csv, uncertainty.json")
    return 0 if result.failed == 0 else 1
