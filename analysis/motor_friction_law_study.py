"""Why a Coulomb law can replay a LuGre truth better: the motor side's friction law (docs/gap_benchmark.md, 3cd).

The benchmark's ``drakecreep``-kind truth has LuGre friction on the table and a smooth Coulomb (``tanh``) force on
the motor side; its declared params file (:func:`drakecreep.gap.benchmark.declared_params`) has one friction law
for both, so the motor side's share becomes the nut's preload drag on the screw with the table's LuGre law. This
script takes one spent row of a held-out run (its dataset regenerated from its seed), writes the row's final fit
and its claimed lead error into the declared params file, and replays the audit runs with the friction law as
fitted, switched to Coulomb, with the nut's friction on the table, and without the nut's preload: the mean audit
force error of each.

Run: ``PYTHONPATH=. python analysis/motor_friction_law_study.py ROWS.json [ROWS.json ...] --seed SEED``
"""

import argparse
import sys

import numpy as np

from drakecreep.gap.benchmark import generate_dataset
from drakecreep.gap.drake_replay import drake_replay_errors, replay_drakecreep
from drakecreep.params import with_value
from study_cli import read_rows


def audit_error(runs, params):
    """RMS over ``runs`` of the closed-loop replay's relative force error [%]."""
    return float(np.sqrt(np.mean([drake_replay_errors(replay_drakecreep(r, params))["force"] ** 2 for r in runs])))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rows", nargs="+", help="rows files of analysis/bench_gap_benchmark.py (drakecreep kind)")
    ap.add_argument("--seed", type=int, required=True, help="the row's dataset seed")
    args = ap.parse_args(argv)
    keys = ("seed", "kind", "withheld", "axis")
    rows = [r for f in args.rows for r in read_rows(ap, "rows", f, keys=keys)["datasets"] if r["seed"] == args.seed]
    if not rows or rows[0]["kind"] != "drakecreep" or not rows[0].get("claimed_model"):
        print(f"--seed: got {args.seed}; allowed: the seed of a drakecreep-kind row with a fitted model in "
              + ", ".join(args.rows), file=sys.stderr)
        return 2
    row = rows[0]
    ds = generate_dataset(row["seed"], withheld=tuple(row["withheld"]), kind="drakecreep", axis=row["axis"])
    params = ds.train[0].meta.params
    model = row["claimed_model"]
    values = dict(model["fitted"])
    for name, fields in model["effects"].items():
        if not name.startswith("law_"):
            values.update(fields)
    for path, value in values.items():
        params = with_value(params, path, value)
    print(f"{row['seed']} ({row['axis']}, withheld {', '.join(row['withheld'])}): final fit and claims other than a "
          f"law switch; law {params.friction.law}, the nut's friction on the {params.friction.nut_friction_on}, "
          f"motor side's share of the truth's Coulomb friction {ds.truth.motor_friction_share:.2f}")
    variants = {f"as fitted ({params.friction.law})": params,
                "friction law coulomb": with_value(params, "friction.law", "coulomb"),
                "the nut's friction on the table": with_value(params, "friction.nut_friction_on", "table"),
                "no nut preload (no friction on the screw)": with_value(params, "nut.preload_torque", 0.0)}
    for label, p in variants.items():
        print(f"  {label:45s} audit force error {audit_error(ds.audit, p):6.2f} %", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
