"""``drakecreep compensate``: friction compensation methods against none over feeds and loads."""

from drakecreep.cli._common import (add_params_options, comma_items, distinct, params_from_args, positive_float,
                                    print_json, workers)
from drakecreep.errors import InputError, renaming
from drakecreep.params import COMPENSATION_METHODS, COMPENSATION_STUDY_METHODS, COMPENSATION_VARIANTS

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    p = subparsers.add_parser(
        "compensate",
        help="compare friction compensation methods (static, LuGre observer, DOB, dither) against none",
        description=(
            "Simulate each compensation method and no compensation at each feed and load case; report the speed "
            "fluctuation, stick fraction and following error over the steady window, optionally the lowest feed "
            "without creep (--critical) and the effect of a +-30 % model error (--robustness). Writes "
            "compensation.csv, summary.md, rows.json and comparison.png to --out."
        ),
    )
    add_params_options(p)
    p.add_argument("--method", action="append",
                   choices=[m for m in COMPENSATION_METHODS + tuple(COMPENSATION_VARIANTS) if m != "none"],
                   help="method to compare (repeatable; default: " + ", ".join(COMPENSATION_STUDY_METHODS[1:]) + "). "
                   "static = Stribeck feedforward at the reference speed; static-measured = the same model at the "
                   "measured motor speed")
    p.add_argument("--feeds", default="0.05,0.1,0.2,0.5,1,2,5", metavar="MM_PER_S",
                   help="comma-separated feeds in mm/s (default 0.05,0.1,0.2,0.5,1,2,5)")
    p.add_argument("--load-cases", default="1,2,3", metavar="N", help="comma-separated load cases (default 1,2,3)")
    p.add_argument("--duration", type=positive_float, default=2.0, metavar="S", help="simulated time per run (default 2)")
    p.add_argument("--speed-source", choices=("encoder", "ideal"), default=None,
                   help="speed the compensators read (default: from the parameters, compensation.speed_source): "
                        "encoder = at the velocity-loop rate on the count difference, output held and delayed "
                        "like the command; ideal = continuously on the true motor speed")
    p.add_argument("--critical", action="store_true", help="also the lowest feed without creep (bisection)")
    p.add_argument("--robustness", action="store_true", help="also the model off by +-30 %% in each parameter")
    p.add_argument("--workers", type=workers, default=2, metavar="N",
                   help="processes (default 2; no more than the CPUs this process may use are started)")
    p.add_argument("--out", default="out/compensate", metavar="DIR", help="output folder")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)
    return p


def _list(text, option, kind, check, allowed):
    items = comma_items(text, option, allowed)
    try:
        values = [kind(x) for x in items]
    except ValueError:
        raise InputError(option, text, allowed) from None
    if not all(check(v) for v in values):
        raise InputError(option, text, allowed)
    return distinct(values, option, text, allowed + ", each once")


def run(args):
    from drakecreep.studies.compensation import check_duration, creep_boundaries, evaluate, robustness, write_report
    from drakecreep.scenario import MAX_FEED

    params = params_from_args(args)
    if args.speed_source is not None:
        from drakecreep.params import with_value

        if not params.controller.sampled:  # a continuous controller's compensators read the ideal speed
            raise InputError("--speed-source", args.speed_source, "only with a sampled controller (controller.sampled: "
                             "the continuous one's compensators read the ideal speed; the results were the same)")
        params = with_value(params, "compensation.speed_source", args.speed_source)
    twice = sorted({m for m in args.method or () if args.method.count(m) > 1})
    if twice:  # as --feeds 1,1 (a method given twice was run once without a word)
        raise InputError("--method", ",".join(args.method), f"each method once ({', '.join(twice)} given twice)")
    from drakecreep.files import check_output_dir

    feeds = _list(args.feeds, "--feeds", float, lambda v: 1e-4 <= v <= MAX_FEED * 1e3,
                  f"comma-separated feeds in [1e-4, {MAX_FEED * 1e3:g}] mm/s")
    renaming(lambda field: "--duration", check_duration, params, args.duration)  # the study's bounds, in s
    n = len(params.loads.cases)
    loads = _list(args.load_cases, "--load-cases", int, lambda v: 0 <= v <= n, f"comma-separated integers in 0..{n}")
    check_output_dir(args.out)  # before the study, not after it
    methods = ["none"] + list(dict.fromkeys(args.method or COMPENSATION_STUDY_METHODS[1:]))
    rows = evaluate(params, methods, feeds, loads, duration=args.duration, workers=args.workers)
    crit = creep_boundaries(params, methods, loads) if args.critical else None
    robust = robustness(params, [m for m in methods if m != "none"], load_case=max(loads), duration=args.duration,
                        workers=args.workers) if args.robustness else None
    name = args.params or args.preset
    paths = write_report(args.out, rows, crit, robust, name)
    if args.json:
        print_json(dict(rows=rows, critical=crit, robustness=robust, out={k: str(v) for k, v in paths.items()}))
    else:
        print(paths["markdown"].read_text(), end="")
        print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 0
