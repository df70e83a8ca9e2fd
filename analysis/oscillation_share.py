"""How often the benchmark's measured runs oscillate, per withheld effect (docs/gap_benchmark.md 3bl).

For each withheld effect of the truth (and nulls), ``--n`` datasets of one controller kind (axes alternate) are
generated, and each training and held-out run's measured force is searched for its dominant oscillation above
20 Hz (:func:`drakecreep.gap.residuals.dominant_oscillation`). A run whose oscillation holds at least
``OSCILLATION_SHARE`` (a quarter) of the force's variance is counted: the diagnosis withholds its
sample-by-sample claims when most training runs are such (:func:`drakecreep.gap.drive_fit.claims_withheld`).
Development seeds only: dataset ``j`` of effect ``i`` has seed ``SEED + 1000 i + j`` (nulls ``i`` = 99).

Run (about 2 min for ``--n 20`` on one core)::

    PYTHONPATH=. python analysis/oscillation_share.py --seed 3000 --n 20 --kind drakecreep
"""

import argparse
import collections

import numpy as np

from drakecreep.gap import benchmark as B
from drakecreep.gap import truth as T
from drakecreep.gap.residuals import OSCILLATION_SHARE, dominant_oscillation


def specs(seed, n, kind):
    """``(seed, withheld, kind, axis)`` of every dataset probed."""
    slots = [(e,) for e in T.WITHHELD] + [()]
    return [(seed + 1000 * (T.WITHHELD.index(w[0]) if w else 99) + j, w, kind, T.AXES[j % len(T.AXES)])
            for j in range(n) for w in slots]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=3000, help="first development seed (default 3000)")
    ap.add_argument("--n", type=int, default=20, help="datasets per withheld effect and of nulls (default 20)")
    ap.add_argument("--kind", choices=B.BENCHMARK_KINDS, default="drakecreep")
    args = ap.parse_args(argv)
    if args.n < 1:
        ap.error(f"--n: got {args.n}; allowed: an integer >= 1")
    if args.seed < 0 or args.seed + 99 * 1000 + args.n > B.HELDOUT_SEEDS // 2:
        ap.error(f"--seed: got {args.seed}; allowed: a development seed >= 0, far below the held-out seeds "
                 f"({B.HELDOUT_SEEDS})")
    stat = collections.defaultdict(list)
    for ds in B.generate_datasets(specs(args.seed, args.n, args.kind)):
        found = [dominant_oscillation(r.force, r.dt) for r in ds.train + ds.test]
        shares = [o["share"] for o in found]
        stat[ds.withheld[0] if ds.withheld else "null"].append(
            (ds.seed, ds.axis, ds.snr, max(shares), sum(s >= OSCILLATION_SHARE for s in shares), len(shares),
             float(np.median([o["freq_Hz"] for o in found]))))
    print(f"{args.kind} kind, seeds from {args.seed}: a run oscillates when its dominant oscillation above 20 Hz "
          f"holds >= {OSCILLATION_SHARE:g} of the force's variance")
    print(f"{'withheld':20s} {'datasets':>8s} {'oscillating':>11s} {'largest share':>13s}")
    for name, rows in stat.items():
        print(f"{name:20s} {len(rows):8d} {sum(r[4] > 0 for r in rows):11d} {max(r[3] for r in rows):13.3f}")
        for seed, axis, snr, share, k, of, freq in rows:
            if k:
                print(f"    seed {seed} ({axis}, SNR {snr:.1f}): {k} of {of} runs, share up to {share:.2f}, "
                      f"median {freq:.0f} Hz")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
