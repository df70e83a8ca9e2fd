"""What the gap benchmark's truth costs per dataset, with the terms that are zero left out and with every term.

The benchmark's truth (:func:`drakecreep.gap.truth.simulate_batch`) integrates every run of a dataset at once, one
numpy column per run, 24 substeps per 1 ms sample: its cost is the overhead of the substep's numpy calls, not the
arithmetic, so a term that is zero in every column (an effect the truth does not have) costs as much as one that
acts. ``simulate_batch`` leaves those out (``skip_zero_terms``, the default) and gives the same bits
(``tests/gap/test_truth.py::test_the_terms_left_out_where_they_are_zero_change_no_bit``). This script times one
dataset's runs of a null truth and of a truth with one withheld effect, both ways, as CPU time of this process
(``time.process_time``), and prints the ratio.

Run from the repository root: ``PYTHONPATH=. python analysis/bench_truth.py [--runs N] [--samples N] [--repeat N]``
"""

import argparse
import time

import numpy as np

from drakecreep.gap import truth as T
from drakecreep.gap.benchmark import N_AUDIT, N_TEST, N_TRAIN

__all__ = ["main"]

CASES = (("null, drakecreep kind, flexible", "drakecreep", "flexible", ()),
         ("cogging, p_p_cascade kind, rigid", "p_p_cascade", "rigid", ("cogging",)),
         ("structural mode, drakecreep kind, flexible", "drakecreep", "flexible", ("structural_mode",)))


def _cpu(job, repeat, skip):
    """Least CPU time [s] of ``repeat`` simulations of ``job``."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        T.simulate_batch(job, skip_zero_terms=skip)
        best = min(best, time.process_time() - t0)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=N_TRAIN + N_TEST + N_AUDIT,
                    help="runs per dataset (default %(default)s, the benchmark's training, held-out and audit runs)")
    ap.add_argument("--samples", type=int, default=3000, help="samples per run (default %(default)s, 3 s)")
    ap.add_argument("--repeat", type=int, default=2,
                    help="simulations per case and way, the least CPU time kept (default %(default)s)")
    args = ap.parse_args(argv)
    if not 1 <= args.runs <= 64:
        ap.error(f"--runs: got {args.runs}; allowed: an integer in [1, 64]")
    if not 240 <= args.samples <= 100_000:
        ap.error(f"--samples: got {args.samples}; allowed: an integer in [240, 100000]")
    if not 1 <= args.repeat <= 20:
        ap.error(f"--repeat: got {args.repeat}; allowed: an integer in [1, 20]")
    print(f"{args.runs} runs of {args.samples} samples, {T.SUBSTEPS} substeps each; least CPU time of "
          f"{args.repeat}")
    print(f"{'truth':44s} {'every term [s]':>15s} {'zeros left out [s]':>19s} {'ratio':>6s}")
    for label, kind, axis, withheld in CASES:
        rng = np.random.default_rng(7)
        tr = T.draw_truth(rng, kind, axis, withheld)
        refs, pulses, _ = T.draw_profiles(rng, args.runs, n=args.samples)
        drift, noise = T.noise_draws(tr, args.runs, args.samples, rng)
        job = [(tr, refs, pulses, drift, noise, True)]
        every, fast = _cpu(job, args.repeat, False), _cpu(job, args.repeat, True)
        print(f"{label:44s} {every:15.2f} {fast:19.2f} {every / fast:6.2f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
