"""Issue 15 defect 1: does the creep verdict depend on the integrator accuracy?

Paper preset, one friction law, a few feeds (mm/s), one load case; runge_kutta3 at 1e-4, 1e-5, 1e-6,
convergence check off (this measures the raw integrator). 3 s runs, metrics over t >= 1 s.
Run: python analysis/convergence_study.py stribeck 0.5,0.6,1.0 3
     python analysis/convergence_study.py lugre 0.05,0.1,0.5 3
"""

import argparse
import sys

from drakecreep.errors import InputError
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate

ACCURACIES = (1e-4, 1e-5, 1e-6)


def _feeds(text):
    """Comma-separated feeds in mm/s, each > 0."""
    try:
        feeds = [float(f) for f in text.split(",")]
    except ValueError:
        feeds = []
    if not feeds or not all(f > 0 for f in feeds):
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: comma-separated feeds in mm/s, each > 0")
    return feeds


def main(argv=None):
    """Simulate each feed at each accuracy (every input checked first) and print the metrics; the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("law", help="friction law (friction.law of the params)")
    ap.add_argument("feeds", type=_feeds, help="comma-separated feeds, mm/s")
    ap.add_argument("load_case", type=int, nargs="?", default=3, help="load case (default 3)")
    a = ap.parse_args(argv)
    try:  # every input checked before the first simulation
        p = with_value(preset("paper"), "friction.law", a.law)
        p.load_case(a.load_case)
        scenarios = [Scenario(feed=feed * 1e-3, load_case=a.load_case, duration=3.0) for feed in a.feeds]
    except InputError as e:
        print(e, file=sys.stderr)
        return 2
    for feed, scenario in zip(a.feeds, scenarios):
        for acc in ACCURACIES:
            q = p
            for path, value in (("simulation.integrator", "runge_kutta3"), ("simulation.accuracy", acc),
                                ("simulation.convergence_check", False)):
                q = with_value(q, path, value)
            r = simulate(q, scenario)
            m = r.metrics
            print(f"{a.law} feed {feed} mm/s lc{a.load_case} runge_kutta3 {acc:g}: creep={m.creep} "
                  f"cyc={m.stick_slip_cycles} stick={m.stick_fraction:.3f} fluct={m.fluctuation_rate * 100:.1f}% "
                  f"wall={r.wall_time:.2f}s steps={r.stats['steps']} {r.status}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
