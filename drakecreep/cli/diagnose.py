"""``drakecreep diagnose``: where the sim-to-real gap of the Drake replay model lies, which effect explains it, how far it shrinks.

DATA is an EMPS .mat file ('estimation' / 'validation' name the benchmark files) or a measured run: CSV,
Parquet, HDF5 or .mat with a metadata YAML beside it or given with --meta; units in the column headers
(t[ms], x_motor[mm], u[V]) are converted. The format is documented in docs/measured_format.md; an example
ships in drakecreep/data/examples/emps_segment.csv. A single-run file is split at every reversal of the
reference; by default alternate pairs of parts train and are held out (--train/--test choose). The
training runs are fitted, the held-out runs only replayed with every parameter fixed. A p_p_cascade run may be
logged every controller tick (controller.sample_time), every few ticks (the controller is replayed on its tick),
or several times a tick (cut to the ticks, where the held u changes).

Runs of controller kind p_p_cascade are replayed in closed loop through the Drake model (P-P cascade +
MeasuredAxis, docs/gap_diagnosis.md): the nominal axis is identified on the training runs, every candidate
effect is screened on inverse dynamics, fitted in closed loop and replayed on the held-out runs, and the
effects that pass are added greedily. --out writes ranking.json as soon as the ranking is known, then
diagnosis.html, diagnosis.json and augmented_model.yaml; ``--score FILE`` replays the augmented model, every
parameter fixed, on another file (e.g. the EMPS validation set), whole runs.

Runs of controller kind drakecreep (the project's PI cascade, a params file in the metadata) are replayed through
that params file's drive diagram (docs/gap_drakecreep_kind.md): the --uncertain values are fitted by output error
with 95 % intervals, the Drake model's candidate effects are fitted and claimed on the held-out runs. --out writes
nominal_params.yaml when the nominal fit ends and ranking.json after each candidate, then diagnosis.html,
diagnosis.json, summary.txt and augmented_params.yaml (for simulate, margins and report --params).
"""

import os
import sys
from pathlib import Path

from drakecreep.cli._common import existing_path, names, path_exists, print_json, regular_file, workers
from drakecreep.errors import InputError, renaming
from drakecreep.gap.runs import CYCLE_MIN_TIME, HALF_CYCLE_MIN_TIME, load_runs, min_samples, train_test
from drakecreep.gap.runs import pick  # noqa: F401 (re-exported: the library side)
from drakecreep.processes import usable_cpus

__all__ = ["add_parser", "run", "load_runs", "pick", "CHECKPOINT"]

#: the file in ``--out`` where a ``kind: drakecreep`` diagnosis keeps its finished steps until its manifest is written
CHECKPOINT = "checkpoint.pkl"


