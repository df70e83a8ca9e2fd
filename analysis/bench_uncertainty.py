"""Uncertainty study of the paper rig (issue 15): its time, and what it finds.

1. **Baseline** (this run): the nominal paper rig at 0.1 mm/s, load case 3, simulated once with
   ``simulate()`` in this process (after one warm-up run); ``N x`` that time is what the study would take
   case by case on one core.
2. **Study**: ``--samples`` plausible rigs (default 200; the ``[assumed]`` values of ``presets/paper.yaml``
   drawn from ``presets/paper_uncertainty.yaml``, Latin hypercube, ``--seed``) at 5 feeds (0.05-1 mm/s),
   load case 3, ``--duration`` s each, through ``run_sweep`` on ``--workers`` local processes (batched).
   Target: < 300 s on 2 cores. Printed: wall time, wall / 300 s, and wall / (baseline x N).
3. **Results**: per feed the share of rigs that creep (95 % Wilson interval) and the fluctuation
   percentiles; per parameter Spearman's rho with the creep verdict over the 0.05-0.2 mm/s cases.
4. **Convergence spot check** (``--check K``): K cases of the study drawn at random (seeded) rerun one by
   one at 10x tighter accuracy; the share whose creep verdict agrees is printed.
5. **Held-out seed** (``--holdout S``): the shares at 0.05-0.2 mm/s again from an independent sample.

Run: ``python analysis/bench_uncertainty.py [--samples 200] [--workers 2] [--check 40] [--holdout 1]``
(writes out/bench_uncertainty/).
"""

import argparse
import time

import numpy as np
import pandas as pd

from drakecreep.sim.simulation import target_accuracy
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
from drakecreep.studies.uncertainty import run_uncertainty, sensitivity, summarize, uncertainty_spec

FEEDS = (0.05e-3, 0.1e-3, 0.2e-3, 0.5e-3, 1.0e-3)
LOW_FEEDS = (0.05e-3, 0.1e-3, 0.2e-3)


def _shares(summary):
    return ", ".join(f"{r.feed_mm_s:g} mm/s {r.creep_percent:.0f} % [{r.creep_low_percent:.0f}-{r.creep_high_percent:.0f}]"
                     for r in summary.itertuples())


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=200)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--duration", type=float, default=3.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--check", type=int, default=40, help="cases rerun at 10x tighter accuracy (0 = none)")
    ap.add_argument("--holdout", type=int, default=None, help="seed of an independent sample at 0.05-0.2 mm/s")
    ap.add_argument("--preset", default="paper")
    ap.add_argument("--out", default="out/bench_uncertainty")
    args = ap.parse_args()
    pd.set_option("display.width", 200)
    pd.set_option("display.max_columns", 20)

    base = preset(args.preset)
    spec = uncertainty_spec("paper")
    scenario = Scenario(feed=0.1e-3, load_case=3, duration=args.duration)
    simulate(base, scenario)  # warm-up (imports, first compile)
    t0 = time.perf_counter()
    nominal = simulate(base, scenario)
    one = time.perf_counter() - t0
    n_cases = args.samples * len(FEEDS)
    print(f"baseline: one case (nominal rig, 0.1 mm/s, load case 3, {args.duration:g} s) serially: {one:.2f} s; "
          f"x {n_cases} cases = {one * n_cases:.0f} s on one core")
    print(f"nominal rig ({args.preset}) at 0.1 mm/s: creep {nominal.metrics.creep}, "
          f"fluctuation {nominal.metrics.max_fluctuation * 1e3:.4f} mm/s")

    result = run_uncertainty(base, spec, args.samples, FEEDS, [3], seed=args.seed, duration=args.duration,
                             workers=args.workers, out_dir=args.out, progress=False)
    wall = result.wall_time
    print(f"study: {args.samples} rigs x {len(FEEDS)} feeds = {n_cases} cases on {args.workers} workers: "
          f"{wall:.1f} s = {wall / 300:.2f} x the 300 s target, {wall / (one * n_cases):.3f} x the serial baseline "
          f"({result.failed} failed; {result.table.get('status', pd.Series()).eq('ok').sum()} ok)")
    print("\nper feed, load case 3 (creep share with 95 % interval; fluctuation percentiles in mm/s):")
    print(result.summary.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    table = result.table
    low = table[table["feed"].isin(LOW_FEEDS)]
    ok = low[low["status"] == "ok"]
    any_creep = ok.groupby("rig")["creep"].any()
    all_creep = ok.groupby("rig")["creep"].all()
    print(f"\nat 0.05-0.2 mm/s: {100 * ok['creep'].mean():.0f} % of (rig, feed) cases creep; "
          f"{100 * any_creep.mean():.0f} % of rigs creep at one of the three feeds at least, "
          f"{100 * all_creep.mean():.0f} % at all three")
    sens = sensitivity(low, spec)
    print("\nwhat decides creep at 0.05-0.2 mm/s (Spearman rho with the verdict; creep % in the lower / upper half "
          "of the range):")
    print(sens[["parameter", "dist", "low", "high", "rho_creep", "rho_fluctuation", "creep_low_half_percent",
                "creep_high_half_percent"]].to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    sens.to_csv(f"{args.out}/sensitivity_low_feeds.csv", index=False)

    if args.check:
        rng = np.random.default_rng(12345)
        pick = table[table["status"] == "ok"].sample(n=min(args.check, len(table)), random_state=rng)
        agree, flips = 0, []
        t0 = time.perf_counter()
        for _, row in pick.iterrows():
            params = base
            for path in spec.paths:
                params = with_value(params, path, float(row[path]))
            params = with_value(params, "simulation.accuracy", target_accuracy(base) / 10)
            tight = simulate(params, Scenario(feed=float(row["feed"]), load_case=3, duration=args.duration))
            same = bool(tight.metrics.creep) == bool(row["creep"])
            agree += same
            if not same:
                flips.append((int(row["rig"]), float(row["feed"]) * 1e3, bool(row["creep"])))
        print(f"\nconvergence: {agree}/{len(pick)} verdicts unchanged at accuracy {target_accuracy(base) / 10:g} "
              f"({time.perf_counter() - t0:.0f} s); changed (rig, feed mm/s, default verdict): {flips}")

    if args.holdout is not None:
        held = run_uncertainty(base, spec, args.samples, LOW_FEEDS, [3], seed=args.holdout, duration=args.duration,
                               workers=args.workers, progress=False)
        print(f"\nheld-out seed {args.holdout}: {_shares(held.summary)}")
        print(f"seed {args.seed}:          {_shares(summarize(low))}")


if __name__ == "__main__":
    main()
