"""``drakecreep tune``: PI gains for a velocity-loop bandwidth and phase margin, P gain for the position loop."""

import sys

from drakecreep.cli._common import add_params_options, number, params_from_args, print_json
from drakecreep.errors import InputError
from drakecreep.files import to_jsonable

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Register ``tune``."""
    p = subparsers.add_parser(
        "tune", help="PI/P gains for a target velocity-loop bandwidth and phase margin",
        description="Loop shaping at the crossover on the linearized (sampled) velocity loop: kv and ki solved "
                    "for |L| = 1 and the target phase margin at the crossover, the crossover placed for the target "
                    "closed-loop bandwidth; kp = 2 pi bandwidth / 4. Prints the gains and the resulting margins.",
    )
    add_params_options(p)
    p.add_argument("--bandwidth", type=number, default=40.0, metavar="HZ",
                   help="velocity-loop -3 dB bandwidth in Hz (default 40)")
    p.add_argument("--phase-margin", type=number, default=60.0, metavar="DEG",
                   help="velocity-loop phase margin in deg (default 60)")
    p.add_argument("--feed", type=number, default=1.0, metavar="MM_PER_S", help="operating feed in mm/s (default 1)")
    p.add_argument("--load-case", type=int, default=3, metavar="N", help="load case (default 3)")
    p.add_argument("--write", metavar="FILE",
                   help="write the parameters with the tuned gains to FILE (YAML; simulate --params FILE reads it)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)
    return p


def run(args):
    """Tune and print."""
    from drakecreep.cli.margins import print_margins, scenario_from_args
    from drakecreep.errors import renaming
    from drakecreep.servo.tuning import check_targets, tune

    # the library's bounds, refused before the parameters are read and anything is linearized
    renaming(lambda field: "--" + field, check_targets, args.bandwidth, args.phase_margin)

    params = params_from_args(args)
    scenario = scenario_from_args(args, params)
    if args.write:  # before the tuning, not after it
        from drakecreep.files import check_output_file

        check_output_file(args.write, "--write")
    try:
        result = tune(params, scenario, args.bandwidth, args.phase_margin)
    except InputError as err:
        if err.field in ("bandwidth", "phase-margin"):
            raise err.renamed("--" + err.field) from None
        raise
    summary = result.summary()
    if args.write:
        from drakecreep.params import save_params

        save_params(result.params, args.write)
        summary["params_file"] = str(args.write)
        if not args.json:
            print(f"wrote {args.write}", file=sys.stderr)
    if args.json:
        print_json(to_jsonable(summary))
        return 0
    print(f"rule: {result.rule}")
    print(f"kv = {result.velocity_gain:.5g} N s/m, ki = {result.velocity_integral_gain:.5g} N/m "
          f"(PI corner {summary['pi_corner_Hz']:.3g} Hz), kp = {result.position_gain:.4g} 1/s")
    print(f"velocity-loop crossover placed at {result.crossover_Hz:.3g} Hz")
    print("resulting margins:")
    print_margins(summary)
    return 0
