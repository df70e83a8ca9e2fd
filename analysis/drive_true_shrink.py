"""The true effect's audit shrink of ``drakecreep``-kind benchmark rows written before it was measured.

Rows of ``analysis/bench_gap_benchmark.py --kinds drakecreep`` written before ``217fd0a`` have no ``true_shrink``:
the benchmark replayed the audit runs with the nominal and the claimed params files only, so the score "median
audit shrink relative to the true effect's" could not be counted for this kind. Since ``217fd0a`` the benchmark
also replays the nominal params file with the truth's own values of its withheld effect
(:func:`drakecreep.gap.benchmark.true_drive_values`; not fitted). This script does the same for older rows, and
counts nothing else: it changes no claim.

For each library row (a withheld effect with a ``DriveParams`` candidate; Stribeck has no true model there, see
:func:`~drakecreep.gap.benchmark.true_drive_values`) it regenerates the dataset from its
seed, effect, kind and axis (:func:`drakecreep.gap.benchmark.generate_dataset`, ``--samples`` as the run's), takes
the params file the diagnosis fitted, ``claimed_model["fitted"]`` written into the dataset's declared one, and
replays the audit runs:

* with that params file as the row had it (its claimed effects too): the result should **reproduce** the row's own
  audit energy (``audit["claimed"]``, which is ``audit["nominal"]`` when nothing was claimed) within
  ``--tolerance`` (the same code and dataset). Rows written at older code differ by the replay's changes since
  (up to 2 % on the rows of held-out runs 3-6); each row prints the difference, and the median is given over all rows
  and over the reproduced ones alone;
* with the fitted uncertain fields and the truth's effect instead of the claims: the true model.

The base of the true model is the nominal fit where nothing was claimed (what the benchmark now uses), and the
final refit where something was (the row does not keep the nominal fit's values): there the true effect is judged
on the friction refitted beside the claims, which can favour it or not. ``true_shrink = 1 - E_true / E_nominal``
with the row's own nominal energy; the relative shrink is ``audit_shrink / true_shrink``. A row whose held-out runs
oscillate (``row["oscillation"]``: a control delay that makes the truth unstable, every held-out one so far) is
compared sample by sample, where a free phase blinds the force error: it is printed, not counted in the medians.

Run: ``PYTHONPATH=. python analysis/drive_true_shrink.py ROWS.json [...] [--json OUT.json]``
"""

import argparse
import json
import sys
import time

import numpy as np

from drakecreep.errors import InputError
from drakecreep.files import check_output_file, write_text
from drakecreep.gap.benchmark import N_SAMPLES, generate_dataset, true_drive_values
from drakecreep.gap.drake_replay import drake_replay_errors, replay_drakecreep
from drakecreep.gap.drive_fit import DEFAULT_UNCERTAIN, _with
from study_cli import read_rows


def _energy(runs, params):
    """Mean over ``runs`` of the squared relative force error of the closed-loop replay [%^2]."""
    return float(np.mean([drake_replay_errors(replay_drakecreep(r, params))["force"] ** 2 for r in runs]))


