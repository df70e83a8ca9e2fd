"""``drakecreep gap-benchmark``: datasets from an independent, richer truth with withheld effects, diagnosed blind by
the product diagnosis of each controller kind (``diagnose_drake`` for p_p_cascade, ``diagnose_drive`` on a
declared params file for drakecreep), scored on audit runs it never sees."""

import json
import sys

from drakecreep.cli._common import integer_in, names, print_json

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Register ``gap-benchmark``.

    Nothing of the library is imported here (the benchmark pulls in SciPy and Drake, seconds that every
    ``drakecreep --help`` and every mistyped option paid): the kinds are checked by ``check_kinds`` in :func:`run`,
    and the help names them (``tests/cli/test_gap_benchmark.py`` holds it to ``BENCHMARK_KINDS``)."""
    p = subparsers.add_parser("gap-benchmark", help="withheld-effect benchmark of the gap diagnosis on realistic data",
                              description=__doc__)
    p.add_argument("--seeds", choices=("heldout", "dev"), default="heldout",
                   help="held-out seeds (reported; never used while tuning) or development seeds (tests, debugging)")
    p.add_argument("--kinds", nargs="+", metavar="KIND",
                   help="controller kinds of the truth: p_p_cascade (the default) and/or drakecreep (diagnosed by "
                        "diagnose_drive on the params file its user would write, minutes per dataset)")
    p.add_argument("--n-per-effect", type=datasets, default=10,
                   help="datasets per library effect with SNR >= 3 (default 10)")
    p.add_argument("--n-null", type=datasets, default=10, help="null datasets per controller kind (default 10)")
    p.add_argument("--n-ool", type=datasets, default=6,
                   help="datasets per out-of-library and per no-candidate effect and kind (default 6)")
    p.add_argument("--samples", type=samples, default=3000, help="samples per run at 1 kHz (default 3000)")
    p.add_argument("--effects", help="comma-separated candidates of the diagnosis of the one kind given (default: "
                                     "all; a subset is for quick checks: the reported figures use all)")
    p.add_argument("--mass-spread", type=float, default=0.0, metavar="S",
                   help="kind drakecreep: each params file's table.mass is the truth's times exp(N(0, S)), e.g. "
                        "0.15 for a workpiece left out or guessed (default 0: the truth's mass)")
    p.add_argument("--out", metavar="DIR",
                   help="keep the run here: rows.json after every dataset, each drakecreep diagnosis's finished "
                        "steps in checkpoints/, and at the end results.json and manifest.json; the same command "
                        "run again with this folder resumes where a stop or a kill left it (other settings are "
                        "refused)")
    p.add_argument("--json", action="store_true", help="print JSON (scores and per-dataset rows)")
    p.set_defaults(func=run)
    return p


#: largest --n-per-effect / --n-null / --n-ool (datasets of minutes each)
MAX_DATASETS = 1000
#: longest run of --samples (1000 s at 1 kHz)
MAX_SAMPLES = 1_000_000


def datasets(text):
    """argparse type of --n-per-effect, --n-null and --n-ool: an integer in [0, :data:`MAX_DATASETS`] (one range, said
    one way: -1 had been 'an integer >= 0' and 1001 'an integer in [0, 1000]')."""
    return integer_in(text, 0, MAX_DATASETS)


def samples(text):
    """argparse type of --samples: an integer in [600, :data:`MAX_SAMPLES`]."""
    return integer_in(text, 600, MAX_SAMPLES)


#: the file of ``--out`` that holds the rows as they come (and the settings they were run with)
ROWS = "rows.json"


def _earlier_rows(out, settings):
    """The rows a run with the same ``settings`` left in ``out`` (none without a rows file); a folder holding a run
    of other settings, or a rows file that cannot be read, is refused naming ``--out``."""
    from drakecreep.errors import InputError
    from drakecreep.files import read_input_text

    path = out / ROWS
    if not path.exists():
        return []
    try:
        earlier = json.loads(read_input_text(path, "--out"))
        rows, before = earlier["datasets"], earlier["settings"]
        if not isinstance(rows, list) or not isinstance(before, dict):
            raise TypeError
    except InputError:
        raise
    except (ValueError, KeyError, TypeError):
        raise InputError("--out", str(out), f"a folder whose {ROWS} is one this command wrote, or another "
                                            "folder") from None
    if before != settings:
        other = ", ".join(f"{k} {before.get(k)!r}" for k in settings if before.get(k) != settings[k])
        raise InputError("--out", str(out), f"a folder of a run with the same settings (it holds one with {other}), "
                                            "or another folder")
    return rows


def run(args):
    """Run and print the scores (each dataset takes minutes: its kind's diagnosis fits every candidate)."""
    from drakecreep.errors import InputError
    from drakecreep.files import OutputSet, check_output_dir, to_jsonable, write_json
    from drakecreep.gap.benchmark import (DEFAULT_KINDS, DEV_SEEDS, HELDOUT_SEEDS, check_effects, check_kinds,
                                          check_mass_spread, run_benchmark)

    kinds = DEFAULT_KINDS if args.kinds is None else check_kinds(args.kinds, "--kinds")
    if args.n_per_effect + args.n_null + args.n_ool == 0:
        raise InputError("--n-per-effect/--n-null/--n-ool", 0, "at least one dataset")
    effects = None if args.effects is None else check_effects(kinds, names(args.effects, "--effects"), "--effects")
    mass_spread = check_mass_spread(args.mass_spread, kinds, "--mass-spread")
    seed = HELDOUT_SEEDS if args.seeds == "heldout" else DEV_SEEDS
    settings = {"seeds": args.seeds, "kinds": list(kinds), "n_per_effect": args.n_per_effect, "n_null": args.n_null,
                "n_ool": args.n_ool, "samples": args.samples, "effects": None if effects is None else list(effects),
                "mass_spread": mass_spread}
    out, done, keep = None, [], None  # without --out: nothing kept, the rows only in the answer
    if args.out is not None:
        out = check_output_dir(args.out)
        done = _earlier_rows(out, settings)
        if done and not args.quiet:
            print(f"[gap-benchmark] resuming the run in {out}: {len(done)} datasets diagnosed in it", file=sys.stderr)

        def write_rows(row, rows):  # after every dataset, atomically: a stop or a kill keeps the rows so far
            write_json(out / ROWS, {"settings": settings, "complete": False, "datasets": rows}, indent=1)

        keep = write_rows

    res = run_benchmark(seed=seed, kinds=kinds, n_per_effect=args.n_per_effect, n_null=args.n_null,
                        n_ool=args.n_ool, progress=not args.quiet, n_samples=args.samples, effects=effects,
                        mass_spread=mass_spread, done=done, on_row=keep,
                        checkpoints=None if out is None else out / "checkpoints")
    if out is not None:
        with OutputSet(out, "manifest.json") as files:
            files.write_text(ROWS, json.dumps(to_jsonable({"settings": settings, "complete": True,
                                                           "datasets": res["datasets"]}), indent=1) + "\n")
            files.write_text("results.json", json.dumps(to_jsonable(dict(res, settings=settings)), indent=1) + "\n")
            files.commit({"kind": "drakecreep.gap_benchmark", "datasets": len(res["datasets"])})
        if not args.quiet:
            print(f"[gap-benchmark] wrote {out}/results.json, {ROWS} and manifest.json", file=sys.stderr)
    if args.json:
        print_json(res)
        return 0
    s = res["scores"]

    def pct(d):
        return "-" if d["rate"] is None else f"{100 * d['rate']:.0f} % (n={d['n']})"

    print(f"datasets diagnosed: {s['n_datasets']} ({args.seeds} seeds from {seed}); "
          f"skipped for SNR < 3: {sum(res['low_snr_skipped'].values())}")
    print(f"top-1 where SNR >= 3: {pct(s['top1_snr3'])} (target >= 90 %)")
    print(f"claims on null datasets: {pct(s['claims_on_nulls'])} (target <= 5 %)")
    print(f"out-of-library answered unexplained: {pct(s['out_of_library_unexplained'])} (target >= 90 %)")
    if s["no_candidate_unclaimed"]["n"]:
        print(f"no-candidate effects not claimed: {pct(s['no_candidate_unclaimed'])}")
    m = s["median_relative_shrink_snr3"]
    print("median audit replay shrink relative to the true effect's (SNR >= 3): "
          + ("-" if m is None else f"{100 * m:.0f} %") + " (target >= 70 %)")
    print(f"claims making the audit replay worse: {s['claims_making_audit_worse']} of {s['n_claims']} (target 0); "
          f"wrong first claims: {s['wrong_claims']}")
    for a, b in s["per_axis"].items():
        print(f"  {a} axis: top-1 {pct(b['top1_snr3'])}, nulls claimed {pct(b['claims_on_nulls'])}, "
              f"out-of-library unexplained {pct(b['out_of_library_unexplained'])}")
    for e, d in sorted(s["per_effect"].items()):
        print(f"  {e}: expected {d['expected'] or 'no claim'}, right {pct(d['right'])}, median SNR {d['median_snr']:.1f}, "
              f"claimed {', '.join(d['claimed']) or '-'}")
    print("", file=sys.stderr)
    return 0
