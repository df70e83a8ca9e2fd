"""Development-seed study: should a candidate be held to the training-run null of its own model?

The training-run null (:func:`drakecreep.gap.drake_diagnosis.training_run_null`) is how far the *nominal's*
held-out log error moves with one training run left out of its fit. When the nominal lacks an effect that only
some training runs excite (a drive that saturates above a force one run reaches), leaving that run out moves the
nominal a lot, because the nominal absorbs the effect elsewhere (the saturation as mass): the null is the
effect's own size. Held-out run 31 missed a drive saturation (SNR 30) whose plain log ratio 0.35 was positive in
every held-out run against a null of 1.61 (level: 0.20 against 0.04); run 39 one at SNR 58, 0.80 against 1.29.

The candidate's own model, if it is the missing effect, should not move so: its fit has nothing left to absorb.
On effect-free data a candidate is a small perturbation of the nominal, so its own moves should be the
nominal's and the null's guard against a candidate that absorbs a systematic share of what the nominal lacks
(docs/gap_benchmark.md, 3s) should stay. This study asks whether that holds: the rows carry each fitted
candidate's own moves (``own_training_run_moves``, :func:`drakecreep.gap.drake_diagnosis.candidate_moves`), and the
first claim is recounted (``analysis/claim_rule_recount.py``, the product's rule before this study,
``before_3bc``) with each candidate's null taken as

* ``nominal``: the nominal's (the product; must give the stored first claims back);
* ``own``: the candidate's own model's, for a candidate whose fit refits the nominal friction with its own
  parameters (its jackknife then moves what the nominal's does); the nominal's for the others (the axial mode
  holds the friction fixed, the control delay is searched, not fitted);
* ``smaller``: the smaller of the two, plain and level each.

Development seeds only (nothing here is a held-out figure). The datasets (:data:`SPECS`): drive saturations of
development seeds, two of them heavily saturated (seeds of session 29, docs 3o), asymmetric frictions, the
effect-free datasets on which candidates absorbed a systematic share before (33000-33007, docs 3o), and effects
outside the library. Run (rows are written after every dataset)::

    PYTHONPATH=. python analysis/candidate_null_study.py --shard 0/2 --json a.json &
    PYTHONPATH=. python analysis/candidate_null_study.py --shard 1/2 --json b.json &
    wait; PYTHONPATH=. python analysis/candidate_null_study.py --score a.json b.json
"""

import json
import sys

import claim_rule_recount
from study_cli import shard_main

from drakecreep.files import write_text
from drakecreep.gap import benchmark as B
from drakecreep.gap.drake_diagnosis import _refits, null_of_moves

#: (seed, withheld, axis), development seeds: drive saturations first (the heavily saturated ones of docs 3o:
#: 32004, 11009), asymmetric frictions, effect-free datasets, effects outside the library
SPECS = ([(32004, ("drive_saturation",), "flexible"), (11009, ("drive_saturation",), "rigid"),
          (32001, ("drive_saturation",), "rigid"), (32002, ("drive_saturation",), "flexible"),
          (32003, ("drive_saturation",), "rigid"), (2001, ("asymmetric_friction",), "rigid"),
          (2003, ("asymmetric_friction",), "flexible")]
         + [(33000 + i, (), "rigid" if i % 2 else "flexible") for i in range(8)]
         + [(12000, ("cable_carrier",), "flexible"), (33400, ("backlash",), "rigid"),
            (33401, ("backlash",), "flexible")])


def _own(row, e):
    """The candidate's own null, where its fit refits the nominal friction beside its own parameters (its
    jackknife then moves what the nominal's does); else the nominal's. The axial mode's fit holds the friction
    fixed (its own moves, about 0, move only the mode), and the control delay is searched, not fitted."""
    if e.get("own_training_run_moves") and _refits(e["effect"]):
        return null_of_moves(e["own_training_run_moves"])
    return row["training_run_null"]


#: variant -> each candidate's (plain, level) null from its row and ranking entry
VARIANTS = {
    "nominal": lambda row, e: row["training_run_null"],
    "own": _own,
    "smaller": lambda row, e: tuple(min(a, b) for a, b in zip(row["training_run_null"], _own(row, e))),
}


def study(shard, n_shards, path):
    """Diagnose this shard's :data:`SPECS` (benchmark rows, no audit), writing ``{"datasets": rows}`` to ``path``
    after each."""
    rows = []
    for seed, withheld, axis in SPECS[shard::n_shards]:
        ds = B.generate_dataset(seed, withheld=withheld, kind="p_p_cascade", axis=axis)
        row = B.evaluate(ds, audit=False)
        rows.append(row)
        write_text(path, json.dumps({"datasets": rows}, indent=1))
        own = {e["effect"]: null_of_moves(e["own_training_run_moves"]) for e in row["ranking"]
               if e.get("own_training_run_moves")}
        print(seed, withheld, axis, f"SNR {ds.snr or 0:.1f}", "claimed", row["claimed"], "null",
              [round(v, 3) for v in row["training_run_null"]], "own",
              {k: [round(x, 3) for x in v] for k, v in own.items()}, f"{row['seconds']:.0f} s", flush=True)


def score(paths):
    """Print the recount per variant and each row's first claim under each."""
    rows = sorted((r for p in paths for r in json.load(open(p))["datasets"]), key=lambda r: r["seed"])
    res = {name: claim_rule_recount.recount(rows, rules=("before_3bc",), null_of=f)["before_3bc"]
           for name, f in VARIANTS.items()}
    product = claim_rule_recount.recount(rows, rules=("current",))["current"]
    same = sum(product["first"][r["seed"]] == res["smaller"]["first"][r["seed"]] for r in rows)
    print(f"the product's rule (the smaller null where the nominal's fails it) gives the first claim of `smaller` "
          f"on {same} of {len(rows)}")
    agree = sum(res["nominal"]["first"][r["seed"]] == claim_rule_recount.stored_first(r) for r in rows)
    print(f"{len(rows)} rows; the recount with the nominal's null gives the stored first claim on {agree}")
    for name, x in res.items():
        print(f"  {name:8s} {claim_rule_recount.score_line(x)}")
    for r in rows:
        firsts = "  ".join(f"{name} {res[name]['first'][r['seed']] or '-':20s}" for name in VARIANTS)
        print(f"    {r['seed']} {r['category']:15s} {r['expected'] or '-':20s} {r['axis']:8s} "
              f"SNR {r['snr'] or 0:5.1f}  {firsts}  null {r['training_run_null'][0]:.3f}/"
              f"{r['training_run_null'][1]:.3f}")
        for e in r["ranking"]:
            if e.get("screened_out") or not e.get("run_log_error_ratios"):
                continue
            own = VARIANTS["own"](r, e)
            print(f"        {e['effect']:20s} lr {e['log_error_ratio']:+.3f} level {e['level_log_error_ratio']:+.3f}"
                  f"  passes {e['passes']!s:5s}  own null {own[0]:.3f}/{own[1]:.3f}")


def main(argv=None):
    return shard_main(__doc__.splitlines()[0], study, score, argv)


if __name__ == "__main__":
    sys.exit(main())
