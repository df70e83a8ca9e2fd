"""How often the benchmark's measured runs oscillate, per withheld effect (docs/gap_benchmark.md 3bl).

For each withheld effect of the truth (and nulls), ``--n`` datasets of one controller kind (axes alternate) are
generated, and each training and held-out run's measured force is searched for its dominant oscillation above
20 Hz (:func:`drakecreep.gap.residuals.dominant_oscillation`). A run whose oscillation holds at least
``OSCILLATION_SHARE`` (a quarter) of the force's variance is counted: the diagnosis withholds its
sample-by-sample claims when most training runs are such (:func:`drakecreep.gap.drive_fit.claims_withheld`).
Development seeds only: dataset ``j`` of effect ``i`` has seed ``SEED + 1000 i + j`` (nulls ``i`` = 99); with
``--effect NAME`` only that effect is drawn, dataset ``j`` on seed ``SEED + j`` (and with ``--axis`` on one axis).
Each oscillating dataset is listed with its training and held-out runs counted apart (docs/gap_benchmark.md 3cy:
the held-out runs withhold the claims too).

Run (about 2 min for ``--n 20`` on one core; 3cy's probe, about 30 min)::

    PYTHONPATH=. python analysis/oscillation_share.py --seed 3000 --n 20 --kind drakecreep
    PYTHONPATH=. python analysis/oscillation_share.py --seed 9000 --n 178 --effect control_delay --axis flexible
"""

import argparse
import collections

import numpy as np

from drakecreep.gap import benchmark as B
from drakecreep.gap import truth as T
from drakecreep.gap.residuals import OSCILLATION_SHARE, dominant_oscillation


def specs(seed, n, kind, effect=None, axis=None):
    """``(seed, withheld, kind, axis)`` of every dataset probed (``effect``: that withheld effect only, on seeds
    ``seed`` to ``seed + n - 1``; ``axis``: every dataset on it, else they alternate)."""
    def on(j):
        return axis or T.AXES[j % len(T.AXES)]

    if effect is not None:
        return [(seed + j, (effect,), kind, on(j)) for j in range(n)]
    slots = [(e,) for e in T.WITHHELD] + [()]
    return [(seed + 1000 * (T.WITHHELD.index(w[0]) if w else 99) + j, w, kind, on(j))
            for j in range(n) for w in slots]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=3000, help="first development seed (default 3000)")
    ap.add_argument("--n", type=int, default=20, help="datasets per withheld effect and of nulls (default 20)")
    ap.add_argument("--kind", choices=B.BENCHMARK_KINDS, default="drakecreep")
    ap.add_argument("--effect", choices=T.WITHHELD, help="draw only this withheld effect, on seeds SEED to SEED+N-1")
    ap.add_argument("--axis", choices=T.AXES, help="every dataset on this axis (default: they alternate)")
    args = ap.parse_args(argv)
    if args.n < 1:
        ap.error(f"--n: got {args.n}; allowed: an integer >= 1")
    if args.seed < 0 or args.seed + 99 * 1000 + args.n > B.HELDOUT_SEEDS // 2:
        ap.error(f"--seed: got {args.seed}; allowed: a development seed >= 0, far below the held-out seeds "
                 f"({B.HELDOUT_SEEDS})")
    stat = collections.defaultdict(list)
    for ds in B.generate_datasets(specs(args.seed, args.n, args.kind, args.effect, args.axis)):
        found = [dominant_oscillation(r.force, r.dt) for r in ds.train + ds.test]
        shares = [o["share"] for o in found]
        split = len(ds.train)
        stat[ds.withheld[0] if ds.withheld else "null"].append(
            (ds.seed, ds.axis, ds.snr, max(shares), sum(s >= OSCILLATION_SHARE for s in shares), len(shares),
             float(np.median([o["freq_Hz"] for o in found])),
             sum(s >= OSCILLATION_SHARE for s in shares[:split]), split))
    print(f"{args.kind} kind, seeds from {args.seed}: a run oscillates when its dominant oscillation above 20 Hz "
          f"holds >= {OSCILLATION_SHARE:g} of the force's variance")
    print(f"{'withheld':20s} {'datasets':>8s} {'oscillating':>11s} {'largest share':>13s}")
    for name, rows in stat.items():
        print(f"{name:20s} {len(rows):8d} {sum(r[4] > 0 for r in rows):11d} {max(r[3] for r in rows):13.3f}")
        for seed, axis, snr, share, k, of, freq, k_train, n_train in rows:
            if k:
                print(f"    seed {seed} ({axis}, SNR {snr:.1f}): {k} of {of} runs ({k_train} of {n_train} training, "
                      f"{k - k_train} of {of - n_train} held-out), share up to {share:.2f}, median {freq:.0f} Hz")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
