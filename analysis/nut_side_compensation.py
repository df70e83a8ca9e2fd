"""Defect 2 of issue 15: how the paper-rig compensation result moves when the ball nut's friction acts on
the screw (catalogue values) instead of the table (the old 0.01 N m / 0.01 values).

Runs ``drakecreep.studies.compensation.evaluate`` at 0.05, 0.1 and 0.5 mm/s, load case 3, methods none /
lugre / dob, for the old and the new nut; prints the fluctuation rate of each and the ratio none/method.
Run: python analysis/nut_side_compensation.py   (a few minutes on 2 cores)
"""

import argparse

from drakecreep.params import preset, with_value
from drakecreep.studies.compensation import evaluate

OLD = {"friction.nut_friction_on": "table", "nut.preload_torque": 0.01, "nut.load_friction_coefficient": 0.01}


def main():
    new = preset("paper")
    old = new
    for path, value in OLD.items():
        old = with_value(old, path, value)
    for label, params in (("old: nut on the table, 0.01 N m / 0.01", old), ("new: nut on the screw, 0.09 N m / 0.08", new)):
        rows = evaluate(params, methods=("none", "lugre", "dob"), feeds_mm_s=(0.05, 0.1, 0.5), load_cases=(3,),
                        duration=2.0, workers=2)
        print(label)
        base = {r["feed_mm_s"]: r for r in rows if r["method"] == "none"}
        for r in rows:
            b = base[r["feed_mm_s"]]
            ratio = b["fluctuation_rate_percent"] / max(r["fluctuation_rate_percent"], 1e-12)
            print(f"  {r['method']:6s} {r['feed_mm_s']:5.2f} mm/s: fluctuation {r['fluctuation_rate_percent']:8.1f} %"
                  f"  creep {r['creep']!s:5s} converged {r.get('converged')!s:5s}  none/method {ratio:6.1f}x",
                  flush=True)


if __name__ == "__main__":
    argparse.ArgumentParser(description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