def add_parser(subparsers):
    """Register ``diagnose``."""
    p = subparsers.add_parser("diagnose", help="sim-to-real gap diagnosis of measured runs (where, which effect, shrink)",
                              description="\n\n".join(__doc__.split("\n\n")[:4]))
    p.add_argument("data", metavar="DATA", help="EMPS .mat file (or 'estimation'), or a measured run "
                   "(CSV/Parquet/HDF5/.mat + metadata YAML; see docs/measured_format.md)")
    p.add_argument("--meta", metavar="FILE", help="metadata YAML of a CSV (default: beside it)")
    p.add_argument("--train", metavar="RUNS", help="training runs: labels or indices, comma separated "
                   "(default: the runs --test does not name; without --test: even indices; parts of one split run: "
                   "0, 1, 4, 5, ...; three runs or parts: 0)")
    p.add_argument("--test", metavar="RUNS", help="held-out runs, at least two (default: the runs --train does not "
                   "name; without --train: odd indices; parts of one split run: 2, 3, 6, 7, ...; three runs or "
                   "parts: 1, 2)")
    p.add_argument("--uncertain", metavar="PATHS", help="kind drakecreep runs: the params-file values to fit, "
                   "comma separated (default: table.seal_force,nut.preload_torque,friction.viscous; add "
                   "loads.constant_force for a constant axial force such as a drive's offset, table.mass for a "
                   "workpiece the params file leaves out)")
    # The names are written out, not imported: the parser is built without the libraries behind it (checked
    # against drake_effects.DRAKE_EFFECTS and drive_fit.DEFAULT_EFFECTS by tests/cli/test_diagnose.py).
    p.add_argument("--effects", metavar="NAMES", help="candidate effects, comma separated (default: all ranked "
                   "ones: stribeck, asymmetric_friction, load_friction, position_friction, position_ripple, "
                   "lead_error, time_ripple, thermal_drift, drive_saturation, axial_mode, control_delay; kind "
                   "drakecreep runs: lead_error, force_ripple, stribeck, law_coulomb, law_stribeck, law_lugre, "
                   "law_gms, nut_friction_side, control_delay; asymmetric_friction, cogging, position_friction, "
                   "drive_saturation, backlash, structural_mode and friction_drift only when named)")
    p.add_argument("--nominal-friction", choices=("regularized", "lugre", "auto"), help="p_p_cascade runs: friction law "
                   "of the nominal axis: regularized Coulomb (default; creeps under any force), lugre (bristles: "
                   "sticks below the breakaway force, the share of the friction that sticks fitted; slower), "
                   "auto (both, the lower training cost kept)")
    p.add_argument("--score", metavar="FILE", help="after the diagnosis, replay the augmented model (parameters "
                   "fixed) on this file")
    p.add_argument("--out", metavar="DIR", help="write ranking.json, diagnosis.html, diagnosis.json and "
                   "augmented_model.yaml here (kind drakecreep runs: augmented_params.yaml for simulate/margins/"
                   "report --params, diagnosis.html, diagnosis.json, summary.txt; a run stopped or failed keeps its "
                   f"finished steps in {CHECKPOINT}, and the same command resumes there)")
    p.add_argument("--workers", type=workers, metavar="N", default=usable_cpus(),
                   help=f"processes for the closed-loop replays (p_p_cascade: the candidates' fits, and as many "
                        f"threads in each for the runs of one evaluation; drakecreep: the runs, Jacobian columns and "
                        f"candidates; default, and the most processes started: the {usable_cpus()} CPUs this process "
                        f"may use; 1: all in this process, one at a time)")
    p.add_argument("--json", action="store_true", help="print the JSON result on stdout")
    p.set_defaults(func=run)
    return p


