"""Diagnose named benchmark datasets with the product path and print each row's verdict and audit.

One benchmark row per dataset (:func:`drakecreep.gap.benchmark.evaluate`, as ``bench_gap_benchmark.py`` makes
them): what was claimed and first, the audit force error [%] of the nominal, the claimed and the true model (whole
and below 100 Hz), their shrinks and ``worse``. For development checks of one change on a few datasets (docs/
gap_benchmark.md, 3cg) and for looking again at spent held-out ones. Seeds of the current held-out set
(``>= benchmark.HELDOUT_SEEDS``) are refused: they are spent in a pre-registered run only, and a seed of it is
looked at again only once a run has spent it: ``--spent ROWS.json`` names that run's rows files (what
``bench_gap_benchmark.py --json`` wrote, ``"complete": true``), and only their seeds are let through.

Usage: ``PYTHONPATH=. python analysis/diagnose_dataset.py SEED:WITHHELD:AXIS [...] --kind drakecreep
[--json OUT.json] [--spent ROWS.json ...] [--effects control_delay]`` (e.g. ``9014:control_delay:flexible``;
``WITHHELD`` ``null`` for a null dataset). A dataset that fails is one line and a ``failed`` entry in the rows, and
the others go on (exit status 1).
"""

import argparse
import json
import sys
import time

from drakecreep.errors import InputError
from drakecreep.files import check_output_file, write_text
from drakecreep.gap import benchmark as B
from study_cli import read_rows

__all__ = ["summary", "main"]


def summary(row):
    """The verdict and audit of a benchmark ``row`` as one line of text."""
    audit = row.get("audit") or {}

    def fig(name):
        a = audit.get(name)
        return "-" if not a else f"{a['force_rms']:.2f} % (< 100 Hz {a.get('force_lowpass_rms', float('nan')):.2f})"

    def share(key):
        value = row.get(key)
        return "-" if value is None else f"{100 * value:.1f} %"

    return (f"{row['seed']} {'/'.join(row.get('withheld') or ['null'])} {row.get('axis')} SNR {row.get('snr', 0):.1f}: "
            f"claimed {row.get('claimed') or 'nothing'} (first {row.get('first_passing')}); audit nominal "
            f"{fig('nominal')}, claimed {fig('claimed')}, true {fig('true')}; shrink {share('audit_shrink')}, "
            f"true {share('true_shrink')}; worse {row.get('worse')}")


def main(argv=None):
    """Parse ``argv``, diagnose each dataset and print its line; the exit status (2 on a bad argument)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("datasets", nargs="+", metavar="SEED:WITHHELD:AXIS",
                    help="a dataset: WITHHELD null or a withheld effect, AXIS rigid or flexible")
    ap.add_argument("--kind", required=True, choices=B.BENCHMARK_KINDS, help="the controller kind")
    ap.add_argument("--json", help="write the rows here (after each dataset)")
    ap.add_argument("--effects", metavar="NAMES",
                    help="comma-separated candidates to fit (default: the diagnosis's own; drakecreep kind): a study "
                         "of one candidate, whose fit and held-out test do not depend on the others, runs only it")
    ap.add_argument("--spent", nargs="+", metavar="ROWS", default=(),
                    help="rows files of a complete pre-registered run: its seeds of the current held-out set are "
                         "let through")
    a = ap.parse_args(argv)
    spent = set()
    for path in a.spent:
        rows = read_rows(ap, "--spent", path)
        if rows.get("complete") is not True:
            ap.exit(2, f"diagnose_dataset: error: --spent: {path!r} is not a complete run's rows (\"complete\": "
                       f"{rows.get('complete')!r}); allowed: the rows of a run that is whole\n")
        spent.update(int(r["seed"]) for r in rows["datasets"])
    effects = None
    try:
        specs = [B.dataset_spec(s) for s in a.datasets]
        if a.effects is not None:
            if a.kind != "drakecreep":
                raise InputError("--effects", a.effects, "only with --kind drakecreep")
            effects = B.check_effects((a.kind,), (e.strip() for e in a.effects.split(",") if e.strip()), "--effects")
        for seed, _, _ in specs:
            if seed >= B.HELDOUT_SEEDS and seed not in spent:
                raise InputError("SEED", seed, f"a seed below {B.HELDOUT_SEEDS} or one of a complete run's rows "
                                 "given to --spent (the current held-out set is spent in a pre-registered run only)")
        if a.json:
            check_output_file(a.json, "--json")
    except InputError as e:
        ap.exit(2, f"diagnose_dataset: error: {e}\n")
    rows, failed = [], []
    for seed, withheld, axis in specs:
        t0 = time.time()
        try:  # one failing dataset is reported and kept, as the benchmark does; the others go on
            ds = B.generate_dataset(seed, withheld=withheld, kind=a.kind, axis=axis)
            row = B.evaluate(ds, effects=effects)
        except Exception as err:  # noqa: BLE001
            failed.append({"seed": seed, "withheld": list(withheld), "axis": axis,
                           "error": f"{type(err).__name__}: {err}"})
            print(f"{seed} {'/'.join(withheld) or 'null'} {axis}: failed ({failed[-1]['error']})", flush=True)
        else:
            row["seconds"] = time.time() - t0
            rows.append(row)
            print(summary(row) + f" ({row['seconds']:.0f} s)", flush=True)
        if a.json:
            write_text(a.json, json.dumps({"kind": a.kind, "effects": effects, "datasets": rows, "failed": failed},
                                          indent=1, default=str))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
