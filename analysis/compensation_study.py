"""Friction compensation against none: feeds 0.05-5 mm/s x load cases 1-3, lowest feed without creep,
and the compensator's model off by +-30 % in each parameter -- on two drives:

* ``paper``: the seed paper's rig. Its creep is the table sticking and slipping on the screw's
  spring (73 Hz mode), out of reach of a torque added at the motor.
* ``rigid_axis``: the same rig with a rigid transmission and a softer velocity loop, where the
  friction is within the loop's reach (the textbook setting of friction compensation).

The sweep API (drakecreep/sim/sweep.py) runs a parameter grid; this study needs per-method parameter sets
plus paired baselines, so it uses drakecreep.studies.compensation.evaluate/robustness on a 2-process pool.
Writes to OUT_DIR/<preset>/: compensation.csv, summary.md, rows.json, comparison.png.
Run: python analysis/compensation_study.py [OUT_DIR] [PRESET ...]   (about 2 minutes on 2 cores)
"""

import argparse
import sys

from drakecreep.studies.compensation import creep_boundaries, evaluate, robustness, write_report
from drakecreep.params import PRESETS, preset


#: feeds (mm/s) of the mismatch study per preset: inside each drive's creeping range
ROBUSTNESS_FEEDS = {"paper": (0.1, 0.2), "rigid_axis": (0.05, 0.1)}


def study(out, name):
    params = preset(name)
    rows = evaluate(params, workers=2)
    crit = creep_boundaries(params)
    robust = robustness(params, feeds_mm_s=ROBUSTNESS_FEEDS.get(name, (0.1, 0.2)), workers=2)
    paths = write_report(f"{out}/{name}", rows, crit, robust, name)
    print(paths["markdown"].read_text())


def main(out="out/compensation-study", *names):
    for name in names or ("paper", "rigid_axis"):
        study(out, name)


def _preset_name(text):
    """A preset's name (:data:`drakecreep.params.PRESETS`)."""
    if text not in PRESETS:
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: one of " + ", ".join(PRESETS))
    return text


def cli(argv=None):
    """Parse ``argv`` (every preset named checked first) and run :func:`main`; the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", nargs="?", default="out/compensation-study", metavar="OUT_DIR",
                    help="output directory (default out/compensation-study)")
    ap.add_argument("names", nargs="*", type=_preset_name, metavar="PRESET",
                    help="presets to study (default paper rigid_axis)")
    a = ap.parse_args(argv)
    main(a.out, *a.names)
    return 0


if __name__ == "__main__":
    sys.exit(cli())
