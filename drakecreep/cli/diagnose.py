"""``drakecreep diagnose``: where the sim-to-real gap of the rigid model lies, which effect explains it, how far it shrinks.

DATA is an EMPS .mat file ('estimation' / 'validation' name the benchmark files) or a measured run: CSV,
Parquet, HDF5 or .mat with a metadata YAML beside it or given with --meta; units in the column headers
(t[ms], x_motor[mm], u[V]) are converted. The format is documented in docs/measured_format.md; an example
ships in drakecreep/data/examples/emps_segment.csv. A single-run file is split into out-and-back cycles; the
training runs are fitted, the held-out runs only scored. ``--score FILE`` finally scores the finished
diagnosis, with every parameter fixed, on another file (e.g. the EMPS validation set).
"""

import sys
from pathlib import Path

from drakecreep.cli._common import positive_float, print_json
from drakecreep.errors import InputError
from drakecreep.gap.runs import load_runs, pick  # noqa: F401 (re-exported: the library side)

__all__ = ["add_parser", "run", "load_runs", "pick"]


def add_parser(subparsers):
    """Register ``diagnose``."""
    p = subparsers.add_parser("diagnose", help="sim-to-real gap diagnosis of measured runs (where, which effect, shrink)",
                              description="\n\n".join(__doc__.split("\n\n")[:2]))
    p.add_argument("data", metavar="DATA", help="EMPS .mat file (or 'estimation'), or a measured run "
                   "(CSV/Parquet/HDF5/.mat + metadata YAML; see docs/measured_format.md)")
    p.add_argument("--meta", metavar="FILE", help="metadata YAML of a CSV (default: beside it)")
    p.add_argument("--train", metavar="RUNS", help="training runs: labels or indices, comma separated "
                   "(default: even indices)")
    p.add_argument("--test", metavar="RUNS", help="held-out runs (default: odd indices)")
    p.add_argument("--screw-lead", type=positive_float, default=2.5, metavar="MM",
                   help="screw lead [mm] (default 2.5: one EMPS motor revolution at the load)")
    p.add_argument("--motor-period", type=positive_float, metavar="MM",
                   help="table travel per motor revolution [mm] (default: the lead, direct drive)")
    p.add_argument("--score", metavar="FILE", help="after the diagnosis, score it (parameters fixed) on this file")
    p.add_argument("--out", metavar="DIR", help="write diagnosis.html and diagnosis.json here")
    p.add_argument("--json", action="store_true", help="print the JSON result on stdout")
    p.set_defaults(func=run)
    return p


def run(args):
    """Diagnose, print the answer, write the report."""
    from drakecreep.files import check_output_dir
    from drakecreep.gap.diagnosis import DiagnosisConfig, diagnose, score_fixed
    from drakecreep.report.gap_report import to_json_dict, write_report

    runs = load_runs(args.data, args.meta)
    train, test = pick(runs, args.train, 0, "--train"), pick(runs, args.test, 1, "--test")
    if set(r.label for r in train) & set(r.label for r in test):
        raise InputError("--test", args.test, "runs disjoint from the training runs")
    # everything the end of the run needs is checked before the diagnosis starts
    if args.out:
        check_output_dir(args.out)
    score_runs = load_runs(args.score, None) if args.score else None
    from drakecreep.gap.drake_replay import check_replayable

    for r in train + test:  # a controller it cannot replay, a missing params file: one line, before any work
        check_replayable(r)
    own = [r for r in test if r.meta.controller.kind == "drakecreep"]
    cfg = DiagnosisConfig(screw_lead=args.screw_lead * 1e-3,
                          motor_period=None if args.motor_period is None else args.motor_period * 1e-3,
                          progress=not args.quiet)
    # the rigid inverse-dynamics ranking; its closed-loop part replays the EMPS P-P law only
    result = diagnose(train, test, cfg, replay=not own)
    if own:
        from drakecreep.gap.drake_replay import drake_replay_errors, replay_drakecreep

        print(f"[diagnose] closed-loop replay of {len(own)} held-out run(s) through the project's diagram",
              file=sys.stderr, flush=True)
        errors = {r.label: drake_replay_errors(replay_drakecreep(r)) for r in own}
        result["drake_replay"] = errors
        result["summary"].append("Held-out replay through the drakecreep diagram of the params file, errors in % "
                                 "of ||y||: " + "; ".join(
                                     f"{k}: position {e['position']:.3g}, force {e['force']:.3g}"
                                     for k, e in errors.items()))
    result["data"] = str(args.data)
    result["train_runs"] = [r.label for r in train]
    result["test_runs"] = [r.label for r in test]
    if args.score:
        if not args.quiet:
            print(f"[diagnose] scoring the fixed diagnosis on {args.score}", file=sys.stderr, flush=True)
        result["scored"] = score_fixed(result, score_runs)
        result["scored"]["data"] = str(args.score)
    if args.out:
        html_path, json_path = write_report(result, args.out)
        if args.score:
            sc = dict(result["scored"])
            sc.update({"nominal": result["nominal"], "claimed": result["claimed"], "ranking": [],
                       "unexplained_share": sc["unexplained_share"]})
            write_report(sc, Path(args.out) / "scored", title=f"Fixed diagnosis scored on {args.score}")
        if not args.quiet:
            print(f"[diagnose] wrote {html_path} and {json_path}", file=sys.stderr)
    if args.json:
        print_json(to_json_dict(result))
    else:
        print("\n".join(result["summary"]))
        if args.score:
            print(f"Scored on {args.score} (parameters fixed):")
            print("\n".join(result["scored"]["summary"]))
    return 0
