"""The ``drakecreep`` kind's ``control_delay`` candidate on runs whose computation delay the params file misstates.

Runs of the quick rig's diagram (:func:`drakecreep.gap.drake_replay.simulated_runs`, 20-35 mm/s, 0.5 s, 2 N of
noise on ``u``) with ``controller.computation_delay`` set to ``DELAY`` speed-loop samples; the params file
says 1 sample. Two runs train, two are held out; candidates lead error, force ripple, Stribeck and the delay, the
seal force uncertain. A delay of 1 is the null (the params file is right). Development seeds (900-903 by
default); the tests use others.

Usage: ``PYTHONPATH=. python analysis/drive_delay_study.py [DELAY:SEED ...]`` (default ``6:900 5:901 1:902 2:903``).
"""

import argparse
import sys
import time

from drakecreep.errors import InputError
from drakecreep.gap.drake_replay import quick_replay_params, rms_force_error, simulated_runs
from drakecreep.gap.drive_fit import diagnose_drive
from drakecreep.params import preset, with_value

SPEEDS = (0.02, 0.03, 0.025, 0.035)
CANDIDATES = ("lead_error", "force_ripple", "stribeck", "control_delay")
DEFAULT_CASES = ("6:900", "5:901", "1:902", "2:903")


def _case(text):
    """``(delay, seed)`` of ``DELAY:SEED``: a delay in speed-loop samples, a seed an integer >= 0."""
    try:
        delay, seed = text.split(":")
        case = (float(delay), int(seed))
    except ValueError:
        case = None
    if case is None or case[1] < 0:
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: DELAY:SEED (SEED an integer >= 0), e.g. 6:900")
    return case


def main(argv=None):
    """Diagnose the runs of each case (every delay checked against the params first); the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cases", nargs="*", type=_case, metavar="DELAY:SEED",
                    help="true delay (speed-loop samples) and noise seed (default " + " ".join(DEFAULT_CASES) + ")")
    cases = ap.parse_args(argv).cases or [_case(c) for c in DEFAULT_CASES]
    rig = quick_replay_params(preset("paper"))
    try:  # the params' own range of the delay, before the first simulation
        truths = [with_value(rig, "controller.computation_delay", delay) for delay, _ in cases]
    except InputError as e:
        print(e, file=sys.stderr)
        return 2
    print(f"params file: computation delay {rig.controller.computation_delay:g} samples of "
          f"{1e3 * rig.controller.velocity_period:g} ms")
    for (delay, seed), truth in zip(cases, truths):
        runs = simulated_runs(truth, SPEEDS, declared=rig, n=500, noise=2.0, seed=seed)
        t0 = time.perf_counter()
        res = diagnose_drive(runs[:2], runs[2:], uncertain=("table.seal_force",), effects=CANDIDATES)
        c = next(c for c in res.candidates if c.name == "control_delay")
        found = c.values.get("controller.computation_delay", "-")
        claimed = " + ".join(res.claimed) or "nothing"
        print(f"truth {delay:g} samples (seed {seed}): candidate {found} samples, held-out gain {c.gain:+.3f} points "
              f"(bar {c.threshold:.3f}); claimed {claimed}; held-out force error "
              f"{rms_force_error(res.nominal_test_errors):.2f} -> {rms_force_error(res.test_errors):.2f} %; "
              f"{time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
