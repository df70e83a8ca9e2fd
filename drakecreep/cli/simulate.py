"""``drakecreep simulate``: one feed at a speed and load; prints the creep metrics, saves CSV/JSON/PNG."""

import sys

from drakecreep.cli._common import (add_params_options, check_duration, check_feed, feed_from_mm_s, number,
                                    params_from_args, positive_float, print_json)
from drakecreep.errors import InputError

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    p = subparsers.add_parser(
        "simulate",
        help="simulate a feed and measure creep (speed fluctuation, stick-slip)",
        description=(
            "Simulate the feed drive at a constant feed under one load case and print the paper's creep "
            "metrics (max speed fluctuation and fluctuation rate over the steady window), stick fraction, "
            "stick-slip cycles and following error. Writes timeseries.csv, metrics.json, params.yaml and "
            "speed.png to --out."
        ),
    )
    add_params_options(p)
    p.add_argument("--load-case", type=int, default=3, metavar="N",
                   help="load case of the parameters (paper: 1, 2, 3; 0 = unloaded; default 3)")
    p.add_argument("--feed", type=number, default=1.0, metavar="MM_PER_S", help="feed speed in mm/s (default 1)")
    p.add_argument("--duration", type=positive_float, default=5.0, metavar="S", help="simulated time in s (default 5)")
    p.add_argument("--controller", choices=("sampled", "continuous"), help="controller variant (default: parameters)")
    p.add_argument("--backend", choices=("compiled", "leaf"), help="compiled symbolic fast path or Python leaf systems")
    p.add_argument("--model", choices=("two_mass", "multibody"), default="two_mass",
                   help="mechanics: the two-mass model (default) or the paper's rig in a Drake MultibodyPlant "
                        "(same controller, sensors, friction and load case; docs/multibody.md)")
    p.add_argument("--segments", type=int, metavar="N",
                   help="--model multibody: screw segments (default 6; with --rigid-joints --axial-screw, "
                        "2 gives the creep verdicts and amplitudes of 6 within 0.4 %% at a fifth of the time; "
                        "use >= 12 for the 1.5 kHz torsion mode, docs/multibody.md)")
    p.add_argument("--rigid-joints", action="store_true",
                   help="--model multibody: make the fixed joints of Tables 1-2 rigid")
    p.add_argument("--axial-screw", action="store_true",
                   help="--model multibody with --rigid-joints: screw segments only slide and turn about the axis "
                        "(no bending; the cheap configuration for creep runs, docs/multibody.md)")
    p.add_argument("--out", default="out/simulate", metavar="DIR", help="output folder (default out/simulate)")
    p.add_argument("--max-wall", type=positive_float, metavar="S",
                   help="stop after S seconds of computing, the convergence check's reruns included (what was "
                        "computed is saved)")
    p.add_argument("--no-plot", action="store_true", help="skip the PNG")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the text summary")
    p.add_argument("--uncertainty", type=int, metavar="N",
                   help="also run N plausible rigs (the preset's assumed values sampled over their ranges, "
                        "drakecreep uncertainty) at this feed and load, and say in what share of them it creeps")
    p.add_argument("--seed", type=int, metavar="S", help="seed of the --uncertainty rig sample (default 0)")
    p.add_argument("--spec", metavar="FILE",
                   help="uncertainty spec for --uncertainty (default: the preset's; needed with --params)")
    p.set_defaults(func=run)
    return p


