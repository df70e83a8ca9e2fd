"""``drakecreep``-kind datasets whose params file declares the table mass wrong (docs/gap_benchmark.md, 3cu; a
development study, not a benchmark row).

The benchmark's params file (:func:`drakecreep.gap.benchmark.declared_params`) has the truth's masses, axial chain
and current loop, and only its friction levels off (``DECLARED_SPREAD``). A user's file is rarely that exact: a
fixture or workpiece left out of ``table.mass``, a catalogue inertia. The diagnosis fits the friction levels by
default (``table.mass`` only with ``--uncertain ...,table.mass``) and warns of a mass only beyond a factor of 2
(``MASS_WARNING``). This runs the benchmark's own scoring (:func:`drakecreep.gap.benchmark.evaluate`) on
development datasets with ``table.mass`` multiplied by a factor in every run's params file, nothing else changed.
One JSON line per case: the benchmark row (claims, audit) with the factor and both masses. Run from the repository
root:

    PYTHONPATH=. python analysis/declared_mass_study.py 114000:null:flexible:0.85 114001:null:rigid:1.15
"""

import argparse
import dataclasses
import json
import math
import sys

from drakecreep.errors import InputError, name_list
from drakecreep.gap import benchmark as B
from drakecreep.params import with_value
from study_cli import dev_spec

__all__ = ["case", "run_case", "main"]


def case(text):
    """``SEED:WITHHELD:AXIS:FACTOR`` (:func:`drakecreep.gap.benchmark.dataset_spec` and a factor 0.1-10 on
    ``table.mass``) -> ``(seed, withheld, axis, factor)``; a development seed only."""
    spec, _, factor = str(text).rpartition(":")
    seed, withheld, axis = dev_spec(spec)
    try:
        factor = float(factor)
    except ValueError:
        factor = math.nan
    if not 0.1 <= factor <= 10.0:
        raise argparse.ArgumentTypeError(f"factor: got {text.rpartition(':')[2]!r} in {text!r}; allowed: a number "
                                         "0.1-10 after SEED:WITHHELD:AXIS, e.g. 114000:null:flexible:0.85")
    return seed, withheld, axis, factor


def run_case(seed, withheld, axis, factor, progress=None, uncertain=None):
    """The benchmark row of one dataset whose params file has ``table.mass`` times ``factor`` (``uncertain``: the
    fields the nominal fit takes as uncertain, :func:`drakecreep.gap.benchmark.evaluate`; None its default)."""
    ds = B.generate_datasets([(seed, withheld, "drakecreep", axis)])[0]
    declared = ds.train[0].meta.params
    wrong = with_value(declared, "table.mass", factor * declared.table.mass)

    def swap(runs):
        return [dataclasses.replace(r, meta=dataclasses.replace(r.meta, params=wrong)) for r in runs]

    ds = dataclasses.replace(ds, train=swap(ds.train), test=swap(ds.test), audit=swap(ds.audit))
    row = B.evaluate(ds, progress=progress, uncertain=uncertain)
    # (the row's own ``uncertain`` names the fields its nominal fit took)
    row.update(mass_factor=factor, declared_table_mass=wrong.table.mass, true_table_mass=declared.table.mass)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cases", nargs="+", type=case, metavar="SEED:WITHHELD:AXIS:FACTOR")
    ap.add_argument("--uncertain", metavar="PATHS", help="the fields the nominal fit takes as uncertain, comma "
                    "separated (default: diagnose_drive's), e.g. table.seal_force,nut.preload_torque,"
                    "friction.viscous,table.mass")
    args = ap.parse_args(argv)
    uncertain = None
    if args.uncertain is not None:
        try:
            uncertain = B.check_uncertain(("drakecreep",), name_list(args.uncertain.split(","), "--uncertain"))
        except InputError as e:
            ap.exit(2, f"{ap.prog}: error: {e}\n")
    failed = 0
    for seed, withheld, axis, factor in args.cases:
        try:
            row = run_case(seed, withheld, axis, factor, uncertain=uncertain,
                           progress=lambda line: print(f"[{seed} x{factor}] {line}", file=sys.stderr, flush=True))
        except InputError as e:
            failed += 1
            row = {"seed": seed, "mass_factor": factor, "failed": str(e)}
        print(json.dumps(row, default=float), flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