def run(args):
    """Check everything, diagnose, print the answer, write the report."""
    from drakecreep.files import check_output_dir
    from drakecreep.gap.drake_replay import check_replayable
    from drakecreep.gap.measured import EMPS_FILES

    for option, path in (("DATA", args.data), ("--score", args.score)):
        if path and path not in EMPS_FILES and not path_exists(option, path):
            raise InputError(option, path, "an existing file: a measured run (CSV, Parquet, HDF5, .mat with its "
                             "metadata beside it) or an EMPS .mat ('estimation' / 'validation' name the benchmark's)")
        if path and path not in EMPS_FILES:
            regular_file(option, path)  # a folder was told 'metadata: got 'adir.yaml''
    if args.score and (args.score == args.data or (args.score not in EMPS_FILES and args.data not in EMPS_FILES
                                                   and os.path.samefile(args.score, args.data))):
        # allowed (whole runs of the file, as the EMPS protocol replays them), but not a held-out score: said so
        print(f"drakecreep diagnose: note: --score {args.score} is DATA itself: its runs include those the model is "
              "fitted on, so its score is not a held-out one", file=sys.stderr, flush=True)
    notes = []
    runs = _in_file("", lambda data: load_runs(data, existing_path("--meta", args.meta), split=False, notes=notes),
                    args.data, {"meta": "--meta"})
    own = any(r.meta.controller is not None and r.meta.controller.kind == "drakecreep" for r in runs)
    # one long run is cut: at every reversal for the Drake path (pairs of half cycles train / are held out, so
    # both sets move both ways), into out-and-back cycles for the kind drakecreep branch
    split = len(runs) == 1
    if split:
        whole = runs[0]
        runs = load_runs(args.data, args.meta, split=True if own else "half")
        if len(runs) < 3 and not (args.train or args.test):
            # too short, or too few reversals of the reference: say so, not "no training run"
            least = CYCLE_MIN_TIME if own else HALF_CYCLE_MIN_TIME
            what = (f"{'out-and-back cycle' if own else 'part between reversals'}{'' if len(runs) == 1 else 's'}"
                    f" of >= {least:g} s ({min_samples(whole, least)} samples)")
            raise InputError(f"DATA {Path(str(args.data)).name}", f"one run of {whole.n} samples "
                             f"({whole.n * whole.dt:.3g} s): {len(runs)} {what}",
                             "at least 3 parts (1 to train, 2 held out): a longer run, or several runs")
    pairs = split and not own
    train, test = train_test(runs, args.train, args.test, pairs=pairs)
    if set(r.label for r in train) & set(r.label for r in test):
        raise InputError("--test", args.test, "runs disjoint from the training runs")
    # everything the end of the run needs is checked before the diagnosis starts
    if args.out:
        check_output_dir(args.out)
    for r in train + test:  # a controller it cannot replay, a missing params file
        _in_file(f"{args.data}: ", check_replayable, r)
    if not train:
        raise InputError("--train", args.train, "at least one training run")
    if len(test) < 2:  # both kinds (the drakecreep kind's library said 'test: got 1')
        raise InputError("--test", args.test or f"{len(test)} run(s) of {', '.join(r.label for r in runs)}",
                         "at least two held-out runs (the claim threshold is their run-to-run spread; "
                         "choose with --train/--test)")
    # the Drake path replays whole scored runs (as the EMPS validation protocol); the drakecreep branch its cycles
    # a refusal of the scored file's loading says it is the --score file (a file may be diagnosed and scored alike)
    score_runs = _in_file("--score ", lambda data: load_runs(data, None, split=own, notes=notes), args.score) \
        if args.score else None
    for line in notes:  # how a log at another rate than the controller's tick is read (a wrong sample_time shows)
        print(f"drakecreep diagnose: note: {line}", file=sys.stderr, flush=True)
    kind = "drakecreep" if own else "p_p_cascade"
    for r in score_runs or ():
        _in_file(f"--score {args.score}: ", check_replayable, r)  # which of the two files (both had 'run: got ...')
        if r.meta.controller.kind != kind:  # a p_p_cascade file scored through a params file: exit 0, 1e4 % errors
            raise InputError("--score", args.score, f"runs of controller kind {kind}, like the diagnosed ones")
        if own:  # what the replay at the end would refuse (a sensor resolution off the lead), before the diagnosis
            from drakecreep.gap.drive_fit import check_run

            _in_file(f"--score {args.score}: ", lambda run: check_run(run, train[0].meta.params), r)
    if own:
        if args.nominal_friction:
            raise InputError("--nominal-friction", args.nominal_friction, "only for runs of controller kind p_p_cascade (kind "
                             "drakecreep: the params file's friction.law, effect law_lugre)")
        return _run_drakecreep_kind(args, train, test, score_runs)
    if args.uncertain:
        raise InputError("--uncertain", args.uncertain, "only for runs of controller kind drakecreep "
                         "(p_p_cascade runs fit viscous, Coulomb and offset)")
    effects = None
    if getattr(args, "effects", None):
        from drakecreep.gap.drake_effects import DRAKE_EFFECTS, NOT_RANKED

        effects = names(args.effects, "--effects")
        for e in effects:
            if e != "control_delay" and e not in DRAKE_EFFECTS:
                raise InputError("--effects", e, NOT_RANKED.get(e, "names among " + ", ".join(
                    tuple(DRAKE_EFFECTS) + ("control_delay",))))
    return _run_drake(args, train, test, score_runs, effects, notes)


def _in_file(prefix, check, run, options=None):
    """``check(run)``, its :class:`InputError` naming the file the run is from (``prefix``), or the CLI option of a
    library parameter (``options``, e.g. ``{"meta": "--meta"}``)."""
    return renaming(lambda field: (options or {}).get(field) or prefix + str(field), check, run)


def _say(args):
    quiet = getattr(args, "quiet", False)
    return (lambda line: None) if quiet else (lambda line: print(f"[diagnose] {line}", file=sys.stderr, flush=True))