def run(args):
    from drakecreep.files import check_output_dir
    from drakecreep.params import with_value
    from drakecreep.scenario import Scenario
    from drakecreep.sim.simulation import check_window, shortest_run, simulate

    params = params_from_args(args)
    if args.controller:
        params = with_value(params, "controller.sampled", args.controller == "sampled")
    feed = feed_from_mm_s(args.feed)
    if not 0 <= args.load_case <= len(params.loads.cases):
        raise InputError("--load-case", args.load_case, params.load_cases_allowed)
    check_window(params, check_duration(args.duration), "--duration")
    scenario = Scenario(feed=feed, load_case=args.load_case, duration=args.duration)
    multibody = None
    if args.model == "multibody":
        from drakecreep.multibody.diagram import DEFAULT_SEGMENTS, MultibodyOptions

        if args.segments is not None and not 2 <= args.segments <= 400:
            raise InputError("--segments", args.segments, "an integer in [2, 400]")
        if args.uncertainty is not None:
            raise InputError("--uncertainty", args.uncertainty, "not given with --model multibody")
        segments = DEFAULT_SEGMENTS if args.segments is None else args.segments
        if args.axial_screw and not args.rigid_joints:
            raise InputError("--axial-screw", True, "only with --rigid-joints (the screw's bending carries the joints)")
        multibody = MultibodyOptions(n_segments=segments, rigid_joints=args.rigid_joints,
                                     screw_bending=not args.axial_screw)
        travel, segment = abs(feed) * args.duration, params.screw.length / segments
        shortest = shortest_run(params)
        if segment / abs(feed) < shortest * (1.0 - 1e-9):
            # no duration both holds the metrics window and keeps the nut on its segment: the feed is too fast ('<=
            # 0.3 s' and '>= 1.005 s' sent the user back and forth)
            raise InputError("--feed", args.feed, f"<= {segment / shortest * 1e3:.4g} mm/s with "
                             f"{segments} segments (the multibody nut stays on one screw segment of "
                             f"{segment * 1e3:g} mm for the shortest run, {shortest:g} s"
                             + ("; fewer --segments make it longer)" if segments > 2 else ")"))
        if travel > segment * (1.0 + 1e-9):
            raise InputError("--duration", args.duration,
                             f"<= {segment / abs(feed):g} s at {args.feed:g} mm/s (the multibody nut stays on one "
                             f"screw segment of {segment * 1e3:g} mm)")
    else:
        given = ([("--segments", args.segments)] if args.segments is not None else []) + [
            (option, True) for option, on in (("--rigid-joints", args.rigid_joints), ("--axial-screw", args.axial_screw))
            if on]
        if given:  # the option given, not all three ('--segments/--rigid-joints/--axial-screw: got True')
            raise InputError(given[0][0], given[0][1], "only with --model multibody")
    spec = None
    if args.uncertainty is not None:
        from drakecreep.cli.uncertainty import check_study, spec_from_args

        args.seed = 0 if args.seed is None else args.seed
        if args.uncertainty < 1:
            raise InputError("--uncertainty", args.uncertainty, "a number of rigs >= 1")
        try:  # before the run, not after it
            check_study(params, args.uncertainty, [feed], [args.load_case], seed=args.seed, duration=args.duration)
        except InputError as err:
            raise err.renamed("--uncertainty" if err.field == "--samples" else err.field) from None
        spec = spec_from_args(args)
    elif args.spec is not None or args.seed is not None:
        raise InputError("--spec" if args.spec is not None else "--seed", args.spec or args.seed,
                         "only with --uncertainty N (the rig sample it describes)")
    # a drive that cannot hold the feed stalls: no stick-slip to give a verdict on (a 1 mN m drive ran 79 s before
    # 'no verdict'; a load of 1e6 N ended 'diverged'), so it is refused before the run, as margins refuses it
    check_feed(params, scenario, "--feed", args.feed)
    check_output_dir(args.out)  # before the run, not after it
    notice = None if args.quiet else (lambda line: print(f"drakecreep simulate: note: {line}", file=sys.stderr,
                                                        flush=True))
    result = simulate(params, scenario, backend=args.backend, wall_limit=args.max_wall, model=args.model,
                      multibody=multibody, notice=notice)
    extra = {}
    if not args.no_plot and len(result.time) > 1:
        from drakecreep.report.plots import plot_feed

        extra["speed.png"] = lambda path: plot_feed(result, path)
    paths = result.save(args.out, extra=extra)  # one set, metrics.json last (also after a stop or Ctrl-C)
    if "speed" in paths:
        paths["plot"] = paths.pop("speed")
    summary = result.summary()
    summary["out"] = str(paths["metrics"].parent)
    study = None
    if spec is not None:
        from drakecreep.cli.uncertainty import run_study, share_line

        study = run_study(params, spec, args.uncertainty, [feed], [args.load_case], seed=args.seed,
                          duration=args.duration, out=str(paths["metrics"].parent / "uncertainty"),
                          progress=not args.json)
        row = study.summary.iloc[0]
        summary["uncertainty"] = dict(
            rigs=int(row["rigs"]), seed=args.seed, creep_percent=float(row["creep_percent"]),
            creep_low_percent=float(row["creep_low_percent"]), creep_high_percent=float(row["creep_high_percent"]),
            fluctuation_p50_mm_s=float(row["fluctuation_p50_mm_s"]), fluctuation_p95_mm_s=float(row["fluctuation_p95_mm_s"]),
            deciding=[str(x) for x in study.sensitivity.dropna(subset=["rho_creep"])["parameter"].head(3)],
        )
    if args.json:
        print_json(summary)
    else:
        _print_text(summary, result, paths)
        if study is not None:
            row = study.summary.iloc[0]
            print(f"plausible rigs ({spec.source}, seed {args.seed}): {share_line(row)}; "
                  f"fluctuation p50/p95 {row['fluctuation_p50_mm_s']:.3g}/{row['fluctuation_p95_mm_s']:.3g} mm/s")
    if not result.ok:
        print(f"drakecreep simulate: error: {result.status} (results up to then saved in {args.out})", file=sys.stderr)
        if result.status.startswith("interrupted"):
            return 143 if "SIGTERM" in result.status else 130
        return 1
    return 0


