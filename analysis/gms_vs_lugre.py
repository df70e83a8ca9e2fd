"""GMS against LuGre at very low feed on the paper rig (issue 15, defect 8).

Both laws share the Stribeck curve (same Fc, Fs, vs, delta, Fv) and the initial presliding stiffness
sigma0; GMS adds presliding hysteresis with genuine stick (N elements) and a frictional memory time g/C.
For each law, load case 3, 3 s runs (metrics from 1 s): creep verdict, stick-slip cycles, stick fraction and
the maximum speed fluctuation at 0.005-1 mm/s; for GMS also the sensitivity to its two extra assumptions
(N elements, attraction C) and the verdict at 10x tighter accuracy (convergence).

Run: ``python analysis/gms_vs_lugre.py [--preset paper]``
"""

import argparse

from drakecreep.sim.simulation import target_accuracy
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate

FEEDS_MM_S = (0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0)


def run(p, feed_mm_s):
    r = simulate(p, Scenario(feed=feed_mm_s * 1e-3, load_case=3, duration=3.0))
    m = r.metrics
    return (f"{'creep' if m.creep else 'smooth':6s} {m.stick_slip_cycles:4d} cyc  stick {m.stick_fraction:4.2f}  "
            f"fluct {m.max_fluctuation * 1e3:8.4g} mm/s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", default="paper")
    args = ap.parse_args()
    base = preset(args.preset)
    variants = [
        ("lugre", {"friction.law": "lugre"}),
        ("lugre, accuracy/10", {"friction.law": "lugre", "simulation.accuracy": target_accuracy(base) / 10}),
        ("gms N=4 C=1e4", {"friction.law": "gms"}),
        ("gms N=4 C=1e4, accuracy/10", {"friction.law": "gms", "simulation.accuracy": target_accuracy(base) / 10}),
        ("gms N=1 C=1e4", {"friction.law": "gms", "friction.gms_elements": 1}),
        ("gms N=8 C=1e4", {"friction.law": "gms", "friction.gms_elements": 8}),
        ("gms N=4 C=1e3", {"friction.law": "gms", "friction.gms_attraction": 1e3}),
        ("gms N=4 C=1e5", {"friction.law": "gms", "friction.gms_attraction": 1e5}),
    ]
    for label, changes in variants:
        p = base
        for path, value in changes.items():
            p = with_value(p, path, value)
        for f in FEEDS_MM_S:
            print(f"{label:28s} {f:6g} mm/s  {run(p, f)}", flush=True)


if __name__ == "__main__":
    main()
