"""Realistic gap benchmark of the product diagnosis (``diagnose_drake``): top-1, nulls, out-of-library, audit replay.

Datasets from :mod:`drakecreep.gap.truth` (see :mod:`drakecreep.gap.benchmark`), controller kind ``p_p_cascade``
(``diagnose_drake``) or, with ``--kinds drakecreep``, the project's own controller (``diagnose_drive`` on the params
file the truth's user would write; one to three hours per dataset: 3519-9727 s on a shared machine in run 3bm
of docs/gap_benchmark.md). The reported
figures use the held-out seeds (``--seeds heldout``, the default); ``--seeds dev`` is for debugging.

Rows are written to ``--json`` after every dataset (a run cut short still gives figures: ``--score FILE``
prints the scores of such a file); progress goes to stderr.

Run (about 2-4 min per dataset on one core)::

    PYTHONPATH=. nohup python analysis/bench_gap_benchmark.py --seeds heldout --n-per-effect 3 --n-null 6 \\
        --n-ool 3 --json heldout.json > heldout.txt 2> heldout.err &
    PYTHONPATH=. python analysis/bench_gap_benchmark.py --score heldout.json
    PYTHONPATH=. python analysis/bench_gap_benchmark.py ... --resume heldout.json --json heldout2.json  # go on
    # a drakecreep run that keeps each diagnosis's finished steps: killed in a dataset, it resumes inside it
    PYTHONPATH=. python analysis/bench_gap_benchmark.py --kinds drakecreep ... --checkpoints ckpt --json a.json
    PYTHONPATH=. python analysis/bench_gap_benchmark.py --kinds drakecreep ... --checkpoints ckpt --resume a.json \
        --json a2.json
    # two processes (or machines) sharing one run, scored together
    PYTHONPATH=. python analysis/bench_gap_benchmark.py ... --shard 0/2 --json a.json &
    PYTHONPATH=. python analysis/bench_gap_benchmark.py ... --shard 1/2 --json b.json &
    PYTHONPATH=. python analysis/bench_gap_benchmark.py --score a.json b.json
"""

import argparse
import json
import time

from drakecreep.cli._common import names
from drakecreep.files import check_output_dir, write_text
from drakecreep.errors import InputError
from drakecreep.gap.benchmark import (BENCHMARK_KINDS, DEFAULT_KINDS, DEV_SEEDS, HELDOUT_SEEDS, benchmark_specs,
                                      check_effects, check_mass_spread, check_uncertain, run_benchmark, score_rows)
from study_cli import read_rows, seed_list

TARGETS = {"top1_snr3": ">= 90 %", "claims_on_nulls": "<= 5 %", "out_of_library_unexplained": ">= 90 %",
           "median_relative_shrink_snr3": ">= 70 %", "claims_making_audit_worse": "0"}


def _pct(d):
    return "-" if d["rate"] is None else f"{100 * d['rate']:.0f} % (n={d['n']})"


def print_scores(s, indent=""):
    """Print one block of :func:`drakecreep.gap.benchmark.score_rows` with the targets beside the figures."""
    print(f"{indent}top-1 where SNR >= 3: {_pct(s['top1_snr3']):16s} target {TARGETS['top1_snr3']}   "
          f"(all SNR: {_pct(s['top1_all'])})")
    print(f"{indent}claims on nulls: {_pct(s['claims_on_nulls']):16s} target {TARGETS['claims_on_nulls']}")
    print(f"{indent}out-of-library answered unexplained: {_pct(s['out_of_library_unexplained']):16s} "
          f"target {TARGETS['out_of_library_unexplained']}")
    if s["no_candidate_unclaimed"]["n"]:
        print(f"{indent}no-candidate effects not claimed: {_pct(s['no_candidate_unclaimed'])}")
    m = s["median_relative_shrink_snr3"]
    print(f"{indent}median audit shrink / true effect's (SNR >= 3, n={s['n_relative_shrink']}): "
          f"{'-' if m is None else f'{100 * m:.0f} %'}   target {TARGETS['median_relative_shrink_snr3']}")
    print(f"{indent}claims making the audit replay worse: {s['claims_making_audit_worse']} of {s['n_claims']} claims"
          f"   target 0;  wrong first claims: {s['wrong_claims']}")


