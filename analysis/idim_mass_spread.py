"""How far the inverse-dynamics mass of ``drakecreep``-kind runs spreads around the params file's rigid-body mass
(docs/gap_benchmark.md, 3cv; a development study, not a benchmark row).

The diagnosis warns of a wrong mass only when every run's IDIM-LS mass
(:func:`drakecreep.gap.drive_fit.inverse_dynamics_mass`) lies more than a factor ``MASS_WARNING`` (2) off the
rigid-body mass at the table (:func:`drakecreep.gap.drive_fit.rigid_mass`: table, nut, rotor, coupling and screw
through the lead). A tighter warning could tell a ``table.mass`` 15 % off (3cu) only if the runs' masses spread
less around the exact params file's than that error moves the rigid-body mass. This prints, per development
dataset, the exact file's rigid-body mass, the table's share of it and each run's IDIM mass over it (train, test
and audit runs; None where a run does not determine it). Run from the repository root:

    PYTHONPATH=. python analysis/idim_mass_spread.py 114000:null:flexible 114001:null:rigid
"""

import argparse
import json
import sys

from drakecreep.gap import benchmark as B
from drakecreep.gap.drive_fit import inverse_dynamics_mass, rigid_mass
from study_cli import dev_spec

__all__ = ["spread", "main"]


def spread(ds):
    """One JSON-ready row of dataset ``ds``: its rigid-body mass [kg] at the exact params file, the table mass [kg]
    in it, and every run's IDIM mass over the rigid-body mass (None where the run does not determine it)."""
    params = ds.train[0].meta.params
    rigid = rigid_mass(params)
    ratios = []
    for run in (*ds.train, *ds.test, *ds.audit):
        mass = inverse_dynamics_mass(run)
        ratios.append(None if mass is None else mass / rigid)
    return {"seed": ds.seed, "axis": ds.axis, "withheld": list(ds.withheld), "rigid_mass_kg": rigid,
            "table_mass_kg": params.table.mass, "ratios": ratios}


def _spec(text):
    seed, withheld, axis = dev_spec(text)
    return seed, withheld, "drakecreep", axis


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("datasets", nargs="+", type=_spec, metavar="SEED:WITHHELD:AXIS")
    args = ap.parse_args(argv)
    for ds in B.generate_datasets(args.datasets):
        print(json.dumps(spread(ds)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
