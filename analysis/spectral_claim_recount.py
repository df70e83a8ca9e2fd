"""Recount the ``drakecreep`` kind's delay claims on the held-out spectrum under another rule (study 3cy).

When the measured runs oscillate where the fitted model does not (an unstable real loop, a stable model), the
diagnosis replays a computation delay that makes the model oscillate at the measured frequency on the held-out
runs and claims it on the spectrum (``drive_fit._spectral_delay``): over the held-out runs that oscillate, the
per-run decrease of the band error ``|ln(model RMS / measured RMS)|`` must exceed ``t(1 - ALPHA, n - 1)`` standard
errors of those decreases, with most of those runs better and oscillating at their measured frequency, and at most
half of the quiet runs oscillating. With two or three oscillating held-out runs the Student quantile is 6.31 or
2.92, and decreases of 2-8 nepers on every run (a model 7 to 3000 times closer in amplitude) can stay under it when
they differ from run to run.

Rules recounted on rows written by ``analysis/bench_gap_benchmark.py --kinds drakecreep`` (each row with a
held-out spectrum test keeps the per-run band errors, nominal and delayed):

* ``student``: the product's rule (a self-check: it must give each row's own ``passes``);
* ``detector``: the detector's own criterion run by run in place of the Student bar. A run oscillates where the
  model does not when its band RMS is at least :data:`~drakecreep.gap.residuals.OSCILLATION_RATIO` times the
  model's, i.e. a band error of ``ln(10)`` or more; the delayed model *reproduces* a held-out run's oscillation when
  its band error there is below ``ln(10)`` while the fitted model's is not. The delay passes when it reproduces
  more than half of the oscillating held-out runs, oscillates at their measured frequency on more than half, and
  on at most half of the quiet runs (the product's two other conditions), with the run-to-run null present.

Rows written before ``oscillating_runs`` was kept (session 89) name only how many held-out runs oscillate, or not
even that: those runs are taken as the ones with the largest nominal band errors (a stable model misses an
oscillating run by ``ln(10)`` or more, a quiet one by little), and kept only where the mean decrease over them is
the row's own ``gain``; else the row reads ``n/a``.

Run: ``PYTHONPATH=. python analysis/spectral_claim_recount.py ROWS.json [ROWS.json ...]``
"""

import argparse
import math
import sys

import numpy as np
from scipy import stats

from drakecreep.gap.claims import ALPHA
from drakecreep.gap.residuals import OSCILLATION_RATIO
from study_cli import unique_rows

__all__ = ["RULES", "oscillating_runs", "spectral_passes", "recount", "main"]

RULES = ("student", "detector")
NOT_AVAILABLE = "n/a"


def oscillating_runs(spectral):
    """The held-out runs that oscillate (indices) of a row's ``spectral`` test, or None when they cannot be told.

    Kept by rows since session 89 (``oscillating_runs``); else inferred as the runs of the largest nominal band
    errors, ``oscillating`` of them where the row says how many, else any count from two up, and accepted only
    where their mean decrease is the row's ``gain`` (to 1e-9 nepers)."""
    if spectral.get("oscillating_runs") is not None:
        return sorted(int(i) for i in spectral["oscillating_runs"])
    e0, e1 = np.asarray(spectral["nominal_nepers"]), np.asarray(spectral["delay_nepers"])
    counts = [spectral["oscillating"]] if spectral.get("oscillating") is not None else range(2, e0.size + 1)
    gain = spectral.get("gain")
    for k in counts:
        osc = sorted(np.argsort(-e0, kind="stable")[:k].tolist())
        if k > 1 and gain is not None and math.isfinite(gain) and abs(np.mean((e0 - e1)[osc]) - gain) < 1e-9:
            return osc
    return None


def spectral_passes(rule, spectral, osc, null_present=True):
    """Whether the delay of a row's ``spectral`` test passes under ``rule`` with the oscillating runs ``osc``."""
    e0, e1 = np.asarray(spectral["nominal_nepers"]), np.asarray(spectral["delay_nepers"])
    n = e0.size
    quiet = n - len(osc)
    same, spurious = spectral["same_frequency"], spectral.get("spurious", 0)
    shared = bool(null_present and len(osc) > 1 and 2 * same > len(osc) and 2 * spurious <= quiet)
    if rule == "student":
        dec = (e0 - e1)[osc]
        se = float(np.std(dec, ddof=1) / math.sqrt(dec.size))
        better = int(np.sum(dec > 0))
        return bool(shared and dec.mean() > stats.t.ppf(1 - ALPHA, dec.size - 1) * se and 2 * better > len(osc))
    if rule == "detector":
        bar = math.log(OSCILLATION_RATIO)
        reproduced = int(np.sum((e1[osc] < bar) & (e0[osc] >= bar)))
        return bool(shared and 2 * reproduced > len(osc))
    raise ValueError(rule)


def recount(rows):
    """``[(row, {rule: passes or "n/a"}, oscillating runs)]`` of the rows with a held-out spectrum test."""
    out = []
    for row in rows:
        spectral = (row.get("oscillation") or {}).get("spectral")
        if not spectral or not spectral.get("nominal_nepers"):
            continue
        osc = oscillating_runs(spectral)
        null = row.get("replay_null") is not None
        verdicts = {rule: NOT_AVAILABLE if osc is None else spectral_passes(rule, spectral, osc, null)
                    for rule in RULES}
        out.append((row, verdicts, osc))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rows", nargs="+", help="JSON files written by analysis/bench_gap_benchmark.py --kinds drakecreep")
    args = ap.parse_args(argv)
    rows = unique_rows(ap, args.rows)
    table = recount(rows)
    if not table:
        print("no rows with a held-out spectrum test")
        return 0
    print(f"{'seed':>10s} {'withheld':18s} {'train osc':>9s} {'held-out osc':>12s} {'own':>6s} "
          + " ".join(f"{r:>9s}" for r in RULES))
    for row, verdicts, osc in table:
        o, sp = row["oscillation"], row["oscillation"]["spectral"]
        name = row["withheld"][0] if row["withheld"] else "null"
        held = "?" if osc is None else f"{len(osc)}/{len(sp['nominal_nepers'])}"
        print(f"{row['seed']:>10d} {name:18s} {o['runs']:>4d}/{o['of']:<4d} {held:>12s} {str(sp['passes']):>6s} "
              + " ".join(f"{str(verdicts[r]):>9s}" for r in RULES))
        if verdicts["student"] not in (NOT_AVAILABLE, sp["passes"]):
            print("           (the recount of student differs from the row's own verdict)")
    for rule in RULES:
        told = [v for _, d, _ in table for v in [d[rule]] if v != NOT_AVAILABLE]
        withheld = [v for (row, d, _) in table for v in [d[rule]]
                    if v != NOT_AVAILABLE and "control_delay" in (row.get("withheld") or [])]
        print(f"{rule:9s} passes {sum(told)} of {len(told)} rows ({sum(withheld)} of {len(withheld)} with a "
              "withheld delay)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
