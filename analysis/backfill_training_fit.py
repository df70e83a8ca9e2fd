"""Backfill the nominal training fit's SSE and variance into ``drakecreep``-kind benchmark rows written before
``752729f`` (study 3br, docs/gap_benchmark.md).

Study 3br recounts first claims under rules that weigh a candidate's training gain by a chi-square test
(``analysis/drive_claim_statistics.py``: ``train_gain * train_sse / train_variance``). Rows written before
``752729f`` lack ``train_sse`` and ``train_variance``. Both come from the nominal fit alone (the uncertain fields'
output-error fit on the training runs, before any candidate), so they can be recomputed without rerunning the whole
diagnosis. For each such development row this script regenerates its dataset from the seed, withheld effect,
kind and axis (:func:`drakecreep.gap.benchmark.generate_dataset`), reruns the nominal fit with the row's uncertain
fields (:func:`drakecreep.gap.drive_fit.fit_drive`, as ``diagnose_drive`` does), and replays the held-out runs
with the fitted params file. The fields are written only when those replays **reproduce** the row's own nominal
held-out force errors (``test_force_nominal_runs``, every run within ``--tolerance`` points): otherwise the fit at
this code is not the one the row's claims were judged against, and the row is left as it was, with the
difference printed.

Held-out rows are refused: 3br is a development study.

Run: ``PYTHONPATH=. python analysis/backfill_training_fit.py ROWS.json [...] --out BACKFILLED.json``
"""

import argparse
import json
import sys
import time

import numpy as np

from drakecreep.files import write_text
from drakecreep.gap.benchmark import generate_dataset
from drakecreep.gap.drive_fit import (DEFAULT_UNCERTAIN, _effective_variance, _errors_of, _Replayer, fit_drive)


def backfill(row, tolerance=1e-3, say=print):
    """``row`` with ``train_sse``, ``train_variance`` and ``backfilled`` set when the refit reproduces the row's
    nominal held-out errors, else ``row`` unchanged; and the largest per-run difference [points]."""
    ds = generate_dataset(int(row["seed"]), withheld=tuple(row["withheld"]), kind=row["kind"], axis=row["axis"])
    prior = ds.train[0].meta.params
    uncertain = tuple(row.get("uncertain") or DEFAULT_UNCERTAIN)
    replay = _Replayer(0)
    params, _, _, sse, fit = fit_drive(ds.train, prior, uncertain, replay, max_nfev=20, details=True)
    errors = _errors_of(ds.test, replay(ds.test, params))
    got = [float(e["force"]) for e in errors.values()]
    diff = float(np.max(np.abs(np.subtract(got, row["test_force_nominal_runs"]))))
    if diff > tolerance:
        say(f"seed {row['seed']}: not reproduced (held-out nominal force errors differ by up to {diff:.3g} points)")
        return row, diff
    out = dict(row, train_sse=float(sse), train_variance=_effective_variance(fit.residual, len(fit.paths)),
               backfilled={"by": "analysis/backfill_training_fit.py", "max_difference_points": diff,
                           "replays": replay.count})
    say(f"seed {row['seed']}: train_sse {out['train_sse']:.4g}, train_variance {out['train_variance']:.4g} "
        f"(held-out nominal reproduced within {diff:.2g} points; {replay.count} replays)")
    return out, diff


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rows", nargs="+", help="JSON files of analysis/bench_gap_benchmark.py --seeds dev --kinds drakecreep")
    ap.add_argument("--out", required=True, help="JSON file for the rows, backfilled where reproduced")
    ap.add_argument("--tolerance", type=float, default=1e-3,
                    help="largest difference of a held-out run's nominal force error [points] (default 1e-3)")
    args = ap.parse_args(argv)
    if not args.tolerance > 0:
        ap.error(f"--tolerance: got {args.tolerance}; allowed: a number > 0 [points]")
    rows, seen = [], set()
    for path in args.rows:
        try:
            with open(path, encoding="utf-8") as f:
                data = json.load(f)
            if data.get("seeds") != "dev":
                ap.error(f"rows: got {path!r} (seeds {data.get('seeds')!r}); allowed: development rows (seeds dev)")
            for r in data["datasets"]:
                if r.get("kind") == "drakecreep" and r["seed"] not in seen:
                    seen.add(r["seed"])
                    rows.append(r)
        except (OSError, ValueError, KeyError, TypeError, AttributeError) as e:
            ap.error(f"rows: got {path!r} ({e}); allowed: a JSON file of gap-benchmark rows (a 'datasets' list)")
    out = []
    for row in rows:
        if row.get("train_sse") is not None or row.get("test_force_nominal_runs") is None:
            out.append(row)
            continue
        t0 = time.perf_counter()
        new, _ = backfill(row, args.tolerance)
        print(f"    ({time.perf_counter() - t0:.0f} s)", flush=True)
        out.append(new)
        write_text(args.out, json.dumps({"seeds": "dev", "datasets": out}, indent=1) + "\n")
    done = sum(1 for r in out if r.get("backfilled"))
    print(f"{done} of {len(out)} rows backfilled -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
