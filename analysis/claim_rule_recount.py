"""Recount the first claim of stored benchmark rows under another claim rule (no diagnosis is rerun).

Spent held-out rows only (runs already scored and looked into, never a run's own seeds before it is scored). Each
row of ``analysis/gap_benchmark_heldout*.json`` (runs 14 onwards) keeps, per ranked candidate, the per-held-out-run
log error ratios (plain, with each run's own friction level, at constant speed) and the dataset's training-run
null. This script feeds them to the product's own test (:func:`drakecreep.gap.drake_diagnosis._passes`, through
error dicts whose log ratios are the stored values) under

* ``current``: each candidate's own rule (``drift_robust``; ``either`` for the position friction), its
  fallback regime (the asymmetric friction's constant speed, from session 38) and its piece test (the lead error,
  from session 40; rows stored before have no pieces, so it never passes there), the product today;
* ``before_3bc``: ``current`` with every candidate held to the nominal's training-run null, the rule of held-out
  runs 36-42 (since session 49 a candidate that refits the friction is held to the smaller of that and its own,
  where the rows carry its own moves: ``own_training_run_moves``, rows from session 48 on; docs/gap_benchmark.md,
  3bc, 3be);
* ``before_3ap``: ``before_3bc`` without the outranking of session 42 (a passing candidate below a fitted one that
  fails is not claimed; docs/gap_benchmark.md, 3ap);
* ``both``: the rule before session 35 (``both`` where the product has ``drift_robust``);
* ``either``: every candidate with ``either`` (one test passing, the other's mean log ratio positive);
* ``pieces_bound``: ``current``, with a piece test that passes whenever its two means pass (both above their
  training-run nulls): the most the piece test can add on rows stored without pieces (its sign-flip condition on
  the pieces is taken as met; docs/gap_benchmark.md, 3ai).

and reports the first candidate in ranking order that passes: top-1 where SNR >= 3, claims on nulls and on effects
outside the library. It recounts the first claim only (the greedy steps after it are refitted on top of it and
cannot be recounted from the rows), so its top-1 is the benchmark's ``first_passing`` score.

Usage: ``PYTHONPATH=. python analysis/claim_rule_recount.py analysis/gap_benchmark_heldout16.json [...]``
"""

import argparse
import json
import math
import sys

from scipy import stats

from drakecreep.gap.claims import ALPHA
from drakecreep.gap.drake_diagnosis import (_claim_test, _fallback, _passes, _piece_test, _rule, null_of_moves,
                                            outranking)
from drakecreep.gap.drake_replay import piece_keys
from drakecreep.gap.drake_effects import DRAKE_EFFECTS

RULES = ("current", "before_3bc", "before_3ap", "both", "either", "pieces_bound")
_KEYS = {"force": "run_log_error_ratios", "force_level": "run_level_log_error_ratios",
         "force_constant_speed": "run_constant_speed_log_error_ratios"}


def _regime_of(entry):
    """The regime a ranked candidate must also show in: stored with rows from session 37 on; before, the effect's
    static one (an axial mode's band, resolved per fit, was not stored then: such rows recount without it). A
    stored fallback regime (session 38 on) is not one it must show in."""
    effect = DRAKE_EFFECTS.get(entry["effect"])
    if "regime" in entry:
        return "" if effect is not None and effect.fallback_regime and entry["regime"] == effect.fallback_regime \
            else entry["regime"]
    regime = effect.regime if effect is not None else ""
    return "" if regime == "mode_band" else regime


def _errors(entry):
    """(reference, candidate) error dicts whose per-run ``ln(reference / candidate)`` are the stored values."""
    n = len(entry["run_log_error_ratios"])
    ref = {f"r{i}": {} for i in range(n)}
    cand = {f"r{i}": {} for i in range(n)}
    keys = dict(_KEYS)
    if _regime_of(entry) and entry.get("run_regime_log_error_ratios") is not None:
        keys[f"force_{_regime_of(entry)}"] = "run_regime_log_error_ratios"
    # the constant-speed ratios are stored under their own name (the key above); any other fallback regime's are
    # the regime ratios
    fb = _fallback(entry["effect"])
    if fb and f"force_{fb}" not in keys and entry.get("run_regime_log_error_ratios") is not None:
        keys[f"force_{fb}"] = "run_regime_log_error_ratios"
    for key, field in keys.items():
        values = entry.get(field)
        if values is None:
            continue
        for i, v in enumerate(values):
            ref[f"r{i}"][key] = 1.0
            cand[f"r{i}"][key] = math.exp(-v)
    # each held-out run's pieces (rows from session 40 on): the piece test of DrakeEffect.piece_test
    for i, pieces in enumerate(entry.get("piece_log_error_ratios") or ()):
        for key, v in zip(piece_keys(), pieces):
            ref[f"r{i}"][key] = 1.0
            cand[f"r{i}"][key] = math.exp(-v)
    return ref, cand


