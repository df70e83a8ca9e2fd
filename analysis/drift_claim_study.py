"""Development-seed study: does the friction drift between runs decide a position friction's claim?

The truth (:mod:`drakecreep.gap.truth`) scales each run's friction by a random walk over the runs (``drift_sd``
1-4 % per run). This script regenerates a development dataset with a withheld effect three ways and fits that
one candidate (its expected one, ``benchmark.EXPECTED``) as the diagnosis does (``diagnose_drake``, ``friction="auto"``):

* ``drift``: as drawn;
* ``trainflat``: the four training runs at their mean drift level, the held-out runs as drawn;
* ``nodrift``: every run at level 1.

It prints the claim's two statistics (docs/gap_benchmark.md, 3q) and the per-held-out-run log ratios
``(plain, with the run's own friction level)``. Development seeds only (below the held-out 7_000_000)::

    PYTHONPATH=. python analysis/drift_claim_study.py --seeds 45001 --axis rigid --mode drift
"""

import argparse
import math

import numpy as np

from drakecreep.gap import benchmark as B
from drakecreep.gap.drake_diagnosis import diagnose_drake

MODES = ("drift", "trainflat", "nodrift")
#: the first held-out seed base ever used (held-out run 1); every seed from there on is held out or spent
FIRST_HELDOUT = 7_000_000


#: the benchmark's own draw, wrapped (not re-wrapped) for each mode
_DRAW = B._draw


def _drawing(mode):
    """``benchmark._draw`` with the drift of ``mode``."""
    draw = _DRAW

    def patched(*args, **kwargs):
        tr, refs, pulses, drift, noise = draw(*args, **kwargs)
        drift = np.array(drift, dtype=float)
        if mode == "nodrift":
            drift[:] = 1.0
        elif mode == "trainflat":
            drift[: B.N_TRAIN] = drift[: B.N_TRAIN].mean()
        return tr, refs, pulses, drift, noise

    return patched


def study(seed, axis, mode, effect):
    """One line: the claim statistics of ``effect`` on development ``seed`` with the drift of ``mode``."""
    B._draw = _drawing(mode)
    ds = B.generate_dataset(seed, withheld=(effect,), kind="p_p_cascade", axis=axis)
    res = diagnose_drake(ds.train, ds.test, effects=(B.EXPECTED[effect],), friction="auto")
    r = res.ranking[0]
    if r.fit is None:
        return f"{seed} {axis} {mode}: screened out (inverse-dynamics log ratio {r.screen.log_ratio:+.3f})"
    ref = r.reference_errors or res.nominal_test_errors
    per = [(math.log(ref[k]["force"] / r.fit.test_errors[k]["force"]),
            math.log(ref[k]["force_level"] / r.fit.test_errors[k]["force_level"])) for k in ref]
    return (f"{seed} {axis} {mode}: SNR {ds.snr:.2f}, passes {r.passes}; log ratio {r.log_ratio:+.3f} +- "
            f"{r.log_ratio_se:.3f}, with each run's level {r.level_log_ratio:+.3f} +- {r.level_log_ratio_se:.3f}; "
            "per held-out run " + " ".join(f"({a:+.2f}, {b:+.2f})" for a, b in per))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", default="45001", help="development seeds, comma separated")
    ap.add_argument("--axis", choices=("rigid", "flexible"), default="rigid")
    ap.add_argument("--mode", choices=MODES, default="drift")
    ap.add_argument("--effect", default="position_friction", help="the withheld library effect")
    args = ap.parse_args()
    try:
        seeds = [int(s) for s in args.seeds.split(",")]
    except ValueError:
        ap.error(f"--seeds: got {args.seeds!r}; allowed: integers, comma separated")
    if any(not 0 <= s < FIRST_HELDOUT for s in seeds):
        ap.error(f"--seeds: got {args.seeds}; allowed: development seeds in [0, {FIRST_HELDOUT})")
    if args.effect not in B.EXPECTED:
        ap.error(f"--effect: got {args.effect!r}; allowed: one of " + ", ".join(B.EXPECTED))
    for seed in seeds:
        print(study(seed, args.axis, args.mode, args.effect), flush=True)


if __name__ == "__main__":
    main()