def true_shrink(row, n_samples=N_SAMPLES, tolerance=1e-6):
    """The true model's audit figures of one ``drakecreep``-kind library row.

    Returns
    -------
    dict
        ``seed``, ``effect``, ``snr``, ``claimed``, ``base`` ("nominal" or "refit"), ``reproduced`` (the row's own
        audit energy replayed again, relative difference within ``tolerance``), ``check`` (that difference),
        ``oscillating``, ``true_energy``, ``true_shrink``, ``audit_shrink`` and ``relative`` (None unless the true
        shrink is positive).
    """
    t0 = time.perf_counter()
    ds = generate_dataset(int(row["seed"]), withheld=tuple(row["withheld"]), kind=row["kind"], axis=row["axis"],
                          n_samples=n_samples)
    declared = ds.train[0].meta.params
    model = row["claimed_model"]
    # the row's final model: the claims' values, then the final refit (the uncertain fields and the claims'
    # amplitudes refitted with them); the true model's base: the fitted uncertain fields alone (a claimed ripple's
    # refitted amplitude stays out of it)
    as_row = declared
    for values in model["effects"].values():
        as_row = _with(as_row, values)
    as_row = _with(as_row, model["fitted"])
    uncertain = set(row.get("uncertain") or DEFAULT_UNCERTAIN)
    fitted = _with(declared, {k: v for k, v in model["fitted"].items() if k in uncertain})
    own = row["audit"]["claimed"]["energy"]
    again = _energy(ds.audit, as_row)
    check = abs(again / own - 1.0)
    out = {"seed": row["seed"], "effect": row["withheld"][0], "axis": row["axis"], "snr": row["snr"],
           "claimed": row["claimed"], "base": "refit" if row["claimed"] else "nominal", "check": check,
           "reproduced": bool(check <= tolerance), "audit_shrink": row["audit_shrink"],
           "oscillating": bool(row.get("oscillation"))}
    true = true_drive_values(ds.truth)
    if true is None:  # Stribeck: no true model without a refit of the levels
        out.update(true_energy=None, true_shrink=None, relative=None, seconds=time.perf_counter() - t0)
        return out
    e_true = _energy(ds.audit, _with(fitted, true))
    shrink = 1.0 - e_true / row["audit"]["nominal"]["energy"]
    out.update(true_energy=e_true, true_shrink=shrink,
               relative=(row["audit_shrink"] / shrink if shrink > 0 else None),
               seconds=time.perf_counter() - t0)
    return out


def _rows(ap, path, min_snr):
    """The ``drakecreep``-kind library rows without a true shrink in the rows file ``path``."""
    data = read_rows(ap, "rows", path, keys=("seed", "withheld", "kind", "axis", "expected", "snr"),
                     writer="bench_gap_benchmark.py --json")
    return [r for r in data["datasets"] if r["kind"] == "drakecreep" and r["expected"] is not None
            and r["snr"] >= min_snr and r.get("true_shrink") is None]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("rows", nargs="+", help="JSON files of analysis/bench_gap_benchmark.py")
    ap.add_argument("--samples", type=int, default=N_SAMPLES, help="samples per run, as the run's (default %(default)s)")
    ap.add_argument("--tolerance", type=float, default=1e-6,
                    help="largest relative difference of the row's own audit energy replayed again")
    ap.add_argument("--min-snr", type=float, default=0.0, help="only rows with at least this SNR")
    ap.add_argument("--json", help="write the figures here (after each row)")
    args = ap.parse_args(argv)
    if not 600 <= args.samples <= 1_000_000:
        ap.error(f"--samples: got {args.samples}; allowed: an integer in [600, 1000000]")
    if not 0 < args.tolerance < 1:
        ap.error(f"--tolerance: got {args.tolerance}; allowed: a number in (0, 1)")
    if args.json:
        try:
            check_output_file(args.json, "--json")
        except InputError as err:
            ap.error(str(err))
    rows = [r for path in args.rows for r in _rows(ap, path, args.min_snr)]
    out = []
    for row in rows:
        r = true_shrink(row, args.samples, args.tolerance)
        out.append(r)
        rel = "-" if r["relative"] is None else f"{100 * r['relative']:.0f} %"
        true = "no true model" if r["true_shrink"] is None else f"true {100 * r['true_shrink']:6.1f} % ({r['base']})"
        print(f"{r['seed']} {r['axis']:8s} {r['effect']:13s} SNR {r['snr']:6.1f} "
              f"claimed {','.join(r['claimed']) or '-':14s} audit shrink {100 * r['audit_shrink']:6.1f} %  {true}"
              f"  relative {rel}{' (oscillates: not counted)' if r['oscillating'] else ''}"
              f"  {'reproduced' if r['reproduced'] else 'NOT reproduced'} ({r['check']:.1e})"
              f"  {r['seconds']:.0f} s", flush=True)
        if args.json:
            write_text(args.json, json.dumps(out, indent=1))
    for label, keep in (("", lambda r: True), (", reproduced rows", lambda r: r["reproduced"])):
        rel = [r["relative"] for r in out
               if r["snr"] >= 3 and r["relative"] is not None and not r["oscillating"] and keep(r)]
        if rel:
            print(f"median relative shrink, SNR >= 3{label}: {100 * float(np.median(rel)):.0f} % (n={len(rel)}; "
                  "target >= 70 %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
