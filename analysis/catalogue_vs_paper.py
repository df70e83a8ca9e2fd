"""Which conclusions change between the hammer-test stiffness ("paper") and catalogue stiffness ("paper_catalogue").

For each preset, at load case 3 with the preset's friction law (LuGre) unless ``--friction`` says otherwise:

* the axial chain K, the table-on-chain mode and its damping ratio (lumped, table at x = 0);
* the creep boundary by the paper's eq. 11 (:func:`drakecreep.paper.creep.critical_speed_of`, the
  self-consistent C1) and by simulation (:func:`drakecreep.studies.paper_reproduction.simulated_creep_boundary`,
  0.01-2 mm/s grid, then bisection; 2 s runs);
* creep / fluctuation of the nominal rig at 0.05, 0.1, 0.2 mm/s (3 s runs);
* the loop margins at 1 mm/s (:func:`drakecreep.servo.loops.analyze_loops`);
* with ``--samples N``: the share of plausible rigs (the shared uncertainty spec) that creep at 0.05-0.2 mm/s.

Run: ``python analysis/catalogue_vs_paper.py [--friction lugre] [--samples 200] [--workers 2]``
"""

import argparse
import math

from drakecreep.model.lumped import lumped
from drakecreep.paper.creep import critical_speed_of
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.servo.loops import analyze_loops
from drakecreep.sim.simulation import simulate
from drakecreep.studies.paper_reproduction import simulated_creep_boundary
from drakecreep.studies.uncertainty import run_uncertainty, uncertainty_spec

PRESETS = ("paper", "paper_catalogue")
FEEDS = (0.05e-3, 0.1e-3, 0.2e-3)


def row_of(name, law, samples, workers):
    p = preset(name)
    if law:
        p = with_value(p, "friction.law", law)
    d = lumped(p, 3)
    row = dict(preset=name, law=p.friction.law, K_N_per_um=d.stiffness * 1e-6,
               mode_Hz=math.sqrt(d.stiffness / d.mass) / (2 * math.pi),
               zeta_chain=d.damping / (2 * math.sqrt(d.stiffness * d.mass)),
               eq11_mm_s=critical_speed_of(d) * 1e3,
               simulated_boundary_mm_s=simulated_creep_boundary(p, 3) * 1e3)
    for f in FEEDS:
        m = simulate(p, Scenario(feed=f, load_case=3, duration=3.0)).metrics
        row[f"creep_{f * 1e3:g}"] = bool(m.creep)
        row[f"fluct_{f * 1e3:g}_mm_s"] = m.max_fluctuation * 1e3
    s = analyze_loops(p, Scenario(feed=1e-3, load_case=3)).summary()
    for loop in ("velocity", "position"):
        row[f"{loop}_PM_deg"] = s[loop]["phase_margin_deg"]
        row[f"{loop}_GM_dB"] = s[loop]["gain_margin_dB"]
        row[f"{loop}_crossover_Hz"] = s[loop]["crossover_Hz"]
        row[f"{loop}_delay_margin_ms"] = s[loop]["delay_margin_ms"]
    row["resonance_Hz"] = s["resonance_Hz"]
    if samples:
        r = run_uncertainty(p, uncertainty_spec(name), samples, FEEDS, [3], seed=0, workers=workers, progress=False)
        for rec in r.summary.itertuples():
            row[f"rigs_creep_{rec.feed_mm_s:g}_percent"] = rec.creep_percent
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--friction", choices=("coulomb", "stribeck", "lugre"), default=None)
    ap.add_argument("--samples", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    rows = [row_of(n, args.friction, args.samples, args.workers) for n in PRESETS]
    keys = list(rows[0])
    print(f"| quantity | {' | '.join(PRESETS)} |")
    print("| --- | " + " | ".join("---" for _ in PRESETS) + " |")
    for k in keys[1:]:
        cells = []
        for r in rows:
            v = r.get(k)
            cells.append(f"{v:.4g}" if isinstance(v, float) else str(v))
        print(f"| {k} | {' | '.join(cells)} |")


if __name__ == "__main__":
    main()
