"""Development-seed study: should the training-run null count the moves that make the held-out error worse?

The training-run null (:func:`drakecreep.gap.drake_diagnosis.training_run_null`) is the largest
``|mean over held-out runs of ln(e_k / e)|`` over the training runs ``k`` left out of the nominal's fit. A move
``m_k > 0`` says the nominal fitted without run ``k`` replays the held-out runs *worse*: run ``k`` carried
something the held-out runs need. A move ``m_k < 0`` says the nominal fitted without it replays them *better*:
the choice of training runs alone gains that much, which is what the null guards against (a candidate that
absorbs what one training run happens to have).

When only some training runs excite an effect (a drive that saturates above a force only one run reaches, an
asymmetry one run's direction carries), leaving that run out makes the nominal much worse on the held-out runs
that excite it too: a large positive move, and a null of the effect's own size (held-out run 39 missed a drive
saturation at SNR 58 whose plain bar was a null of 1.292, docs/gap_benchmark.md 3ay). The question here: does
``improving`` = ``max(0, max_k -m_k)`` (the same for the level error) keep the nulls and the effects outside
the library unclaimed while it rescues such misses?

Rows come from ``analysis/bench_gap_benchmark.py --seeds dev`` at a code that stores each dataset's
``training_run_moves`` (from 1ddd75b). The recount is the first claim only, by the product's own test
(``analysis/claim_rule_recount.py``, ``current``), with the stored null replaced by each statistic of the stored
moves; ``largest`` must give the stored first claims back.

Development seeds only (nothing here is a held-out figure). Usage::

    PYTHONPATH=. python analysis/null_direction_study.py ROWS.json [...]

Session 47's rows (11 datasets): ``analysis/null_direction_dev.json``; what they say: docs/gap_benchmark.md, 3ba
(no first claim changes, and the runs that excite an effect move the nominal the *improving* way).
"""

import argparse
import json
import sys

import claim_rule_recount

from drakecreep.gap.drake_diagnosis import null_of_moves

#: statistic name -> the (plain, level) null of a list of signed moves
STATISTICS = {
    "largest": null_of_moves,  # the product's
    "improving": lambda moves: null_of_moves([[min(v, 0.0) for v in m] for m in moves]),
}


def recount(rows):
    """Per statistic: :func:`claim_rule_recount.recount`'s ``current`` rule on the rows with their null replaced
    by the statistic of their moves (top-1 right / scored where SNR >= 3, claims on nulls, claims outside the
    library, each row's first claim)."""
    for r in rows:
        if r.get("training_run_moves") is None:
            raise SystemExit(f"row {r['seed']}: no training_run_moves (rows from 1ddd75b on carry them)")
    return {name: claim_rule_recount.recount([dict(r, training_run_null=list(stat(r["training_run_moves"])))
                                              for r in rows])["current"]
            for name, stat in STATISTICS.items()}


def _read_rows(path):
    """The rows of a rows file, or the line refusing it (not a rows file, or rows without ``training_run_moves``)."""
    try:
        with open(path) as fh:
            rows = list(json.load(fh)["datasets"])
        missing = [r["seed"] for r in rows if r.get("training_run_moves") is None]
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as e:
        return f"ROWS.json: got {path!r}; allowed: a readable benchmark rows file with 'datasets' ({type(e).__name__})"
    if missing:
        return (f"ROWS.json: got {path!r} (row {missing[0]}: no training_run_moves); allowed: rows with "
                "training_run_moves (rows from 1ddd75b on carry them)")
    return rows


def main(argv=None):
    """Print the recount of the rows files of ``argv`` (every file read first); the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="+", metavar="ROWS.json",
                    help="rows files of analysis/bench_gap_benchmark.py with training_run_moves")
    files = [_read_rows(p) for p in ap.parse_args(argv).paths]
    problems = [f for f in files if isinstance(f, str)]
    if problems:  # one line, exit 2, before the recount
        print(problems[0], file=sys.stderr)
        return 2
    rows = sorted((r for f in files for r in f), key=lambda r: r["seed"])
    res = recount(rows)
    agree = sum(res["largest"]["first"][r["seed"]] == claim_rule_recount.stored_first(r) for r in rows)
    print(f"{len(rows)} rows; the recount with the largest move gives the stored first claim on {agree}")
    for name in STATISTICS:
        print(f"  {name:10s} {claim_rule_recount.score_line(res[name])}")
    for r in rows:
        moves = " ".join(f"{m[0]:+.3f}/{m[1]:+.3f}" for m in r["training_run_moves"])
        firsts = " ".join(f"{name} {res[name]['first'][r['seed']] or '-':20s}" for name in STATISTICS)
        print(f"    {r['seed']} {r['category']:15s} {r['expected'] or '-':20s} SNR {r['snr'] or 0:5.1f}  {firsts}"
              f" moves (plain/level) {moves}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
