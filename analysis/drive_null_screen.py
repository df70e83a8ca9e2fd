"""Test-rig nulls of the ``drakecreep`` kind: how large a candidate's pooled held-out shrink gets, in run-to-run
nulls, where the runs carry no effect (a screen of study 3bs's factor of 20, docs/gap_benchmark.md; not a
benchmark row).

Each seed draws a truth that is the test rig (``quick_replay_params(preset("paper"))``) with its three default
uncertain values moved (seal force 2-8 N, viscous 150-280 N s/m, nut preload 0.07-0.11 N m), six 0.5 s
out-and-back runs at 15-45 mm/s from random places on the screw, 2 N of noise on ``u``; the even runs train, the
odd are held out, the params file is the test rig's. One JSON line per seed: the claims, the null, and each fitted
candidate's training gain, Student test and pooled shrink / null. Run from the repository root:

    PYTHONPATH=. python analysis/drive_null_screen.py --seeds 1-6
"""

import argparse
import json

import numpy as np

from drakecreep.gap.drake_replay import quick_replay_params, simulated_runs
from drakecreep.gap.drive_fit import diagnose_drive
from drakecreep.params import preset, with_value
from study_cli import seed_list

RANGES = (("table.seal_force", 2.0, 8.0), ("friction.viscous", 150.0, 280.0), ("nut.preload_torque", 0.07, 0.11))


def screen(seed):
    """The JSON-ready screen of one seed."""
    rng = np.random.default_rng(1000 + seed)
    rig = quick_replay_params(preset("paper"))
    truth = rig
    for path, lo, hi in RANGES:
        truth = with_value(truth, path, float(rng.uniform(lo, hi)))
    speeds = tuple(float(v) for v in rng.uniform(0.015, 0.045, 6))
    origins = tuple(float(v) for v in rng.uniform(0, 0.005, 6))
    runs = simulated_runs(truth, speeds, declared=rig, n=500, noise=2.0, seed=seed * 10, origins=origins)
    res = diagnose_drive(runs[0::2], runs[1::2])
    out = {"seed": seed, "claimed": list(res.claimed), "null": res.replay_null, "candidates": []}
    for c in res.candidates:
        if not c.test_errors:
            continue
        rt = c.replay  # the diagnosis's own pooled test, against its run-to-run null
        out["candidates"].append({"name": c.name, "train_gain": c.train_gain, "student": bool(c.gain > c.threshold),
                                  "pooled": rt["passes"],
                                  "shrink_in_nulls": rt["shrink"] / res.replay_null if res.replay_null else None})
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=seed_list, default=range(1, 7), help="seeds or ranges, e.g. 1-6 (default)")
    args = ap.parse_args()
    for seed in args.seeds:
        print(json.dumps(screen(seed)), flush=True)


if __name__ == "__main__":
    main()