def _print_text(s, result, paths):
    model = ""
    if s.get("model") == "multibody":
        joints = "rigid fixed joints" if s["rigid_joints"] else "fixed joints of Tables 1-2"
        model = f", multibody model ({s['n_segments']} screw segments, {joints})"
    print(f"feed {s['feed_mm_s']:g} mm/s, load case {s['load_case']}, {s['friction_law']} friction, "
          f"{s['controller']} cascade{model}: {s['sim_time_s']:g} s simulated in {s['wall_time_s']:.2f} s")
    if result.metrics is not None:
        rows = [
            ("metrics window", f"{s['window_start_s']:g}-{s['window_end_s']:g} s"),
            ("mean table speed", f"{s['mean_speed_mm_s']:.5f} mm/s"),
            ("max speed fluctuation", f"{s['max_fluctuation_mm_s']:.5f} mm/s"),
            ("fluctuation rate", f"{s['fluctuation_rate_percent']:.3f} %"),
            ("table speed min / max", f"{s['min_speed_mm_s']:.5f} / {s['max_speed_mm_s']:.5f} mm/s"),
            ("stick fraction", f"{s['stick_fraction'] * 100:.2f} %"),
            ("stick-slip cycles", f"{s['stick_slip_cycles']} ({s['stick_slip_frequency_Hz']:.1f} Hz)"),
            ("creep (stick-slip)", "yes" if s["creep"] else "no"),
            ("converged", _converged_text(s)),
            ("travel error max / rms", f"{s['following_error_max_um']:.3f} / {s['following_error_rms_um']:.3f} um"),
        ]
        width = max(len(r[0]) for r in rows)
        for name, value in rows:
            print(f"  {name:<{width}}  {value}")
    print("wrote " + ", ".join(str(p) for p in paths.values()))


def _converged_text(summary):
    """The convergence check's verdict in words (drakecreep.sim.simulation)."""
    c = summary.get("converged")
    if c is None:
        return "not checked"
    acc = summary.get("accuracy")
    where = f" at accuracy {acc:g}" if acc else ""
    if c:
        return f"yes{where}, checked at 10x tighter"
    same, change = summary.get("convergence_verdict_agrees"), summary.get("convergence_fluctuation_change_mm_s")
    if same and change is not None:  # the verdict holds; the amplitude moved beyond the tolerance
        verdict = "creeps" if summary.get("creep") else "no creep"
        return (f"NO{where}: a 10x tighter run gives the same verdict ({verdict}) but a fluctuation "
                f"{change:.2g} mm/s apart (tolerance {summary.get('convergence_tolerance_mm_s', float('nan')):.2g} "
                f"mm/s); read the amplitudes as indicative")
    if same is False:
        return f"NO{where}: a 10x tighter run gives the other verdict; the creep verdict is not converged"
    return f"NO{where}: the 10x tighter run failed; read the figures as indicative"
