"""Development-seed study of the closed-loop claim rule: the held-out force error as is (``plain``), with each
held-out run's own friction level (``level``, :func:`drakecreep.gap.drake_replay.drake_replay_errors`'s
``force_level``), or both.

Every dataset of the screen study's development list (:mod:`analysis.screen_study`: development seeds only, this
study chose :data:`drakecreep.gap.drake_diagnosis.CLAIM_RULE`) is diagnosed as the benchmark does
(``benchmark.evaluate``, no audit); each ranked candidate's two log error ratios are kept with the claim bar.
The score counts, per rule and dataset category, the datasets whose first passing candidate (in the ranking's
order, as the greedy step takes them) is the withheld effect's, another, or none.

Run (about 50 min on two free cores; rows are written as they come, so a partial run can be scored)::

    PYTHONPATH=. python analysis/claim_study.py --shard 0/2 --json a.json &
    PYTHONPATH=. python analysis/claim_study.py --shard 1/2 --json b.json &
    wait; PYTHONPATH=. python analysis/claim_study.py --score a.json b.json
"""

import argparse
import collections
import json

from scipy import stats

from drakecreep.files import write_text
from drakecreep.gap import benchmark as B
from drakecreep.gap.claims import ALPHA

RULES = ("plain", "level", "both")


def _specs():
    specs = B.benchmark_specs(B.DEV_SEEDS, n_per_effect=2, tries=2, n_null=8, n_ool=3)
    # the datasets without a library answer first: a partial run already counts false claims
    return sorted(specs, key=lambda s: B.category_of(s[2], s[1]) == "library")


def study(shard, n_shards, path):
    """Diagnose this shard's datasets; rows to ``path`` as they come."""
    rows = []
    for ds in B.generate_datasets(_specs()[shard::n_shards]):
        row = B.evaluate(ds, audit=False)
        row["bar"] = float(stats.t.ppf(1.0 - ALPHA, len(ds.test) - 1))
        rows.append(row)
        write_text(path, json.dumps(rows, indent=1))
        print(ds.seed, ds.withheld, row["claimed"], flush=True)


def _passes(r, bar, rule):
    if r["screened_out"] or r["log_error_ratio"] is None:
        return False
    plain = r["log_error_ratio"] > bar * r["log_error_ratio_standard_error"]
    lv, lv_se = r["level_log_error_ratio"], r["level_log_error_ratio_standard_error"]
    level = True if lv is None or lv != lv else lv > bar * lv_se
    return {"plain": plain, "level": level, "both": plain and level}[rule]


def score(paths):
    """Print each dataset's passing candidates per rule and the counts of the module docstring."""
    rows = [r for p in paths for r in json.load(open(p))]
    counts = collections.defaultdict(collections.Counter)
    for r in sorted(rows, key=lambda r: (r["category"], r["withheld"])):
        first = {}
        for rule in RULES:
            passing = [c["effect"] for c in r["ranking"] if _passes(c, r["bar"], rule)]
            first[rule] = passing[0] if passing else None
            verdict = ("none" if first[rule] is None else "right" if first[rule] == r["expected"] else "other")
            counts[(r["category"], rule)][verdict] += 1
        lines = [f"{c['effect']} {c['log_error_ratio']:+.3f}/{r['bar'] * c['log_error_ratio_standard_error']:.3f} "
                 f"level {c['level_log_error_ratio']:+.3f}/{r['bar'] * c['level_log_error_ratio_standard_error']:.3f}"
                 for c in r["ranking"] if not c["screened_out"] and c["log_error_ratio"] is not None
                 and c["effect"] != "control_delay" or (c["effect"] == "control_delay" and c["log_error_ratio"])]
        print(r["seed"], r["category"], r["withheld"], "expected", r["expected"], "first", first)
        for line in lines:
            print("    ", line)
    print()
    for (cat, rule), c in sorted(counts.items()):
        print(f"{cat:15s} {rule:6s} right {c['right']:2d} other {c['other']:2d} none {c['none']:2d}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--shard", default="0/1", help="k/n: every n-th dataset from the k-th")
    ap.add_argument("--json", default="claim_study.json", help="rows written here as they come")
    ap.add_argument("--score", nargs="+", metavar="JSON", help="score earlier rows instead of running")
    a = ap.parse_args()
    if a.score:
        score(a.score)
        return
    k, n = (int(v) for v in a.shard.split("/"))
    study(k, n, a.json)


if __name__ == "__main__":
    main()
