"""``drakecreep``-kind datasets whose params file declares the table mass wrong (docs/gap_benchmark.md, 3cu; a
development study, not a benchmark row), or with ``--field`` another value the benchmark's params file copies from
the truth (3cx).

The benchmark's params file (:func:`drakecreep.gap.benchmark.declared_params`) has the truth's masses, axial chain
and current loop, and only its friction levels off (``DECLARED_SPREAD``). A user's file is rarely that exact: a
fixture or workpiece left out of ``table.mass``, a catalogue inertia. The diagnosis fits the friction levels by
default (``table.mass`` only with ``--uncertain ...,table.mass``) and warns of a mass only beyond a factor of 2
(``MASS_WARNING``). This runs the benchmark's own scoring (:func:`drakecreep.gap.benchmark.evaluate`) on
development datasets with ``table.mass`` multiplied by a factor in every run's params file, nothing else changed.
One JSON line per case: the benchmark row (claims, audit) with the factor and both masses. Run from the repository
root:

    PYTHONPATH=. python analysis/declared_mass_study.py 114000:null:flexible:0.85 114001:null:rigid:1.15
    PYTHONPATH=. python analysis/declared_mass_study.py --field axial_chain 114000:null:flexible:1.5

``--field`` (:data:`FIELDS`): ``table.mass`` (the default), ``axial_chain`` (the stiffness of every element of the
axial chain, the bearing's, the nut's and the shaft's through its Young's modulus, times the factor, so that the
chain's stiffness is off by it at every table position, its damping kept: a catalogue's stiffness is often above
what a mounted screw shows), ``motor.rotor_inertia`` or ``motor.current_loop_time_constant``. Rows carry
``field``, ``field_factor`` and the declared and true values of the field (for ``axial_chain`` the bearing's
stiffness, one of its three elements); ``table.mass`` rows also keep 3cu's names.
"""

import argparse
import dataclasses
import json
import math
import sys

from drakecreep.errors import InputError
from drakecreep.gap import benchmark as B
from drakecreep.params import get_value, with_value
from study_cli import dev_spec, drakecreep_uncertain

__all__ = ["FIELDS", "case", "declare", "run_case", "main"]

#: the fields ``--field`` can declare off by a factor (``axial_chain``: the chain's three stiffnesses at once)
FIELDS = ("table.mass", "axial_chain", "motor.rotor_inertia", "motor.current_loop_time_constant")
#: the params paths ``axial_chain`` scales
CHAIN = ("screw.bearing_stiffness", "nut.axial_stiffness", "screw.youngs_modulus")


def declare(params, field, factor):
    """``params`` with ``field`` (one of :data:`FIELDS`) times ``factor``: ``(params, declared, true)``, the last
    two the field's value in the new and the given params (the bearing's stiffness for ``axial_chain``)."""
    paths = CHAIN if field == "axial_chain" else (field,)
    out = params
    for path in paths:
        out = with_value(out, path, factor * get_value(params, path))
    return out, get_value(out, paths[0]), get_value(params, paths[0])


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


def run_case(seed, withheld, axis, factor, progress=None, uncertain=None, field="table.mass"):
    """The benchmark row of one dataset whose params file has ``field`` (:func:`declare`) times ``factor``
    (``uncertain``: the fields the nominal fit takes as uncertain, :func:`drakecreep.gap.benchmark.evaluate`; None
    its default)."""
    ds = B.generate_datasets([(seed, withheld, "drakecreep", axis)])[0]
    declared = ds.train[0].meta.params
    wrong, value, true = declare(declared, field, factor)

    def swap(runs):
        return [dataclasses.replace(r, meta=dataclasses.replace(r.meta, params=wrong)) for r in runs]

    ds = dataclasses.replace(ds, train=swap(ds.train), test=swap(ds.test), audit=swap(ds.audit))
    row = B.evaluate(ds, progress=progress, uncertain=uncertain)
    # (the row's own ``uncertain`` names the fields its nominal fit took)
    row.update(field=field, field_factor=factor, declared_value=value, true_value=true)
    if field == "table.mass":
        row.update(mass_factor=factor, declared_table_mass=value, true_table_mass=true)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cases", nargs="+", type=case, metavar="SEED:WITHHELD:AXIS:FACTOR")
    ap.add_argument("--field", default="table.mass", choices=FIELDS,
                    help="the value the params file declares off by FACTOR (default: table.mass)")
    ap.add_argument("--uncertain", metavar="PATHS", help="the fields the nominal fit takes as uncertain, comma "
                    "separated (default: diagnose_drive's), e.g. table.seal_force,nut.preload_torque,"
                    "friction.viscous,table.mass")
    args = ap.parse_args(argv)
    uncertain = drakecreep_uncertain(ap, args.uncertain)
    failed = 0
    for seed, withheld, axis, factor in args.cases:
        try:
            row = run_case(seed, withheld, axis, factor, uncertain=uncertain, field=args.field,
                           progress=lambda line: print(f"[{seed} {args.field} x{factor}] {line}", file=sys.stderr,
                                                       flush=True))
        except InputError as e:
            failed += 1
            row = {"seed": seed, "field": args.field, "field_factor": factor, "failed": str(e)}
        print(json.dumps(row, default=float), flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