def _run_drake(args, train, test, score_runs, effects=None, notes=()):
    """The product path: :func:`drakecreep.gap.drake_diagnosis.diagnose_drake` on p_p_cascade runs."""
    import json

    from drakecreep.files import OutputSet
    from drakecreep.gap.drake_diagnosis import diagnose_drake
    from drakecreep.gap.drake_effects import score_parameters
    from drakecreep.report.gap_report import drake_to_json_dict, ranking_json, write_drake_report

    say = _say(args)
    outset = OutputSet(args.out, "manifest.json").start() if args.out else None
    extra = {"data": str(args.data), "train_runs": [r.label for r in train], "test_runs": [r.label for r in test]}
    if notes:
        extra["log_rate"] = list(notes)

    def keep_ranking(nominal, nominal_test, ranking):
        if outset is not None:  # written before the greedy augmentation: a late failure keeps it
            body = dict(ranking_json(nominal, nominal_test, ranking), **extra)
            path = outset.write_text("ranking.json", json.dumps(body, indent=1))
            say(f"ranking written to {path}")

    say(f"{len(train)} training, {len(test)} held-out runs; identifying the nominal axis")
    diag = diagnose_drake(train, test, effects, progress=say, on_ranking=keep_ranking,
                          workers=args.workers, friction=args.nominal_friction or "regularized")
    model = diag.model
    if score_runs:
        say(f"replaying the augmented model on {args.score} (parameters fixed)")
        nominal_scored, _ = score_parameters(score_runs, diag.nominal.parameters, delay=diag.nominal.delay)
        augmented_scored, _ = score_parameters(score_runs, model["parameters"], flexible=model["flexible"],
                                               delay=model["delay"])
        extra["scored"] = {"data": str(args.score), "nominal": nominal_scored, "augmented": augmented_scored}
    if outset is not None:
        residuals = _residuals(diag, test[0])
        outset.write("augmented_model.yaml", lambda tmp: diag.save_model(tmp))
        html_path, _ = write_drake_report(diag, args.out, residuals=residuals, outset=outset, **extra)
        outset.commit(dict(report="sim-to-real gap diagnosis (Drake model)", html="diagnosis.html",
                           json="diagnosis.json", model="augmented_model.yaml", ranking="ranking.json"))
        say(f"wrote {html_path}, diagnosis.json and augmented_model.yaml")
    if args.json:
        print_json(drake_to_json_dict(diag, **extra))
        return 0
    print("\n".join(diag.summary()))
    if score_runs:
        print(f"Replayed on {args.score} (every parameter fixed), force error [%] nominal -> augmented:")
        for lab, e in extra["scored"]["augmented"].items():
            n = extra["scored"]["nominal"][lab]
            print(f"  {lab}: force {n['force']:.3f} -> {e['force']:.3f}, position {n['position']:.4g} -> "
                  f"{e['position']:.4g}")
    return 0


def _residuals(diag, run):
    """Measured minus replayed force and position of one held-out run, nominal and augmented (for the report)."""
    from drakecreep.gap.drake_replay import make_replay

    out = {"label": run.label, "t": run.t - run.t[0]}
    m = diag.model
    for key, params, flexible, delay in (("nominal", diag.nominal.parameters, False, diag.nominal.delay),
                                         ("augmented", m["parameters"], m["flexible"], m["delay"])):
        res = make_replay(run, flexible=flexible, delay=delay, free=()).simulate(params)
        out[key] = {"force": run.force - res.force, "position": run.x_motor - res.x_motor}
    return out


