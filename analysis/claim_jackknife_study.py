"""Development-seed study: does a candidate's held-out gain survive leaving one training run out?

The claim rule (:mod:`drakecreep.gap.drake_diagnosis`, 3) asks for a held-out log error ratio above
``t_(1-ALPHA, n-1)`` paired standard errors over the held-out runs. That spread is the held-out runs'; it does
not see how much the gain depends on which runs the model was *fitted* on. On effect-free data a flexible candidate
can fit a tiny, consistent share of what the nominal model lacks (held-out run 9: two nulls claimed with log
ratios of 0.006 and 0.02, docs/gap_benchmark.md 3n).

For every candidate fitted in closed loop, and for its reference, this study takes the fitted values with each
training run left out (:attr:`drakecreep.gap.identify.Identified.jackknife`: one Gauss-Newton step from the fit's
own Jacobian, no refit), replays the held-out runs with each, and computes the gain per left-out run: ``g_k``, the
mean held-out log error ratio of the candidate's ``k``-th values against the reference's ``k``-th values (on the
plain error and with each run's own friction level). Its jackknife standard error
``se_J = sqrt((n - 1) / n sum (g_k - mean g)^2)`` is the training runs' share of the gain's uncertainty. A rule
that adds it to the held-out spread asks for ``lr > t sqrt(se^2 + se_J^2)``: the score prints, per dataset
category, which candidates pass now and which would pass so.

Development seeds only (nothing here is a held-out figure). Run (rows are written as they come)::

    PYTHONPATH=. python analysis/claim_jackknife_study.py --shard 0/2 --json a.json &
    PYTHONPATH=. python analysis/claim_jackknife_study.py --shard 1/2 --json b.json &
    wait; PYTHONPATH=. python analysis/claim_jackknife_study.py --score a.json b.json

Session 29's rows (9 of the 16 datasets): ``analysis/claim_jackknife_dev.json``; what they say:
docs/gap_benchmark.md, 3o.
"""

import json
import math
import sys

import numpy as np
from scipy import stats
from study_cli import shard_main

from drakecreep.files import write_text
from drakecreep.gap import benchmark as B
from drakecreep.gap.claims import ALPHA
from drakecreep.gap.drake_diagnosis import diagnose_drake, paired_log_ratio
from drakecreep.gap.drake_effects import score_parameters

#: (seed, withheld, axis): eight effect-free datasets and the library effects whose held-out gains are small
#: (the ones such a rule could cost), all on development seeds
SPECS = ([(33000 + i, (), "rigid" if i % 2 else "flexible") for i in range(8)]
         + [(33100 + i, ("lead_error",), a) for i, a in enumerate(("rigid", "flexible"))]
         + [(33200 + i, ("control_delay",), a) for i, a in enumerate(("rigid", "flexible"))]
         + [(33300 + i, ("load_friction",), a) for i, a in enumerate(("flexible", "rigid"))]
         + [(33400 + i, ("backlash",), a) for i, a in enumerate(("rigid", "flexible"))])


def _jackknife_errors(test, model_parameters, identified, flexible, delay):
    """Held-out errors with each left-out training run's values (None when the fit has none)."""
    if identified is None or not identified.jackknife:
        return None
    return [score_parameters(test, dict(model_parameters, **values), flexible=flexible, delay=delay)[0]
            for values in identified.jackknife]


def _spread(reference, candidate, key):
    """Jackknife standard error of the per-left-out-run gain (0 when either side has no jackknife)."""
    if reference is None or candidate is None:
        return 0.0, []
    g = [paired_log_ratio(r, c, key)[0] for r, c in zip(reference, candidate)]
    n = len(g)
    return float(math.sqrt((n - 1) / n * sum((x - np.mean(g)) ** 2 for x in g))), g


def study(shard, n_shards, path):
    rows = []
    for seed, withheld, axis in SPECS[shard::n_shards]:
        ds = B.generate_dataset(seed, withheld=withheld, kind="p_p_cascade", axis=axis)
        diag = diagnose_drake(ds.train, ds.test, friction="auto")
        nom = diag.nominal
        ref = _jackknife_errors(ds.test, nom.parameters, nom, nom.flexible, nom.delay)
        t = float(stats.t.ppf(1.0 - ALPHA, len(ds.test) - 1))
        cands = []
        for r in diag.ranking:
            if r.screened_out:
                continue
            own = r.reference_errors is not None  # (its own reference has no jackknife here: reported, not used)
            fit = r.fit
            cand = _jackknife_errors(ds.test, fit.parameters, fit.identified, fit.flexible, fit.delay)
            se_j, g = _spread(None if own else ref, cand, "force")
            se_jl, gl = _spread(None if own else ref, cand, "force_level")
            cands.append({"effect": r.name, "lr": r.log_ratio, "lr_se": r.log_ratio_se, "lv": r.level_log_ratio,
                          "lv_se": r.level_log_ratio_se, "passes": r.passes, "se_J": se_j, "se_J_level": se_jl,
                          "g": g, "g_level": gl, "own_reference": own})
        rows.append({"seed": seed, "withheld": list(withheld), "axis": axis, "snr": ds.snr, "t": t,
                     "claimed": list(diag.claimed), "candidates": cands})
        write_text(path, json.dumps(rows, indent=1))
        print(seed, withheld, axis, "snr", ds.snr, "claimed", diag.claimed,
              [(c["effect"], round(c["lr"], 4), round(c["lr_se"], 4), round(c["se_J"], 4), c["passes"])
               for c in cands], flush=True)


def _would_pass(c, t):
    plain = c["lr"] > t * math.hypot(c["lr_se"], c["se_J"])
    level = c["lv"] != c["lv"] or c["lv"] > t * math.hypot(c["lv_se"], c["se_J_level"])
    return bool(c["passes"] and plain and level)


def score(paths):
    rows = []
    for p in paths:
        data = json.load(open(p))
        rows += data["rows"] if isinstance(data, dict) else data  # (a kept file has a note beside its rows)
    for r in rows:
        now = [c["effect"] for c in r["candidates"] if c["passes"]]
        then = [c["effect"] for c in r["candidates"] if _would_pass(c, r["t"])]
        label = ",".join(r["withheld"]) or "null"
        print(f"{r['seed']} {label:16s} {r['axis']:8s} SNR {r['snr'] or 0:5.2f}  passes now: {now}  "
              f"with the training spread: {then}")
        for c in r["candidates"]:
            if c["passes"]:
                print(f"    {c['effect']:20s} lr {c['lr']:+.4f} se {c['lr_se']:.4f} se_J {c['se_J']:.4f}  "
                      f"level {c['lv']:+.4f} se {c['lv_se']:.4f} se_J {c['se_J_level']:.4f}")


def main(argv=None):
    return shard_main(__doc__.splitlines()[0], study, score, argv)


if __name__ == "__main__":
    sys.exit(main())
