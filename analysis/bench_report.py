"""Build time of the servo-loop report for the paper preset (issue 4: "under 60 s on this machine").

Times the whole ``drakecreep report`` path (``build_report``: linearizations, margins, loci, the
16 x 20 pole map, 36 creep simulations on its coarse grid over ``--workers`` processes, two simulations,
six plots, HTML) and, in the same process, a baseline: one ``simulate()`` of the paper's 5 s feed at 1 mm/s
under load case 3. The ratio is robust to a busy machine; the absolute time is the one the issue asks for.

Run: ``python analysis/bench_report.py [--out DIR] [--repeats N] [--workers N]``
"""

import argparse
import tempfile
import time

from drakecreep.params import preset
from drakecreep.processes import usable_cpus
from drakecreep.report.loop_report import build_report
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=None, help="report folder (default: a temporary one)")
    ap.add_argument("--repeats", type=int, default=1, help="report builds (the best is kept)")
    ap.add_argument("--workers", type=int, default=usable_cpus(), help="processes for the pole map's creep "
                    "simulations (default: the usable CPUs, as drakecreep report)")
    args = ap.parse_args()
    if args.workers < 1:
        ap.error(f"--workers: got {args.workers}; allowed: an integer >= 1")
    params = preset("paper")
    start = time.perf_counter()
    simulate(params, Scenario(feed=1e-3, load_case=3, duration=5.0))
    baseline = time.perf_counter() - start
    best, timings = float("inf"), None
    for _ in range(args.repeats):
        out = args.out or tempfile.mkdtemp(prefix="drakecreep_report_")
        start = time.perf_counter()
        result = build_report(params, out, workers=args.workers)
        wall = time.perf_counter() - start
        if wall < best:
            best, timings = wall, result["timings"]
    stages = "; ".join(f"{k} {v:.1f} s" for k, v in timings.items())
    print(f"report (paper preset, {args.workers} worker(s)): {best:.1f} s wall  [{stages}]")
    print(f"baseline, one 5 s simulate(): {baseline:.2f} s -> report = {best / baseline:.0f} x baseline")
    print(f"written to {result['html']}")
    print("PASS: under 60 s" if best < 60 else "FAIL: over 60 s")


if __name__ == "__main__":
    main()
