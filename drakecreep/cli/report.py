"""``drakecreep report``: a self-contained HTML servo-loop report (margins, Bode, Nyquist, loci, pole map, runs)."""

from drakecreep.cli._common import add_params_options, number, params_from_args, workers
from drakecreep.errors import InputError
from drakecreep.processes import usable_cpus

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Register ``report``."""
    p = subparsers.add_parser(
        "report", help="HTML report: margins, Bode, Nyquist, root loci, pole map with the creep conditions",
        description="Write DIR/index.html (plots embedded), DIR/margins.json and the PNGs.",
    )
    add_params_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--feed", type=number, default=1.0, metavar="MM_PER_S", help="operating feed of the loop analysis (default 1)")
    p.add_argument("--low-feed", type=number, default=0.1, metavar="MM_PER_S",
                   help="low-speed feed of the simulation and the pole map (default 0.1)")
    p.add_argument("--load-case", type=int, default=3, metavar="N", help="load case (default 3)")
    p.add_argument("--no-sim-grid", action="store_true", help="skip the simulated creep markers on the pole map")
    p.add_argument("--workers", type=workers, metavar="N",
                   help=f"processes for the pole map's 36 creep simulations (default: the usable CPUs, {usable_cpus()} "
                        "here; not with --no-sim-grid)")
    p.add_argument("--json", action="store_true", help="print one JSON object (the written files and the margins)")
    p.set_defaults(func=run)
    return p


def run(args):
    """Build the report and print where it is."""
    from drakecreep.cli._common import POSITIVE_FEED, check_feed, feed_from_mm_s
    from drakecreep.cli.margins import scenario_from_args
    from drakecreep.files import check_output_dir
    from drakecreep.report.loop_report import build_report
    from drakecreep.scenario import Scenario

    if args.no_sim_grid and args.workers is not None:  # it ran on one process without a word
        raise InputError("--workers", args.workers, "only with the pole map's creep simulations (not with "
                         "--no-sim-grid, which runs none)")
    params = params_from_args(args)
    scenario = scenario_from_args(args, params)
    if not args.low_feed > 0:
        raise InputError("--low-feed", args.low_feed, POSITIVE_FEED)
    low = feed_from_mm_s(args.low_feed, "--low-feed")
    check_feed(params, Scenario(feed=low, load_case=scenario.load_case), "--low-feed", args.low_feed)
    check_output_dir(args.out)  # before the computation, not after it
    source = args.params if args.params else f"preset {args.preset}"
    if getattr(args, "friction", None):
        source += f", friction law {args.friction}"
    result = build_report(params, args.out, feed=scenario.feed, load_case=scenario.load_case, low_feed=low,
                          source=source, sim_grid=None if args.no_sim_grid else (6, 6),
                          workers=args.workers or usable_cpus())
    if args.json:
        import json

        from drakecreep.cli._common import print_json

        print_json({"html": str(result["html"]), "json": str(result["json"]), "pngs": result.get("pngs"),
                    "margins": json.loads(result["json"].read_text()), "wall_time_s": result["timings"]["total"]})
        return 0
    print(f"wrote {result['html']} ({result['timings']['total']:.1f} s)")
    return 0