def first_claim(row, rule, null_of=None):
    """The first candidate of ``row``'s ranking that passes under ``rule`` (None if none); under ``current`` and
    ``pieces_bound`` not one whose log ratio is below a fitted candidate's that does not pass (``outranking``).
    ``null_of(row, entry)``: each candidate's training-run null ``(plain, level)`` (default: the row's)."""
    decided = []
    for entry in row["ranking"]:
        if entry.get("screened_out") or not entry.get("run_log_error_ratios"):
            continue
        null = tuple(null_of(row, entry) if null_of else row.get("training_run_null") or (0.0, 0.0))
        ref, cand = _errors(entry)
        bar = float(stats.t.ppf(1.0 - ALPHA, len(entry["run_log_error_ratios"]) - 1))
        name = entry["effect"]
        own = _rule(name)
        current = rule in ("current", "before_3bc", "pieces_bound", "before_3ap")
        chosen = own if current else {"both": "both" if own == "drift_robust" else own}.get(rule, rule)
        kw = dict(rule=chosen, regime=_regime_of(entry), fallback_regime=_fallback(name) if current else "",
                  pieces=_piece_test(name) if current else False)
        moves = entry.get("own_training_run_moves")
        if rule == "current":
            t = _claim_test(ref, cand, name, bar, null, lambda: null_of_moves(moves) if moves else None, **kw)
        else:
            t = _passes(ref, cand, bar, null=null, **kw)
        passes = t.passes or (rule == "pieces_bound" and _piece_test(name) and null[0] > 0 and t.log_ratio > null[0]
                              and not t.level_log_ratio <= null[1])
        decided.append((name, passes, t.log_ratio))
    outranked = outranking(decided) if rule in ("current", "before_3bc", "pieces_bound") else {}
    return next((name for name, passes, _ in decided if passes and name not in outranked), None)


def recount(rows, rules=RULES, null_of=None):
    """Per rule: top-1 right / scored (SNR >= 3), claims on nulls, claims on out-of-library effects, and each
    row's first claim (``first``: seed -> candidate or None); ``null_of`` as :func:`first_claim`'s."""
    out = {}
    for rule in rules:
        top = [0, 0]
        null = [0, 0]
        ool = [0, 0]
        firsts = {}
        for r in rows:
            f = first_claim(r, rule, null_of)
            firsts[r["seed"]] = f
            if r["category"] == "library" and (r["snr"] or 0) >= 3:
                top[1] += 1
                top[0] += f == r["expected"]
            elif r["category"] == "null":
                null[1] += 1
                null[0] += f is not None
            elif r["category"] in ("out_of_library", "no_candidate"):
                ool[1] += 1
                ool[0] += f is not None
        out[rule] = {"top1": top, "null_claims": null, "out_of_library_claims": ool, "first": firsts}
    return out


def score_line(counts):
    """One line of a :func:`recount` entry's counts: top-1, claims on nulls, claims outside the library."""
    return (f"top-1 {counts['top1'][0]}/{counts['top1'][1]}  claims on nulls {counts['null_claims'][0]}/"
            f"{counts['null_claims'][1]}  out of library claimed {counts['out_of_library_claims'][0]}/"
            f"{counts['out_of_library_claims'][1]}")


def stored_first(row):
    """The row's stored first claim: the first of ``claimed`` (``first_passing`` ignores the outranking)."""
    return (row["claimed"] or [None])[0]


def main(argv=None):
    """Print each rows file's recount; the exit status (2, with one line, on a file that is not a rows file)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="+", metavar="JSON",
                    help="benchmark rows files (analysis/gap_benchmark_heldout*.json)")
    files = {}
    for path in ap.parse_args(argv).paths:  # every file read before the first recount
        try:
            with open(path) as fh:
                files[path] = json.load(fh)["datasets"]
        except (OSError, ValueError, KeyError, TypeError) as e:
            print(f"JSON: got {path!r}; allowed: a readable benchmark rows file with 'datasets' ({type(e).__name__})",
                  file=sys.stderr)
            return 2
    for path, rows in files.items():
        res = recount(rows)
        print(path)
        for rule in RULES:
            print(f"  {rule:8s} {score_line(res[rule])}")
        for r in rows:
            firsts = [res[rule]["first"][r["seed"]] for rule in RULES]
            if len(set(firsts) | {r["first_passing"]}) > 1:
                print(f"    {r['seed']} {r['category']:15s} expected {r['expected'] or '-':20s} SNR {r['snr'] or 0:5.1f} "
                      f"stored {r['first_passing'] or '-':20s} "
                      + " ".join(f"{rule} {f or '-':20s}" for rule, f in zip(RULES, firsts)).rstrip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