def report(res):
    """Print the scores of a benchmark result (``scores`` and ``datasets``)."""
    s = res["scores"]
    print_scores(s)
    for name, group in (("controller", s["per_kind"]), ("axis", s["per_axis"])):
        for k, b in group.items():
            print(f"{name} {k}:")
            print_scores(b, "  ")
    print("per effect (right = first claim is the expected candidate for library effects with SNR >= 3; "
          "no claim for nulls, no-candidate and out-of-library):")
    for e, d in sorted(s["per_effect"].items(), key=lambda kv: (kv[1]["category"], kv[0])):
        m = d["median_relative_shrink"]
        print(f"  {e:20s} {d['category']:14s} expected {str(d['expected'] or 'no claim'):20s} n={d['n']:2d} "
              f"scored={d['n_scored']:2d} right={_pct(d['right']):12s} median SNR {d['median_snr']:5.1f} "
              f"rel. shrink {'-' if m is None else f'{100 * m:.0f} %':>6s} worse {d['worse']}  "
              f"claimed: {', '.join(d['claimed']) or '-'}")
    print("datasets:")
    for r in res["datasets"]:
        a = r.get("audit") or {}
        e = {k: (None if v is None else v["force_rms"]) for k, v in a.items()}
        low = {k: (None if v is None else v.get("force_lowpass_rms")) for k, v in a.items()}
        f = lambda x: "-" if x is None else f"{x:.2f}"  # noqa: E731
        below = (f" (below 100 Hz {f(low.get('nominal'))} / {f(low.get('claimed'))} / {f(low.get('true'))})"
                 if low.get("nominal") is not None else "")  # rows written before the figure have none
        print(f"  {r['seed']} {r['axis']:8s} {(r['withheld'] or ['null'])[0]:20s} SNR {r['snr']:5.1f} "
              f"expected {str(r['expected'] or '-'):19s} claimed {'+'.join(r['claimed']) or '-':32s} "
              f"first passing {str(r['first_passing'] or '-'):19s} audit force % nom {f(e.get('nominal'))} "
              f"claimed {f(e.get('claimed'))} true {f(e.get('true'))}{below}  {r['seconds']:.0f} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-per-effect", type=int, default=3, help="diagnosed datasets per library effect with SNR >= 3")
    ap.add_argument("--n-null", type=int, default=6, help="null datasets")
    ap.add_argument("--n-ool", type=int, default=3, help="datasets per out-of-library and per no-candidate effect")
    ap.add_argument("--seeds", choices=("heldout", "dev"), default="heldout")
    ap.add_argument("--kinds", nargs="+", choices=BENCHMARK_KINDS, default=list(DEFAULT_KINDS),
                    help="controller kinds (default p_p_cascade)")
    ap.add_argument("--tries", type=float, default=4.0, help="candidates per library effect / --n-per-effect")
    ap.add_argument("--json", help="write scores and rows to this file (after every dataset)")
    ap.add_argument("--score", nargs="+", metavar="JSON",
                    help="only print the scores of JSON files written by this script (the shards of one run together)")
    ap.add_argument("--shard", default="0/1", metavar="I/N",
                    help="diagnose only every N-th dataset from the I-th (0-based): N processes share one run")
    ap.add_argument("--library", nargs="+", metavar="EFFECT",
                    help="withheld library effects to draw (default all; nulls and effects outside the library as "
                         "--n-null and --n-ool set)")
    ap.add_argument("--effects", metavar="NAMES",
                    help="candidates of the diagnosis of the one kind given, comma separated (default: its default "
                         "candidates; e.g. the drakecreep kind's defaults with asymmetric_friction, which it fits "
                         "only when named)")
    ap.add_argument("--uncertain", metavar="PATHS",
                    help="kinds drakecreep alone: the fields its nominal fit takes as uncertain, comma separated "
                         "(default diagnose_drive's: table.seal_force,nut.preload_torque,friction.viscous); a "
                         "development study of another nominal, e.g. with loads.constant_force")
    ap.add_argument("--mass-spread", type=float, default=0.0, metavar="S",
                    help="kind drakecreep: each params file's table.mass is the truth's times exp(N(0, S)), e.g. "
                         "0.15 (a workpiece left out or guessed; each row carries its mass_factor); default 0, exact")
    ap.add_argument("--resume", help="a JSON file of an interrupted run with the same settings: its datasets are "
                                     "not diagnosed again")
    ap.add_argument("--checkpoints", metavar="DIR",
                    help="a folder where each drakecreep dataset's diagnosis keeps its finished steps (nominal fit and "
                         "null, each candidate) until its row is written: with --resume and the same folder, a "
                         "dataset the run was killed in goes on where it was (same code only)")
    ap.add_argument("--skip-seeds", metavar="SEEDS", type=seed_list, default=(),
                    help="--seeds dev alone: datasets not to draw, comma-separated seeds or ranges (e.g. "
                         "114000-114003,104000): those an earlier study looked at; the next datasets take their place")
    args = ap.parse_args()
    if args.skip_seeds and args.seeds != "dev":
        ap.error(f"--skip-seeds: got {args.skip_seeds!r} with --seeds {args.seeds}; allowed: with --seeds dev only "
                 "(a held-out run draws its datasets as they come)")
    if args.score:
        by_seed = {}  # a resumed shard repeats the rows it resumed from: each dataset is scored once
        for path in args.score:
            for row in read_rows(ap, "--score", path)["datasets"]:
                by_seed[row["seed"]] = row
        data = {"datasets": list(by_seed.values())}
        data["scores"] = score_rows(data["datasets"])
        report(data)
        return
    try:
        shard = tuple(int(x) for x in args.shard.split("/"))
        if len(shard) != 2 or not 0 <= shard[0] < shard[1]:
            raise ValueError
    except ValueError:
        ap.error(f"--shard: got {args.shard!r}; allowed: I/N with integers 0 <= I < N")
    seed = HELDOUT_SEEDS if args.seeds == "heldout" else DEV_SEEDS
    if args.library is not None:
        try:  # before any dataset is generated
            benchmark_specs(seed, args.kinds, library=args.library)
        except InputError as err:
            ap.error(str(err))
    uncertain, effects = (None if text is None else names(text) for text in (args.uncertain, args.effects))
    try:  # run_benchmark's checks, before any dataset is generated
        check_uncertain(args.kinds, uncertain)
        check_effects(args.kinds, effects)
        check_mass_spread(args.mass_spread, args.kinds, "--mass-spread")
        if args.checkpoints is not None:
            check_output_dir(args.checkpoints, "--checkpoints")
    except InputError as err:
        ap.error(str(err))
    done = []
    if args.resume:
        earlier = read_rows(ap, "--resume", args.resume)
        if earlier.get("seed") != seed:
            raise SystemExit(f"--resume: {args.resume} has seeds from {earlier.get('seed')}; this run's are from {seed}")
        if float(earlier.get("mass_spread", 0.0)) != args.mass_spread:
            ap.error(f"--resume: {args.resume!r} was run with --mass-spread {earlier.get('mass_spread', 0.0)}; "
                     f"allowed: the same --mass-spread (got {args.mass_spread})")
        done = earlier["datasets"]
    t0 = time.perf_counter()

    def write(row, rows):
        if args.json:
            write_text(args.json, json.dumps({"seeds": args.seeds, "seed": seed, "mass_spread": args.mass_spread,
                                              "complete": False, "datasets": rows}, indent=1, default=str))

    res = run_benchmark(seed=seed, kinds=args.kinds, n_per_effect=args.n_per_effect, n_null=args.n_null, n_ool=args.n_ool,
                        progress=True, tries=args.tries, on_row=write, done=done, shard=shard, library=args.library,
                        uncertain=uncertain, effects=effects, skip=args.skip_seeds, mass_spread=args.mass_spread,
                        checkpoints=args.checkpoints)
    s = res["scores"]
    print(f"{s['n_datasets']} datasets diagnosed, {args.seeds} seeds from {seed}, {', '.join(args.kinds)}, "
          f"{time.perf_counter() - t0:.0f} s; candidates skipped for SNR < 3: {res['low_snr_skipped']}; "
          f"effects short of {args.n_per_effect} datasets with SNR >= 3: {res['short'] or 'none'}")
    report(res)
    if args.json:
        write_text(args.json, json.dumps(dict(res, seeds=args.seeds, seed=seed, mass_spread=args.mass_spread,
                                              complete=True), indent=1, default=str))


if __name__ == "__main__":
    main()
