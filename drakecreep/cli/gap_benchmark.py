"""``drakecreep gap-benchmark``: generate datasets with hidden effects, diagnose them blind, score the diagnosis."""

import sys

from drakecreep.cli._common import print_json, workers

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Register ``gap-benchmark``."""
    p = subparsers.add_parser("gap-benchmark", help="withheld-effect benchmark of the gap diagnosis",
                              description=__doc__)
    p.add_argument("--n", type=workers, default=20, help="datasets (default 20)")
    p.add_argument("--seed", type=int, default=0, help="first seed (datasets use seed .. seed+n-1)")
    p.add_argument("--no-replay", action="store_true", help="skip the closed-loop replay (inverse dynamics only)")
    p.add_argument("--json", action="store_true", help="print JSON (scores and per-dataset rows)")
    p.set_defaults(func=run)
    return p


def run(args):
    """Run and print the scores."""
    from drakecreep.gap.benchmark import run_benchmark

    res = run_benchmark(n=args.n, seed=args.seed, replay=not args.no_replay, progress=not args.quiet)
    if args.json:
        print_json(res)
        return 0
    s = res["scores"]

    def pct(d):
        return "-" if d["rate"] is None else f"{100 * d['rate']:.0f} % (n={d['n']})"

    print(f"datasets: {s['n_datasets']} (seeds {args.seed}..{args.seed + args.n - 1})")
    print(f"top-1 attribution: {pct(s['top1_all'])} all, {pct(s['top1_snr3'])} where SNR >= 3")
    print(f"top-3 attribution: {pct(s['top3_all'])} all, {pct(s['top3_snr3'])} where SNR >= 3")
    print(f"false claims on null datasets: {pct(s['false_claims_null'])}")
    print(f"datasets with effects where a claimed effect is not hidden: {pct(s['wrong_claims_with_effects'])}")
    ms = s["median_excess_shrink_snr3"]
    print("median held-out gap shrink (excess over the noise floor, SNR >= 3): "
          + ("-" if ms is None else f"{100 * ms:.0f} %"))
    mr = s["median_raw_idim_shrink_snr3"]
    print("median held-out inverse-dynamics RMS shrink (raw, SNR >= 3): " + ("-" if mr is None else f"{100 * mr:.0f} %"))
    for k, v in s["parameter_recovery_median_rel_error"].items():
        print(f"parameter recovery {k}: median relative error {100 * v:.1f} %")
    print("", file=sys.stderr)
    return 0
