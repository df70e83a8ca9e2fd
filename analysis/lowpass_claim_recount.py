"""Recount the first claim of ``drakecreep``-kind benchmark rows on the force error below 100 Hz (docs 3ce).

Under the PI cascade the recorded force carries the speed loop's encoder-count ripple, whose sample pattern no
replay reproduces and which any change of the model draws anew (docs/gap_benchmark.md, 3ce). The claim rule
judges a candidate on the held-out force error. This script asks what the same rule decides on ``force_lowpass``,
the part of that error below 100 Hz, where the ripple hardly reaches.

Rows written since ``force_lowpass`` was added carry, beside the force errors the rule used, the same errors below
100 Hz: the nominal's held-out runs (``test_force_lowpass_nominal_runs``), each candidate's
(``test_force_lowpass_runs``) and each leave-one-out refit's (``null_test_force_lowpass_runs``). For each row the
script feeds them to the product's own test (:func:`drakecreep.gap.drive_fit.force_test` and
:func:`~drakecreep.gap.drive_fit.passes_on_force`, with the run-to-run null recounted from the refits below
100 Hz), orders the candidates by their gain below 100 Hz as the product orders them by the force's, and reports
the first that passes. Left as the rows have them, because their decision is not made on the force:

* a lead error decided on the screw's transmission (its ranking entry has ``transmission``);
* a row whose held-out runs oscillate (``oscillation``): only a delay on the spectrum can be claimed there.

Like ``analysis/claim_rule_recount.py`` it recounts the first claim only (the greedy steps after it are refitted
on top of it). It changes nothing in the product. Use it on development rows before any held-out run is scored
this way.

Usage: ``PYTHONPATH=. python analysis/lowpass_claim_recount.py ROWS.json [...] [--json OUT.json]``
"""

import argparse
import json
import sys

from drakecreep.errors import InputError
from drakecreep.files import check_output_file, write_text
from drakecreep.gap.benchmark import score_rows
from drakecreep.gap.drive_fit import force_test, passes_on_force
from study_cli import read_rows

__all__ = ["recount_row", "main"]


def _errors(values):
    """Per-run errors below 100 Hz under the key ``force``, the one :func:`force_test` reads."""
    return {f"run{i}": {"force": float(v)} for i, v in enumerate(values)}


def recount_row(row):
    """The first claim of a ``drakecreep``-kind ``row`` on the force error below 100 Hz.

    Parameters
    ----------
    row : dict
        A benchmark row (``analysis/bench_gap_benchmark.py --json``) with the ``*_lowpass_*`` fields.

    Returns
    -------
    dict or None
        ``{"seed", "first_passing", "first_passing_lowpass", "null", "null_lowpass", "candidates"}`` (each
        candidate's gain, bar, pooled shrink and verdict below 100 Hz); None for a row without the fields.
    """
    nominal = row.get("test_force_lowpass_nominal_runs")
    refits = row.get("null_test_force_lowpass_runs")
    if nominal is None or row.get("kind") != "drakecreep":
        return None
    e_nom = sum(v * v for v in nominal)
    null = (max(abs(1.0 - sum(v * v for v in r) / e_nom) for r in refits) if refits and e_nom > 0 else None)
    current = _errors(nominal)
    out = []
    for c in row["ranking"]:
        entry = {"effect": c["effect"], "stored_passes": bool(c["passes"])}
        runs = c.get("test_force_lowpass_runs")
        if row.get("oscillation") or c.get("transmission") is not None or runs is None:
            entry.update(kept=True, passes=bool(c["passes"]), gain=None)
        else:
            gain, se, bar, rt = force_test(current, _errors(runs), null)
            entry.update(kept=False, gain=gain, bar=bar, shrink=rt["shrink"], runs_better=rt["runs_better"],
                         passes=passes_on_force(c["train_gain"], gain, bar, rt, null))
        out.append(entry)
    # the product's order: by the held-out gain, largest first (a kept candidate keeps its force gain)
    stored_gain = {c["effect"]: c["gain"] for c in row["ranking"]}
    order = sorted(out, key=lambda e: -(e["gain"] if e["gain"] is not None else stored_gain[e["effect"]]))
    first = next((e["effect"] for e in order if e["passes"]), None)
    return {"seed": row["seed"], "withheld": row["withheld"], "expected": row.get("expected"),
            "category": row["category"], "snr": row["snr"], "first_passing": row.get("first_passing"),
            "first_passing_lowpass": first, "null": row.get("replay_null"), "null_lowpass": null,
            "candidates": order}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rows", nargs="+", help="rows files of analysis/bench_gap_benchmark.py --json")
    ap.add_argument("--json", help="write the recount here")
    a = ap.parse_args(argv)
    if a.json:
        try:
            check_output_file(a.json, "--json")
        except InputError as e:
            ap.error(str(e))
    keys = ("seed", "kind", "axis", "category", "snr", "ranking")
    rows = [r for path in a.rows for r in read_rows(ap, "rows", path, keys=keys)["datasets"]]
    recounts = [x for x in (recount_row(r) for r in rows) if x is not None]
    if not recounts:
        ap.error("rows: got no drakecreep row with the force_lowpass fields; allowed: rows written since "
                 "they were added (docs 3ce)")
    for x in recounts:
        nl = "-" if x["null_lowpass"] is None else f"{100 * x['null_lowpass']:.2f} %"
        nf = "-" if x["null"] is None else f"{100 * x['null']:.2f} %"
        print(f"{x['seed']} {(x['withheld'] or ['null'])[0]:14s} SNR {x['snr']:6.1f} expected "
              f"{str(x['expected'] or '-'):14s} first passing: force {str(x['first_passing'] or '-'):14s} "
              f"below 100 Hz {str(x['first_passing_lowpass'] or '-'):14s} null {nf} -> {nl}")
    by_seed = {x["seed"]: x for x in recounts}
    for label, key in (("force (as run)", "first_passing"), ("below 100 Hz", "first_passing_lowpass")):
        rescored = [dict(r, claimed=[by_seed[r["seed"]][key]] if by_seed[r["seed"]][key] else [])
                    for r in rows if r["seed"] in by_seed]
        s = score_rows(rescored)
        t, n = s["top1_snr3"], s["claims_on_nulls"]
        print(f"{label:15s}: top-1 (first claim) {t['rate'] and round(t['rate'] * t['n'])} / {t['n']}, "
              f"claims on nulls {n['rate'] and round(n['rate'] * n['n'])} / {n['n']}, "
              f"wrong first claims {s['wrong_claims']} / {s['n_claims']}")
    if a.json:
        write_text(a.json, json.dumps({"recounts": recounts}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
