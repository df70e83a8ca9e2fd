"""Realistic gap benchmark: top-1, claims on nulls, out-of-library, audit replay shrink, claims making it worse.

Datasets from :mod:`drakecreep.gap.truth` (see :mod:`drakecreep.gap.benchmark`). The reported figures use
the held-out seeds (``--seeds heldout``, the default); ``--seeds dev`` is the development set used while
designing the claim rule.

Run: ``python analysis/bench_gap_benchmark.py [--n 60] [--seeds heldout|dev] [--kinds p_p_cascade drakecreep]
[--json out.json]``
"""

import argparse
import json
import time

from drakecreep.gap.benchmark import DEV_SEEDS, HELDOUT_SEEDS, run_benchmark
from drakecreep.gap.truth import CONTROLLER_KINDS


def _pct(d):
    return "-" if d["rate"] is None else f"{100 * d['rate']:.0f} % (n={d['n']})"


def print_scores(s, indent=""):
    print(f"{indent}top-1 where SNR >= 3: {_pct(s['top1_snr3'])}   (all SNR: {_pct(s['top1_all'])})")
    print(f"{indent}claims on nulls: {_pct(s['claims_on_nulls'])}")
    print(f"{indent}out-of-library answered unexplained: {_pct(s['out_of_library_unexplained'])}")
    m = s["median_relative_shrink_snr3"]
    print(f"{indent}median audit replay shrink / true effect's (SNR >= 3): {'-' if m is None else f'{100 * m:.0f} %'}")
    print(f"{indent}claims making the audit replay worse: {s['claims_making_audit_worse']} of {s['n_claims']} claims")
    if s["provisional_top1_snr3"]["n"] and s["provisional_top1_snr3"]["rate"]:
        print(f"{indent}(replay unavailable) provisional top-1 where SNR >= 3: {_pct(s['provisional_top1_snr3'])}, "
              f"provisional on nulls: {_pct(s['provisional_on_nulls'])}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-per-effect", type=int, default=10, help="diagnosed datasets per library effect with SNR >= 3")
    ap.add_argument("--n-null", type=int, default=10, help="null datasets per controller kind")
    ap.add_argument("--n-ool", type=int, default=6, help="datasets per out-of-library effect and controller kind")
    ap.add_argument("--seeds", choices=("heldout", "dev"), default="heldout")
    ap.add_argument("--kinds", nargs="+", default=list(CONTROLLER_KINDS), choices=CONTROLLER_KINDS)
    ap.add_argument("--tries", type=float, default=4.0, help="candidates per library effect / --n-per-effect")
    ap.add_argument("--json", help="write scores and rows to this file")
    args = ap.parse_args()
    seed = HELDOUT_SEEDS if args.seeds == "heldout" else DEV_SEEDS
    t0 = time.perf_counter()
    res = run_benchmark(seed=seed, kinds=args.kinds, n_per_effect=args.n_per_effect, n_null=args.n_null,
                        n_ool=args.n_ool, progress=True, tries=args.tries)
    s = res["scores"]
    print(f"{s['n_datasets']} datasets diagnosed, {args.seeds} seeds from {seed}, kinds {args.kinds}, "
          f"{time.perf_counter() - t0:.0f} s; candidates skipped for SNR < 3: {res['low_snr_skipped']}; "
          f"effects short of {args.n_per_effect} datasets with SNR >= 3: {res['short'] or 'none'}")
    print_scores(s)
    for k, b in s["per_kind"].items():
        print(f"controller {k}:")
        print_scores(b, "  ")
    for a, b in s["per_axis"].items():
        print(f"axis {a}:")
        print_scores(b, "  ")
    print("per effect (right = top-1 for library effects with SNR >= 3, no claim for nulls / out-of-library):")
    for e, d in sorted(s["per_effect"].items()):
        r = d["right"]
        print(f"  {e:22s} n={d['n']:3d} n_scored={d['n_snr3']:3d} right={_pct(r):14s} median SNR {d['median_snr']:.1f}"
              f"  claimed: {', '.join(d['claimed']) or '-'}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(res, fh, indent=1, default=str)


if __name__ == "__main__":
    main()
