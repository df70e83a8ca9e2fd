"""Which statistic decides a claim: Student's t on the held-out runs' log error ratios, or their exact sign-flip
permutation null?

The claim rule (:mod:`drakecreep.gap.drake_diagnosis`, 3) asks for a mean held-out log error ratio above
``t_(1-ALPHA, n-1)`` standard errors, on the plain error and with each run's own friction level. The runs of a
dataset differ in speed, so a real effect's share of the error, and the factor by which its model shrinks it,
differs from run to run: the per-run log ratios of a true effect are all positive but skewed (one slow run gains
much more), and their spread then keeps the t statistic under its bar. On held-out runs 11 and 12, six datasets
whose withheld effect ranked first were answered "nothing" with t between 1.7 and 2.0 (bar 2.13; lead error at
SNR 11.4 among them, docs/gap_benchmark.md 3r). The t quantile assumes normal per-run values; the sign-flip
permutation null does not: under "the candidate is useless", each run's log ratio is as likely negative as
positive, and the exact p value of the mean is the share of the ``2^n`` sign patterns whose mean is at least the
observed one (``scipy.stats.permutation_test``, ``permutation_type="samples"``). With five held-out runs its
smallest p is 1/32, so at ALPHA = 0.05 it asks for every run to improve, whatever the sizes; with four or fewer
runs it can never pass.

This script counts, on benchmark rows that carry each run's log ratios (``run_log_error_ratios``, written by
``analysis/bench_gap_benchmark.py`` since 3150c26), the datasets whose first passing candidate (in the ranking's
order, as the greedy step takes them) is the withheld effect's, another, or none, per rule:

* ``t``: the current rule (both errors over ``t_(1-ALPHA, n-1)`` standard errors);
* ``permutation``: both errors' exact sign-flip p value at most ALPHA;
* ``t_or_permutation``: either (its false-claim rate can reach twice ALPHA per candidate);
* ``+null``: and each mean log ratio above the row's training-run null (``training_run_null``, written by the
  benchmark since a23d548; added to the development rows by ``analysis/nominal_jackknife_floor.py``).

Session 31's development rows (22 datasets, code of 3150c26, the t rule alone deciding their claims):
``analysis/claim_statistic_dev.json``; what they say: docs/gap_benchmark.md, 3s. The product's rule since
6319b43 is ``t_or_permutation+null``.

Development seeds only: a rule chosen here is measured on held-out seeds afterwards. Run::

    PYTHONPATH=. python analysis/bench_gap_benchmark.py --seeds dev --n-per-effect 2 --n-null 6 --n-ool 1 \\
        --shard 0/2 --json a.json &   # and --shard 1/2 --json b.json
    PYTHONPATH=. python analysis/claim_statistic_study.py a.json b.json
"""

import argparse
import collections
import json

import numpy as np
from scipy import stats

from drakecreep.gap.claims import ALPHA, mean_and_standard_error, sign_flip_p

RULES = ("t", "permutation", "t_or_permutation", "t+null", "t_or_permutation+null")
KEYS = ("run_log_error_ratios", "run_level_log_error_ratios")


def t_passes(values, alpha=ALPHA):
    """Mean above ``t_(1-alpha, n-1)`` standard errors (the current rule, on one error)."""
    mean, se = mean_and_standard_error(values)
    return bool(mean > stats.t.ppf(1.0 - alpha, len(values) - 1) * se)


def passes(candidate, rule, alpha=ALPHA, null=(0.0, 0.0)):
    """Does a ranked candidate (a row's ranking entry) pass ``rule`` on both errors (on the plain one when it
    has no level error, as the diagnosis)?"""
    runs = [candidate.get(k) for k in KEYS]
    if runs[0] is None:
        return False
    runs = [r for r in runs if r is not None]  # (a replay without friction parameters has no level error)
    base, _, with_null = rule.partition("+")
    ok = []
    for values, floor in zip(runs, null):
        t_ok = t_passes(values, alpha)
        p_ok = sign_flip_p(values) <= alpha
        ok.append({"t": t_ok, "permutation": p_ok, "t_or_permutation": t_ok or p_ok}[base]
                  and (not with_null or float(np.mean(values)) > floor))
    return all(ok)


def first_passing(row, rule):
    """The first candidate of a row's ranking that passes ``rule``, or None."""
    null = row.get("training_run_null") or (0.0, 0.0)
    return next((c["effect"] for c in row["ranking"] if passes(c, rule, null=null)), None)


def score(rows):
    """``{rule: {category: Counter(right / wrong / none)}}`` and the rows where the rules disagree."""
    out = {rule: collections.defaultdict(collections.Counter) for rule in RULES}
    differ = []
    for row in rows:
        answers = {rule: first_passing(row, rule) for rule in RULES}
        for rule, a in answers.items():
            if row["category"] == "library":
                verdict = "none" if a is None else ("right" if a == row["expected"] else "wrong")
            else:
                verdict = "wrong" if a is not None else "right"
            out[rule][row["category"]][verdict] += 1
        if len(set(answers.values())) > 1:
            differ.append((row, answers))
    return out, differ


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json", nargs="+", help="benchmark JSON files whose rows carry run_log_error_ratios")
    args = ap.parse_args()
    rows = []
    for path in args.json:
        rows += [r for r in json.load(open(path))["datasets"]
                 if all(c.get("run_log_error_ratios") is not None or c["screened_out"] or c["gain"] is None
                        for c in r["ranking"])]
    rows = [r for r in rows if r["category"] != "library" or (r["snr"] or 0) >= 3]
    check = sum(first_passing(r, "t") != r["first_passing"] for r in rows)
    print(f"{len(rows)} datasets; the t rule recounted differs from the diagnosis's own first claim in {check}")
    counts, differ = score(rows)
    for rule in RULES:
        print(f"\n{rule}:")
        for category, c in sorted(counts[rule].items()):
            print(f"  {category:16s} right {c['right']:3d}  wrong {c['wrong']:3d}  none {c['none']:3d}")
    print("\ndatasets where the rules disagree:")
    for row, answers in differ:
        print(f"  {row['seed']} {row['category']} {row['expected']} SNR {row['snr'] or 0:.1f}: {answers}")
        for c in row["ranking"]:
            if c.get("run_log_error_ratios") is not None and c["effect"] in answers.values():
                print(f"      {c['effect']}: plain {np.round(c['run_log_error_ratios'], 3)}  "
                      f"level {np.round(c['run_level_log_error_ratios'], 3)}")


if __name__ == "__main__":
    main()
