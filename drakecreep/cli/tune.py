"""``drakecreep tune``: PI gains for a velocity-loop bandwidth and phase margin, P gain for the position loop."""

import sys

from drakecreep.cli._common import add_params_options, number, params_from_args, print_json
from drakecreep.errors import InputError
from drakecreep.files import to_jsonable

__all__ = ["add_parser", "run"]

#: the targets when an option is not given: :func:`drakecreep.servo.tuning.tune`'s defaults (a test holds them
#: equal; the servo layer is not imported to build the parser: python-control takes 1.9 s)
DEFAULT_BANDWIDTH_HZ = 40.0
DEFAULT_PHASE_MARGIN_DEG = 60.0


def add_parser(subparsers):
    """Register ``tune``."""
    p = subparsers.add_parser(
        "tune", help="PI/P gains for a target velocity-loop bandwidth and phase margin",
        description="Loop shaping at the crossover on the linearized (sampled) velocity loop: kv and ki solved "
                    "for |L| = 1 and the target phase margin at the crossover, the crossover placed for the target "
                    "closed-loop bandwidth; kp = 2 pi bandwidth / 4. Prints the gains and the resulting margins.",
    )
    add_params_options(p)
    p.add_argument("--bandwidth", type=number, metavar="HZ",
                   help=f"velocity-loop -3 dB bandwidth in Hz (default {DEFAULT_BANDWIDTH_HZ:g})")
    p.add_argument("--phase-margin", type=number, metavar="DEG",
                   help=f"velocity-loop phase margin in deg (default {DEFAULT_PHASE_MARGIN_DEG:g})")
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
    given = [option for option, value in (("--bandwidth", args.bandwidth), ("--phase-margin", args.phase_margin))
             if value is not None]
    bandwidth = DEFAULT_BANDWIDTH_HZ if args.bandwidth is None else args.bandwidth
    phase_margin = DEFAULT_PHASE_MARGIN_DEG if args.phase_margin is None else args.phase_margin
    renaming(lambda field: "--" + field, check_targets, bandwidth, phase_margin)

    params = params_from_args(args)
    scenario = scenario_from_args(args, params)
    if args.write:  # before the tuning, not after it
        from drakecreep.files import check_output_file

        check_output_file(args.write, "--write")
        import os

        if args.params and os.path.exists(args.write) and os.path.samefile(args.write, args.params):
            # save_params writes plain YAML: the input's comments (sources, assumptions) were lost without a word
            raise InputError("--write", args.write, "a file other than --params (writing the tuned gains over it "
                             "would drop its comments: write a new file and compare)")
    try:
        result = tune(params, scenario, bandwidth, phase_margin)
    except InputError as err:
        if getattr(err, "pair", False):
            # the two targets together are out of reach: named by the one the user gave (the bandwidth when both
            # or neither), the value showing both
            raise err.renamed("--phase-margin" if given == ["--phase-margin"] else "--bandwidth") from None
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
