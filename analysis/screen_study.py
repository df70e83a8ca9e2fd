"""Development-seed study of two parts of the screen (``drakecreep.gap.screen``): the constancy test and the
per-run friction level.

For every dataset of a small benchmark list (development seeds only: this study chose which candidates the
constancy test applies to, and whether held-out runs get their own friction level), every screened candidate is
run through ``screen_effect`` against the IDIM-LS nominal, twice: with each held-out run's own friction level
(``run_level``, the default) and without; the constancy test is computed for every candidate (whatever its
``run_constancy`` flag). Prints, per dataset, the candidates that pass the held-out screen or are the withheld
effect's, with the constancy test's p-value, then three counts:

* the withheld effect's own candidate rejected by the constancy test (p < ALPHA), per candidate;
* the friction drift passing the held-out screen and rejected by the constancy test, per dataset category;
* candidates passing the held-out screen with and without the per-run level: the withheld effect's own and the
  others, per dataset category.

Run (about 3 min on two free cores)::

    PYTHONPATH=. python analysis/screen_study.py --shard 0/2 --json a.json &
    PYTHONPATH=. python analysis/screen_study.py --shard 1/2 --json b.json &
    wait; PYTHONPATH=. python analysis/screen_study.py --score a.json b.json
"""

import argparse
import collections
import dataclasses
import json

from drakecreep.files import write_text
from drakecreep.gap import benchmark as B
from drakecreep.gap.claims import ALPHA
from drakecreep.gap.drake_effects import DRAKE_EFFECTS
from drakecreep.gap.identify import idim_start
from drakecreep.gap.screen import NOT_SCREENED, screen_effect


def _held_out(sc):
    return bool(sc.inside and sc.log_ratio > sc.log_ratio_se)


def study(shard, n_shards, path):
    """Screen every candidate, the constancy test on, on this shard's datasets; rows to ``path`` as they come."""
    specs = B.benchmark_specs(B.DEV_SEEDS, n_per_effect=2, tries=2, n_null=8, n_ool=3)[shard::n_shards]
    rows = []
    for ds in B.generate_datasets(specs):
        nominal = idim_start(ds.train).parameters
        row = {"seed": ds.seed, "withheld": list(ds.withheld), "category": B.category_of("p_p_cascade", ds.withheld),
               "snr": ds.snr, "candidates": {}}
        for name, effect in DRAKE_EFFECTS.items():
            if name in NOT_SCREENED:
                continue
            flagged = dataclasses.replace(effect, run_constancy=True)
            sc = screen_effect(flagged, ds.train, ds.test, nominal)
            flat = screen_effect(flagged, ds.train, ds.test, nominal, run_level=False)
            c = sc.constancy
            # the held-out part of the screen alone (the constancy flag also decides ``passes``)
            row["candidates"][name] = {"held_out_passes": _held_out(sc), "log_ratio": sc.log_ratio,
                                       "log_ratio_se": sc.log_ratio_se,
                                       "held_out_passes_without_level": _held_out(flat),
                                       "log_ratio_without_level": flat.log_ratio,
                                       "chi2": c.chi2, "dof": c.dof, "p_value": c.p_value, "per_run": list(c.per_run)}
        rows.append(row)
        write_text(path, json.dumps(rows, indent=1))
        print(ds.seed, ds.withheld, flush=True)


def score(paths):
    """Print the per-dataset lines and the two counts of the module docstring."""
    rows = [r for p in paths for r in json.load(open(p))]
    rejected = collections.defaultdict(lambda: [0, 0])
    drift = collections.defaultdict(lambda: [0, 0, 0])
    level = collections.defaultdict(lambda: [0, 0, 0])
    for r in sorted(rows, key=lambda r: (r["category"], r["withheld"])):
        w = r["withheld"][0] if r["withheld"] else "null"
        expected = B.EXPECTED.get(w)
        parts = [f"{'*' if n == expected else ''}{n}{'' if c['held_out_passes'] else ' (fails)'} p={c['p_value']:.2g}"
                 for n, c in r["candidates"].items() if c["held_out_passes"] or n == expected]
        snr = "-" if r["snr"] is None else f"{r['snr']:.1f}"
        print(f"{r['category']:15s} {w:20s} SNR {snr:5s} | " + "; ".join(parts))
        if expected in r["candidates"]:
            rejected[expected][1] += 1
            rejected[expected][0] += r["candidates"][expected]["p_value"] < ALPHA
        for n, c in r["candidates"].items():
            key = (r["category"], "withheld effect's" if n == expected else "other")
            level[key][0] += c["held_out_passes"]
            level[key][1] += c["held_out_passes_without_level"]
            level[key][2] += 1
        d = r["candidates"]["thermal_drift"]
        drift[r["category"]][2] += 1
        if d["held_out_passes"]:
            drift[r["category"]][1] += 1
            drift[r["category"]][0] += d["p_value"] < ALPHA
    print(f"\n{len(rows)} datasets. The withheld effect's candidate rejected by the constancy test (p < {ALPHA}):")
    for n, (k, m) in rejected.items():
        print(f"  {n:20s} {k} of {m}")
    print("The friction drift: rejected / passing the held-out screen / datasets:")
    for n, (k, m, t) in drift.items():
        print(f"  {n:15s} {k} / {m} / {t}")
    print("Candidates passing the held-out screen, with each run's own friction level / without / candidates:")
    for (cat, who), (a, b, t) in sorted(level.items()):
        print(f"  {cat:15s} {who:18s} {a} / {b} / {t}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--shard", default="0/1", help="K/N: this process's share of the datasets (default 0/1)")
    ap.add_argument("--json", default="screen_constancy.json", help="rows, written after every dataset")
    ap.add_argument("--score", nargs="+", metavar="FILE", help="only print the figures of these row files")
    a = ap.parse_args()
    if a.score:
        score(a.score)
        return
    k, n = (int(x) for x in a.shard.split("/"))
    study(k, n, a.json)
    score([a.json])


if __name__ == "__main__":
    main()
