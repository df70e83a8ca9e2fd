"""The ``drakecreep`` kind's ``control_delay`` candidate on runs whose computation delay the params file misstates.

Runs of the quick rig's diagram (:func:`drakecreep.gap.drake_replay.simulated_runs`, 20-35 mm/s, 0.5 s, 2 N of
noise on ``u``) with ``controller.computation_delay`` set to ``DELAY`` speed-loop samples; the params file
says 1 sample. Two runs train, two are held out; candidates lead error, force ripple, Stribeck and the delay, the
seal force uncertain. A delay of 1 is the null (the params file is right). Development seeds (900-903 by
default); the tests use others.

Usage: ``PYTHONPATH=. python analysis/drive_delay_study.py [DELAY:SEED ...]`` (default ``6:900 5:901 1:902 2:903``).
"""

import sys
import time

from drakecreep.gap.drake_replay import quick_replay_params, rms_force_error, simulated_runs
from drakecreep.gap.drive_fit import diagnose_drive
from drakecreep.params import preset, with_value

SPEEDS = (0.02, 0.03, 0.025, 0.035)
CANDIDATES = ("lead_error", "force_ripple", "stribeck", "control_delay")


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    cases = []
    for item in argv or ("6:900", "5:901", "1:902", "2:903"):
        try:
            delay, seed = item.split(":")
            cases.append((float(delay), int(seed)))
        except ValueError:
            sys.exit(f"drive_delay_study: error: case: got {item!r}; allowed: DELAY:SEED, e.g. 6:900")
    rig = quick_replay_params(preset("paper"))
    print(f"params file: computation delay {rig.controller.computation_delay:g} samples of "
          f"{1e3 * rig.controller.velocity_period:g} ms")
    for delay, seed in cases:
        truth = with_value(rig, "controller.computation_delay", delay)
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


if __name__ == "__main__":
    main()
