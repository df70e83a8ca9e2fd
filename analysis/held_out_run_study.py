"""Which held-out runs carry a withheld effect: one spent dataset, the effect's own candidate only.

Spent held-out datasets only (runs already scored and looked into). For a missed effect whose true fit shrinks the
audit, the question is whether the candidate's fit is wrong or the held-out runs do not show it. This script
diagnoses the dataset with the product path (``benchmark.diagnose_dataset``, the withheld effect as the only
candidate), then prints

* the truth's values beside the nominal's and the candidate's fitted ones (mass, viscous, Coulomb, offset and the
  effect's own parameters);
* every run's reference speed, commanded force and travel (training, held out, audit);
* the candidate's inverse-dynamics screen (its held-out log ratio and start values);
* every held-out run's closed-loop force error [%] with the nominal and with the candidate, and their log ratio
  (the claim's per-run statistic), plain and with each run's own friction level.

Usage: ``PYTHONPATH=. python analysis/held_out_run_study.py SEED:WITHHELD:AXIS`` (e.g.
``55010002:drive_saturation:flexible``; docs/gap_benchmark.md, 3am).
"""

import argparse
import math
import sys

import numpy as np

from drakecreep.errors import InputError
from drakecreep.gap import benchmark
from drakecreep.gap.drake_effects import DRAKE_EFFECTS

_BASE = ("mass", "viscous", "coulomb", "offset")


def _run_line(kind, r):
    v = np.gradient(r.x_ref, r.dt)
    return (f"  {kind:8s} {r.label:6s} top speed {1e3 * np.abs(v).max():5.0f} mm/s, commanded force RMS "
            f"{np.sqrt(np.mean(r.force ** 2)):6.1f} N, peak {np.abs(r.force).max():5.0f} N, travel "
            f"{1e3 * r.x_ref.min():6.1f} .. {1e3 * r.x_ref.max():6.1f} mm")


def main(argv=None):
    """Diagnose the dataset of ``argv`` with its effect's candidate and print the rows; the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset", metavar="SEED:WITHHELD:AXIS",
                    help="a spent dataset: WITHHELD an effect with a fitted candidate, AXIS rigid or flexible")
    args = ap.parse_args(argv)
    try:
        seed, withheld, axis = benchmark.dataset_spec(args.dataset)
    except InputError as e:  # one line, exit 2, before any work
        print(e, file=sys.stderr)
        return 2
    name = benchmark.EXPECTED.get(withheld[0]) if len(withheld) == 1 else None
    if name not in DRAKE_EFFECTS:
        allowed = [w for w, c in benchmark.EXPECTED.items() if c in DRAKE_EFFECTS]
        print(f"WITHHELD: got {'+'.join(withheld) or 'null'!r}; allowed: a withheld effect with a fitted candidate, "
              "one of " + ", ".join(allowed), file=sys.stderr)
        return 2
    ds = benchmark.generate_dataset(seed, withheld=withheld, kind="p_p_cascade", axis=axis)
    res = benchmark.diagnose_dataset(ds, effects=[name])
    ranked = next(r for r in res.ranking if r.name == name)
    tr = ds.truth
    print(f"{seed} {withheld[0]} (candidate {name}) {axis}: SNR {ds.snr:.1f}, nominal friction {res.friction}")
    print(f"  truth: mass {tr.M:.1f} kg, viscous {tr.Fv:.1f} N s/m, Coulomb {tr.Fc:.2f} N, offset {tr.offset:.2f} N, "
          f"effect {tr.effects.get(withheld[0])}")
    keys = _BASE + DRAKE_EFFECTS[name].parameters
    print("  nominal:   " + ", ".join(f"{k} {res.nominal.parameters[k]:.4g}" for k in keys))
    for kind, runs in (("training", ds.train), ("held out", ds.test), ("audit", ds.audit)):
        for r in runs:
            print(_run_line(kind, r))
    sc = ranked.screen
    if sc is not None:
        print(f"  screen (inverse dynamics): held-out log ratio {sc.log_ratio:+.3f} (standard error "
              f"{sc.log_ratio_se:.3f}), passes: {sc.passes}; start " + ", ".join(f"{k} {v:.4g}" for k, v in sc.start.items()))
    if ranked.fit is None:
        print("  the candidate was screened out: no closed-loop fit")
        return 0
    print("  candidate: " + ", ".join(f"{k} {ranked.fit.parameters[k]:.4g}" for k in keys)
          + (f" (closed-loop start: {ranked.closed_loop_start})" if ranked.closed_loop_start else ""))
    ref = ranked.reference_errors or res.nominal_test_errors
    print("  held-out force error [%], reference -> candidate, log ratio (with the run's friction level):")
    for label, cand in ranked.fit.test_errors.items():
        a, b = ref[label], cand
        print(f"    {label:6s} {a['force']:7.2f} -> {b['force']:7.2f}  {math.log(a['force'] / b['force']):+.3f} "
              f"({math.log(a['force_level'] / b['force_level']):+.3f})")
    print(f"  mean log ratio {ranked.log_ratio:+.3f} vs bar {ranked.threshold:.3f}; with each run's level "
          f"{ranked.level_log_ratio:+.3f} vs bar {ranked.level_threshold:.3f}; passes: {ranked.passes}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
