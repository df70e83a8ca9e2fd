"""Development-seed study: how much does the nominal model's held-out error move with the training runs alone?

A candidate that passes the claim's significance test can still explain only a sliver of the gap: a flexible
candidate absorbs a small, systematic share of what the nominal lacks against a richer truth, the same in every
held-out run, so no test of significance removes it (docs/gap_benchmark.md, 3o). The ``drakecreep`` kind's
diagnosis (:mod:`drakecreep.gap.drive_fit`) asks for a second thing: the held-out replay must shrink by more
than it changes when the *nominal* is refitted with each training run left out, its run-to-run null.

This study measures that null for the ``p_p_cascade`` diagnosis's nominal, on the datasets of a development
benchmark run: the nominal identified as ``diagnose_drake`` does (``auto`` friction law, the equal-effort refit),
its values with each training run left out (:attr:`drakecreep.gap.identify.Identified.jackknife`, one
Gauss-Newton step), the held-out runs replayed with each, and ``floor = max_k |mean_runs ln(e_k / e)|`` on the
plain error and with each run's own friction level (since a23d548 the product's
:func:`drakecreep.gap.drake_diagnosis.training_run_null`, which this script calls). The score sets it beside each
candidate's held-out log ratio in the benchmark rows.

Run (development rows from ``analysis/bench_gap_benchmark.py --seeds dev``)::

    PYTHONPATH=. python analysis/nominal_jackknife_floor.py dev_a.json dev_b.json --shard 0/2 --out f0.json &
    PYTHONPATH=. python analysis/nominal_jackknife_floor.py dev_a.json dev_b.json --shard 1/2 --out f1.json &
    wait; PYTHONPATH=. python analysis/nominal_jackknife_floor.py dev_a.json dev_b.json --score f0.json f1.json
"""

import argparse
import json

from drakecreep.files import write_text
from drakecreep.gap import benchmark as B
from drakecreep.gap.drake_diagnosis import NOMINAL_FRICTION, _refit, training_run_null
from drakecreep.gap.drake_effects import score_parameters
from drakecreep.gap.identify import identify


def floors(ds, max_nfev=6):
    """``(plain floor, level floor)`` of a dataset's nominal (module docstring)."""
    fits = {law: identify(ds.train, NOMINAL_FRICTION[law], max_nfev=max_nfev) for law in NOMINAL_FRICTION}
    first = min(fits.values(), key=lambda f: f.cost)
    nominal = _refit(ds.train, first, first.fitted, max_nfev)
    return list(training_run_null(ds.test, nominal, score_parameters(ds.test, nominal.parameters)[0]))


def _rows(paths):
    rows = []
    for p in paths:
        rows += json.load(open(p))["datasets"]
    return sorted(rows, key=lambda r: r["seed"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("rows", nargs="+", help="benchmark JSON files (development seeds)")
    ap.add_argument("--shard", default="0/1")
    ap.add_argument("--out", default="floors.json")
    ap.add_argument("--score", nargs="+", metavar="JSON")
    args = ap.parse_args()
    rows = _rows(args.rows)
    if args.score:
        fl = {}
        for p in args.score:
            fl.update({int(k): v for k, v in json.load(open(p)).items()})
        for r in rows:
            if r["seed"] not in fl:
                continue
            f = fl[r["seed"]]
            cands = [(c["effect"], round(c["log_error_ratio"], 3), round(c["level_log_error_ratio"], 3), c["passes"])
                     for c in r["ranking"] if not c["screened_out"] and c["log_error_ratio"] is not None
                     and c["log_error_ratio"] > 0]
            print(f"{r['seed']} {r['category']:14s} {str(r['expected']):20s} floor plain {f[0]:.3f} level {f[1]:.3f}"
                  f"  claimed {r['claimed']}")
            for c in cands:
                print(f"      {c}")
        return
    i, n = (int(x) for x in args.shard.split("/"))
    out = {}
    for r in rows[i::n]:
        ds = B.generate_dataset(r["seed"], withheld=tuple(r["withheld"]), kind=r["kind"], axis=r["axis"])
        out[r["seed"]] = floors(ds)
        print(r["seed"], out[r["seed"]], flush=True)
        write_text(args.out, json.dumps(out))


if __name__ == "__main__":
    main()
