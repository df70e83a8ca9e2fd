"""Speed of the sampled replay (``SampledReplay``) against the error-controlled one (``DrakeReplay``), whole and
fractional computation delays, on the EMPS estimation file.

Both replays are built and timed in this process, one after the other, so the printed ratio is robust to a busy
machine. Each row replays the whole estimation file (24841 samples, 1 kHz) with the published rigid IDIM
parameters (``regularization_velocity = 1e-3 m/s``), or with a two-mass axis whose axial mode is at 58 Hz, and
prints the wall time of one replay after a first one (the build and Drake's first-call costs are left out of both),
the ratio, and the two force errors [% of ||u||] (they should agree within a few hundredths of a point: see the
cross-tests in ``tests/gap/test_drake_replay.py``).

Until session 40 a fractional delay (the inverse-dynamics scan's start of ``fit_delay``) had no sampled replay
and went to ``DrakeReplay``; on the hard-saturated flexible axis of spent held-out dataset 29010000 one 3 s run did
not finish in 9 minutes there.

Run: ``PYTHONPATH=. python analysis/bench_replay.py [--samples N]``
"""

import argparse
import time

from drakecreep.gap.drake_replay import DrakeReplay, SampledReplay, axis_from_idim, drake_replay_errors
from drakecreep.gap.idim import PUBLISHED_IDIM
from drakecreep.gap.measured import load_emps

CASES = (
    ("rigid, no delay", False, 0.0, {}),
    ("rigid, 1 sample", False, 1.0, {}),
    ("rigid, 2.35 samples", False, 2.35, {}),
    ("two-mass 58 Hz, 0.35 samples", True, 0.35, dict(stiffness=2e6, damping=300.0)),
)


def timed(replay, params):
    replay.simulate(params)  # the first call: Drake's first-call costs
    start = time.perf_counter()
    result = replay.simulate(params)
    return time.perf_counter() - start, drake_replay_errors(result)["force"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=0, help="replay only the first N samples (0: the whole file)")
    args = ap.parse_args(argv)
    run = load_emps("estimation").runs[0]
    if args.samples < 0 or args.samples == 1:
        ap.error(f"--samples: got {args.samples}; allowed: 0 (the whole file) or 2 .. {run.n}")
    if args.samples:
        run = run.slice(0, min(args.samples, run.n))
    print(f"EMPS estimation file, {run.n} samples; one replay each after a first one [s]")
    print(f"{'case':32s} {'DrakeReplay':>12s} {'SampledReplay':>14s} {'ratio':>7s} {'force error %':>22s}")
    for label, flexible, delay, extra in CASES:
        params = axis_from_idim(PUBLISHED_IDIM, regularization_velocity=1e-3, **extra)
        t_ref, e_ref = timed(DrakeReplay(run, flexible=flexible, delay=delay), params)
        t_fast, e_fast = timed(SampledReplay(run, flexible=flexible, delay=delay, free=()), params)
        print(f"{label:32s} {t_ref:12.3f} {t_fast:14.3f} {t_ref / t_fast:6.1f}x {e_ref:10.3f} vs {e_fast:8.3f}")


if __name__ == "__main__":
    main()
