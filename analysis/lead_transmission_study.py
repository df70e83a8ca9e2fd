"""Development check of the lead error decided on the screw's transmission (``drakecreep`` kind; docs 3bu).

Runs with a linear scale carry a lead error in ``x_table - x_motor`` (micrometres) where the drive force carries a
few newtons of its push. Since session 70 :func:`drakecreep.gap.drive_fit.diagnose_drive` fits the lead error on
that transmission and decides it there (:func:`~drakecreep.gap.drive_fit._held_out_on_scale`). This script
diagnoses benchmark datasets of the ``drakecreep`` kind (:func:`drakecreep.gap.benchmark.generate_dataset`,
development seeds only) with the lead error as the only candidate and the default uncertain fields, and writes
one JSON row per dataset: the truth's lead error (if any), what was fitted, the decision and its reason. The
question it answers: is a lead error claimed where the truth has one, and never where it has none (nulls, and
the other effects of the truth: the rule must not read their windup as a kinematic error)?

Usage: ``PYTHONPATH=. python analysis/lead_transmission_study.py --json rows.json SEED:WITHHELD:AXIS ...``
(``WITHHELD`` ``null`` or an effect of :data:`drakecreep.gap.truth.LIBRARY_EFFECTS` and the others the truth
draws); the rows are appended as each dataset ends. The specs of docs 3bu are ``--plan``.
"""

import argparse
import json
import math
import os
import sys
import time

from drakecreep.gap.benchmark import generate_dataset
from drakecreep.gap.drive_fit import diagnose_drive

#: The development datasets of docs 3bu, declared before any was diagnosed: seeds 3_700_000 onwards (a block no
#: study used), per row ``(seed offset, withheld, axis)``.
PLAN = ([(i, "lead_error", ("rigid", "flexible")[i % 2]) for i in range(5)]
        + [(10 + i, "null", ("rigid", "flexible")[i % 2]) for i in range(3)]
        + [(20, "cogging", "rigid"), (21, "time_ripple", "flexible")])
PLAN_SEED = 3_700_000
#: The first seed of any held-out block (docs/gap_benchmark.md: 7_000_000 onwards): refused here.
FIRST_HELDOUT = 7_000_000


def _spec(text):
    seed, withheld, axis = text.split(":")
    seed = int(seed)
    if seed >= FIRST_HELDOUT:
        raise SystemExit(f"seed: got {seed}; allowed: a development seed below 7000000")
    return seed, withheld, axis


def study(seed, withheld, axis):
    """One row: the dataset's truth, the lead-error candidate's fit and its decision."""
    ds = generate_dataset(seed, withheld=() if withheld == "null" else (withheld,), kind="drakecreep", axis=axis)
    t0 = time.perf_counter()
    res = diagnose_drive(ds.train, ds.test, effects=("lead_error",))
    (lead,) = [c for c in res.candidates if c.name == "lead_error"] or [None]
    truth = ds.truth.effects.get("lead_error")
    row = {"seed": seed, "withheld": withheld, "axis": axis, "snr": ds.snr, "truth": ds.truth.effects,
           "lead": ds.train[0].meta.params.screw.lead, "claimed": list(res.claimed),
           "values": None if lead is None else lead.values, "reason": None if lead is None else lead.reason,
           "train_gain": None if lead is None else lead.train_gain,
           "transmission": None if lead is None else (lead.replay or {}).get("transmission"),
           "force_gain": None if lead is None else lead.gain, "replay_null": res.replay_null,
           "transmission_null": res.transmission_null, "seconds": time.perf_counter() - t0}
    if truth:
        row["true_amplitude_m"] = truth["amplitude_m"]
        row["true_h2_amplitude_m"] = truth["amplitude_m"] * truth["h2"]
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("specs", nargs="*", type=_spec, help="SEED:WITHHELD:AXIS")
    ap.add_argument("--plan", metavar="I/N", help="shard I of N of the declared plan (PLAN)")
    ap.add_argument("--json", required=True, help="rows are appended here (JSON lines)")
    args = ap.parse_args(argv)
    specs = list(args.specs)
    if args.plan:
        i, n = (int(v) for v in args.plan.split("/"))
        # the datasets without a lead error first, other effects before nulls (each takes 25-45 min): whether the
        # rule claims where it must not
        plan = sorted(PLAN, key=lambda spec: (spec[1] == "lead_error", spec[1] == "null"))
        specs += [(PLAN_SEED + k, w, a) for j, (k, w, a) in enumerate(plan) if j % n == i]
    done = set()
    if os.path.exists(args.json):
        with open(args.json) as f:
            done = {(r["seed"], r["withheld"], r["axis"]) for r in map(json.loads, f)}
    for spec in specs:
        if spec in done:
            continue
        row = study(*spec)
        with open(args.json, "a") as f:
            f.write(json.dumps(row, default=float) + "\n")
        v = row["values"] or {}
        print(f"{spec}: SNR {row['snr']:.1f}, claimed {row['claimed']}, fitted "
              f"{1e6 * v.get('disturbance.lead_error_amplitude', math.nan):.3g} um at "
              f"{1e3 * v.get('disturbance.lead_error_period', math.nan):.3g} mm "
              f"(+ {1e6 * v.get('disturbance.lead_error_2_amplitude', 0.0):.3g} um), truth "
              f"{row['truth'].get('lead_error')}; {row['reason']}; {row['seconds']:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
