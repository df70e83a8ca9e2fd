"""Eq. 11 against simulation, per friction law, per drive and per load case (issue 15).

For the ``paper`` preset (ball nut's drag on the screw, catalogue-sized) and each friction law, the
critical speed of eq. 11 (:func:`drakecreep.paper.creep.critical_speed_of` of
:func:`drakecreep.model.lumped.lumped`: the friction on the table, i.e. the guides' share) is set beside
the simulated boundary (:func:`drakecreep.studies.paper_reproduction.simulated_creep_boundary`: the
fastest creeping feed, bisected) of

* ``constant_speed``: the paper's Fig. 2 mechanism (motor side at exactly the feed speed: the nut's drag
  on the screw is absorbed by the drive), what eq. 11 models;
* ``cascade``: the machine with its sampled PI cascade.

Every simulated verdict is checked for convergence by ``simulate`` (10x tighter accuracy rerun).
Prints a table and writes ``out/eq11_by_law/eq11_by_law.csv``.

Run: ``python analysis/eq11_by_law.py [--laws coulomb,stribeck@1e-6,stribeck,lugre] [--load-cases 0,3] [--drives constant_speed,cascade]``
"""

import argparse
import time
from pathlib import Path

import pandas as pd

from drakecreep.model.lumped import lumped
from drakecreep.paper.creep import critical_speed_of
from drakecreep.params import preset, with_value
from drakecreep.studies.paper_reproduction import simulated_creep_boundary


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--laws", default="coulomb,stribeck@1e-6,stribeck,lugre",
                    help="friction laws; law@VS sets the Stribeck velocity VS m/s (stribeck@1e-6: a step drop)")
    ap.add_argument("--load-cases", default="0,3")
    ap.add_argument("--drives", default="constant_speed,cascade")
    ap.add_argument("--duration", type=float, default=2.0, help="simulated seconds per feed (default 2)")
    ap.add_argument("--iterations", type=int, default=4, help="bisection steps (default 4)")
    ap.add_argument("--out", default="out/eq11_by_law")
    args = ap.parse_args()
    rows = []
    for spec in args.laws.split(","):
        law, _, vs = spec.partition("@")  # "stribeck@1e-6": that law with friction.stribeck_velocity = 1e-6 m/s
        p = with_value(preset("paper"), "friction.law", law)
        if vs:
            p = with_value(p, "friction.stribeck_velocity", float(vs))
        for lc in (int(x) for x in args.load_cases.split(",")):
            d = lumped(p, lc)
            v0 = critical_speed_of(d) * 1e3
            for drive in args.drives.split(","):
                t0 = time.perf_counter()
                sim = simulated_creep_boundary(p, lc, lo=0.02e-3, hi=3e-3, points=8, iterations=args.iterations,
                                               duration=args.duration, drive=drive) * 1e3
                rows.append(dict(law=spec, load_case=lc, drive=drive, Fc_table_N=d.coulomb, Fs_table_N=d.breakaway,
                                 eq11_mm_s=v0, simulated_mm_s=sim, eq11_over_simulated=v0 / sim if sim else float("nan"),
                                 wall_s=time.perf_counter() - t0))
                print({k: (round(v, 4) if isinstance(v, float) else v) for k, v in rows[-1].items()}, flush=True)
    df = pd.DataFrame(rows)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    df.to_csv(out / "eq11_by_law.csv", index=False)
    print(df.to_string(index=False, float_format=lambda v: f"{v:.3g}"))


if __name__ == "__main__":
    main()