def _run_drakecreep_kind(args, train, test, score_runs):
    """Runs of ``controller: {kind: drakecreep}`` (the project's own PI-cascade diagram and params file).

    :func:`drakecreep.gap.drive_fit.diagnose_drive`: the uncertain ``DriveParams`` fields fitted by output error
    through the compiled diagram, candidate effects of the Drake model ranked and claimed on the held-out runs;
    with ``--out`` the augmented params file (``augmented_params.yaml``, for ``simulate/margins/report
    --params``), the report (``diagnosis.html``), ``diagnosis.json`` and ``summary.txt``, the manifest last; ``--score`` replays the augmented
    params, fixed, on the runs of another file. While it runs, ``--out`` keeps what is known: the fitted params
    file (``nominal_params.yaml``) as soon as the nominal fit ends, and ``ranking.json`` (the candidates so
    far, ``"stage"`` and ``"complete": false``) after each candidate and once the claims are decided, so that a
    failure or a stop late in the run (the refit with the claims takes a third of it) keeps them; at the end
    ``ranking.json`` is the final ranking (``"stage": "final"``, ``"complete": true``). The diagnosis's finished
    steps (the nominal fit and its null, each candidate, the result) are kept in ``--out``'s :data:`CHECKPOINT`
    until the manifest is written: the same command (same runs, options and code) run again after a stop or a
    failure resumes from them, with the result an uninterrupted run gives.
    """
    import json

    from drakecreep.files import OutputSet
    from drakecreep.gap.drake_replay import drake_replay_errors, replay_drakecreep
    from drakecreep.gap.drive_fit import check_run, diagnose_drive
    from drakecreep.report.drive_report import write_drive_report

    for r in train + test:  # named by the file, as every other check ('u (run r0): got ...' alone did not say which)
        _in_file(f"{args.data}: ", check_run, r)
    say = _say(args)
    kwargs = {}
    if args.uncertain:
        kwargs["uncertain"] = names(args.uncertain, "--uncertain")
    if getattr(args, "effects", None):
        kwargs["effects"] = names(args.effects, "--effects")
    outset = OutputSet(args.out, "manifest.json").start() if args.out else None
    steps = None if outset is None else outset.dir / CHECKPOINT
    extra = {"data": str(args.data), "train_runs": [r.label for r in train], "test_runs": [r.label for r in test]}

    def keep(stage, partial):  # written atomically as the run goes: a late failure keeps them
        if outset is None:
            return
        if stage == "nominal":
            path = outset.write("nominal_params.yaml", partial.save_params)
            say(f"the fitted params file is kept in {path}; ranking.json follows each candidate")
        body = {k: v for k, v in partial.to_json().items() if k not in ("unexplained", "hints")}  # known at the end
        body.update(stage=stage, complete=stage == "final", **extra)
        outset.write_text("ranking.json", json.dumps(body, indent=1) + "\n")

    try:
        result = diagnose_drive(train, test, progress=not args.quiet, workers=args.workers, on_stage=keep,
                                checkpoint=steps, **kwargs)
    except BaseException as err:  # a failure or a stop (Ctrl-C): say what is kept, then the one-line error as always
        if isinstance(err, InputError) and err.field in ("uncertain", "effects"):  # checked before any work
            raise err.renamed(f"--{err.field}") from None  # the option, not the parameter
        if outset is not None and outset.files:
            say(f"kept {' and '.join(sorted(outset.files))} in {outset.dir} (no manifest: the run did not finish)")
        if steps is not None and steps.exists():
            say(f"the finished steps are kept in {steps}: the same command resumes from them")
        raise
    payload = result.to_json()
    lines = list(result.summary())
    if score_runs:
        say(f"replaying the augmented params, fixed, on {args.score}")
        scored = {r.label: drake_replay_errors(replay_drakecreep(r, params=result.params)) for r in score_runs}
        payload["scored"] = {"data": str(args.score), "errors_percent": scored}
        lines.append(f"Scored on {args.score} (parameters fixed), errors in % of ||y||: " + "; ".join(
            f"{k}: position {e['position']:.3g}, force {e['force']:.3g}" for k, e in scored.items()))
    payload.update(**extra)
    if outset is not None:
        outset.write("augmented_params.yaml", result.save_params)
        outset.write_text("diagnosis.json", json.dumps(payload, indent=2) + "\n")
        outset.write_text("summary.txt", "\n".join(lines) + "\n")
        write_drive_report(result, outset, scored=payload.get("scored"), **extra)
        keep("final", result)
        outset.commit({"kind": "drakecreep.drive_diagnosis", "claimed": list(result.claimed),
                       "html": "diagnosis.html"})
        steps.unlink(missing_ok=True)  # the run is whole in its manifest
        say(f"wrote {outset.dir}/diagnosis.html, augmented_params.yaml, diagnosis.json, summary.txt, "
            "nominal_params.yaml and ranking.json")
    if args.json:
        print_json(payload)
    else:
        print("\n".join(lines))
    return 0
