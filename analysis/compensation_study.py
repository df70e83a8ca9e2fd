"""Friction compensation against none: feeds 0.05-5 mm/s x load cases 1-3, lowest feed without creep,
and the compensator's model off by +-30 % in each parameter.

The sweep API (drakecreep/sweep.py) runs a parameter grid; this study needs per-method parameter sets
plus paired baselines, so it uses drakecreep.compensation.evaluate/robustness on a 2-process pool.
Writes to out/compensation-study/: compensation.csv, summary.md, rows.json, comparison.png.
Run: python analysis/compensation_study.py [OUT_DIR] [PRESET]   (about 5 minutes on 2 cores)
"""

import sys

from drakecreep.compensation import critical_speeds, evaluate, robustness, write_report
from drakecreep.params import preset


def main(out="out/compensation-study", name="paper"):
    params = preset(name)
    rows = evaluate(params, workers=2)
    crit = critical_speeds(params)
    robust = robustness(params, feeds_mm_s=(0.1, 0.2), workers=2)
    paths = write_report(out, rows, crit, robust, name)
    print(paths["markdown"].read_text())


if __name__ == "__main__":
    main(*sys.argv[1:])
