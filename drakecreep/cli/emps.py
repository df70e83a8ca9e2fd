"""``drakecreep emps``: the EMPS benchmark reference results (IDIM-LS table, replay errors) beside the published values.

Fits on DATA_EMPS.mat only; DATA_EMPS_PULSES.mat (the held-out validation set) is only scored with the
fixed parameters. The data folder is ``--data``, else the files shipped in ``drakecreep/data/emps``
beside the repository.
"""

from pathlib import Path

from drakecreep.cli._common import print_json
from drakecreep.errors import InputError

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Register ``emps``."""
    p = subparsers.add_parser("emps", help="EMPS benchmark: IDIM-LS parameters and replay errors vs published",
                              description=__doc__.split("\n\n")[0])
    p.add_argument("--data", metavar="DIR", help="folder of DATA_EMPS.mat and DATA_EMPS_PULSES.mat")
    p.add_argument("--json", action="store_true", help="print JSON instead of Markdown tables")
    p.set_defaults(func=run)
    return p


def run(args):
    """Compute and print the tables."""
    from drakecreep.gap.emps import reference_results, to_markdown
    from drakecreep.gap.measured import EMPS_FILES, emps_data_dir

    folder = Path(args.data) if args.data else emps_data_dir()
    missing = [name for name in EMPS_FILES.values() if not (folder / name).exists()]
    if missing:
        raise InputError("--data", str(folder), "a folder holding " + " and ".join(EMPS_FILES.values()))
    results = reference_results(folder)
    if args.json:
        print_json(results)
    else:
        print(to_markdown(results))
    return 0
