"""Where LuGre's smooth window at very low feed comes from: the bristles' relaxation length against the mode.

LuGre relaxes toward the Stribeck curve over a sliding *distance* ~ g/sigma0 (0.34 um for the paper rig at
load case 3), i.e. over a time (g/sigma0)/v that grows as the feed falls. Hypothesis: the paper rig is
smooth where that time exceeds the period of the axial mode (13.6 ms at 73.5 Hz), because the friction then
cannot follow the falling Stribeck curve within one oscillation (it acts as the bristle spring and damper
instead); the lower edge of the creep range then scales as v* ~ (Fs/sigma0) f_mode, i.e. with 1/sigma0.
Test: the lowest creeping feed for sigma0 = 1e7, 1e8 (preset), 1e9 N/m; the hypothesis predicts v* about
0.25, 0.025, 0.0025 mm/s.

Run: ``python analysis/lugre_smooth_window.py``
"""

import argparse

from drakecreep.model.lumped import axial_mode_frequency, lumped
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate

FEEDS_MM_S = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0)


def main():
    base = preset("paper")
    f_mode = axial_mode_frequency(base)
    for sigma0 in (1e7, 1e8, 1e9):
        p = with_value(base, "friction.bristle_stiffness", sigma0)
        g = lumped(p, 3).breakaway
        predicted = g / sigma0 * f_mode * 1e3
        verdicts = []
        for f in FEEDS_MM_S:
            m = simulate(p, Scenario(feed=f * 1e-3, load_case=3, duration=3.0)).metrics
            verdicts.append(f"{f:g}:{'C' if m.creep else '.'}")
        print(f"sigma0 {sigma0:.0e} N/m: (Fs/sigma0) f_mode = {predicted:.3g} mm/s;  creep (C) / smooth (.) at "
              + " ".join(verdicts), flush=True)


if __name__ == "__main__":
    argparse.ArgumentParser(description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
