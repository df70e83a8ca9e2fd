"""The README's two simulations: creep at a low feed and smooth sliding at the paper's 1 mm/s.

Run: ``python analysis/readme_figures.py [--out docs/img]`` (about a minute: two 5 s runs, each checked for convergence).
"""

import argparse
from pathlib import Path

from drakecreep.params import preset
from drakecreep.report.plots import plot_feed
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate

CASES = {"creep_0.1mm_s.png": 1e-4, "smooth_1mm_s.png": 1e-3}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="docs/img")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, feed in CASES.items():
        result = simulate(preset("paper"), Scenario(feed=feed, load_case=3, duration=5.0))
        plot_feed(result, out / name)
        s = result.summary()
        print(f"{name}: feed {s['feed_mm_s']:g} mm/s, fluctuation {s['max_fluctuation_mm_s']:.4g} mm/s "
              f"({s['fluctuation_rate_percent']:.3g} %), stick {s['stick_fraction']:.3f}, "
              f"{s['stick_slip_cycles']} cycles, converged {s['converged']}")


if __name__ == "__main__":
    main()
