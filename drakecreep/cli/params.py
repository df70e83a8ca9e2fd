"""``drakecreep params``: print a preset's YAML (with its sources) or check a parameter file."""

from drakecreep.cli._common import existing_path, print_json

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    from drakecreep.params import PRESETS

    p = subparsers.add_parser(
        "params",
        help="print a parameter preset as YAML, or validate a parameter file",
        description="Print a preset as commented YAML (SI units; assumptions and their sources in the "
        "comments), or load and validate --check FILE.",
    )
    # one or the other: '--check FILE --preset rigid_axis' printed the file, the preset ignored without a word
    which = p.add_mutually_exclusive_group()
    which.add_argument("--preset", choices=PRESETS, help="preset to print (default: paper)")
    which.add_argument("--check", metavar="FILE", help="validate a parameter file and print it resolved (defaults filled)")
    p.add_argument("--json", action="store_true", help="print as JSON instead of YAML")
    p.set_defaults(func=run)
    return p


def run(args):
    import yaml

    from drakecreep.params import load_params, params_to_dict, preset, preset_text

    args.preset = args.preset or "paper"
    if args.check:
        params = load_params(existing_path("--check", args.check))  # said 'No such file or directory: x.yaml'
    elif not args.json:
        print(preset_text(args.preset), end="")
        return 0
    else:
        params = preset(args.preset)
    if args.json:
        print_json(params_to_dict(params))
    else:
        print(yaml.safe_dump(params_to_dict(params), sort_keys=False), end="")
    return 0
