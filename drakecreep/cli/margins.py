"""``drakecreep margins``: gain, phase and delay margins, crossover, bandwidth and Ms of both servo loops."""

import dataclasses
import math

import numpy as np

from drakecreep.cli._common import add_params_options, feed_from_mm_s, number, params_from_args, print_json
from drakecreep.errors import InputError
from drakecreep.files import to_jsonable

__all__ = ["add_parser", "run", "scenario_from_args", "check_feed"]

_ROWS = (
    ("gain_margin_dB", "gain margin", "dB", "{:.1f}"),
    ("phase_margin_deg", "phase margin", "deg", "{:.1f}"),
    ("delay_margin_ms", "delay margin", "ms", "{:.3g}"),
    ("crossover_Hz", "gain crossover", "Hz", "{:.3g}"),
    ("bandwidth_Hz", "closed-loop bandwidth", "Hz", "{:.3g}"),
    ("ms_peak", "sensitivity peak Ms", "", "{:.3f}"),
)


def add_parser(subparsers):
    """Register ``margins``."""
    p = subparsers.add_parser(
        "margins", help="servo-loop margins at a sliding operating point (velocity and position loop)",
        description="Linearize the feed-drive diagram at steady sliding (AutoDiff) and print gain, phase and "
                    "delay margins, crossover, closed-loop bandwidth and sensitivity peak of the velocity loop "
                    "(broken at the speed feedback) and the position loop (broken at the position feedback), "
                    "for the controller as configured (sampled: ZOH, sample delays and controller.computation_delay included) and continuous.",
    )
    add_params_options(p)
    p.add_argument("--feed", type=number, default=1.0, metavar="MM_PER_S", help="operating feed in mm/s (default 1)")
    p.add_argument("--load-case", type=int, default=3, metavar="N", help="load case (paper: 1-3; 0 = unloaded; default 3)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)
    return p


def scenario_from_args(args, params):
    """The operating point's :class:`~drakecreep.scenario.Scenario` from ``--feed`` and ``--load-case``."""
    from drakecreep.scenario import Scenario

    if params.friction.law == "gms" and getattr(args, "friction", None):  # the operating point said 'friction.law'
        raise InputError("--friction", args.friction, "coulomb, stribeck or lugre (the linear analysis needs a smooth "
                         "law)")
    if not args.feed > 0:  # an operating point slides one way: its speed
        raise InputError("--feed", args.feed, POSITIVE_FEED)
    feed = feed_from_mm_s(args.feed)
    if not 0 <= args.load_case <= len(params.loads.cases):
        raise InputError("--load-case", args.load_case, f"an integer in 0..{len(params.loads.cases)} (0 = unloaded)")
    scenario = Scenario(feed=feed, load_case=args.load_case)
    check_feed(params, scenario, "--feed", args.feed)
    return scenario


#: what a feed option of the linear analyses takes (margins, tune, report, critical): one way, in the range of every
#: command's feeds (critical said 'a finite speed > 0 in mm/s', the others 'a feed > 0 mm/s')
POSITIVE_FEED = "a feed in [1e-4, 1000] mm/s (> 0: the analysis takes a feed in +x)"


def check_feed(params, scenario, option, mm_s):
    """Raise :class:`InputError` naming ``option`` (a feed of ``mm_s`` mm/s) when the drive cannot slide steadily at
    ``scenario``'s feed: the force it takes is beyond the drive's limit (the operating point said 'feed: got 0.001',
    the scenario's field in m/s, and blamed the feed for what is mostly the params' load and friction)."""
    from drakecreep.model.steady import nut_on_table, sliding_overload, steady_sliding

    overload = sliding_overload(params, scenario)
    if overload is not None:
        force, limit = overload
        feeds = np.geomspace(1e-7, 1.0, 43)  # the commands' feeds, 1e-4 to 1000 mm/s
        needs = [sliding_overload(params, dataclasses.replace(scenario, feed=float(v))) for v in feeds]
        if all(n is not None for n in needs):
            # no feed slides: the load and the friction are the drive's, not the feed's ('--feed: got 1.0', an option
            # not given, 'allowed: a feed the drive can slide at', where none can)
            raise InputError("--load-case", scenario.load_case, f"a load case the drive can hold at some feed: this one "
                             f"takes at least {min(n[0] for n in needs):.4g} N at 1e-4 to 1000 mm/s, beyond the "
                             f"drive's limit {limit:.4g} N (motor.peak_torque through screw.lead against the params "
                             "file's load and friction)")
        _, friction, spring, _, _ = steady_sliding(nut_on_table(params), scenario)
        raise InputError(option, mm_s, f"a feed in mm/s the drive can slide at: at load case {scenario.load_case} it "
                         f"takes {force:.4g} N (load {spring - friction:.4g} N, friction {friction:.4g} N, motor drag "
                         f"{force - spring:.4g} N), beyond the drive's limit {limit:.4g} N (motor.peak_torque through "
                         "screw.lead)")


def print_margins(summary):
    """Text table of both loops (the configured controller, and continuous when sampled)."""
    variants = [summary["controller"]] + (["continuous"] if "continuous" in summary else [])
    cols = [(loop, v) for loop in ("velocity", "position") for v in variants]
    print(f"{'':28s}" + "".join(f"{loop + ' ' + v:>22s}" for loop, v in cols))
    for key, label, unit, fmt in _ROWS:
        cells = []
        for loop, v in cols:
            m = summary[loop] if v == summary["controller"] else summary[v][loop]
            x = m[key]
            cells.append(("inf" if x > 0 else "-") if isinstance(x, float) and not math.isfinite(x) else fmt.format(x))
        print(f"{label + (' (' + unit + ')' if unit else ''):28s}" + "".join(f"{c:>22s}" for c in cells))
    for loop, v in cols:
        m = summary[loop] if v == summary["controller"] else summary[v][loop]
        if not m["closed_loop_stable"]:
            print(f"WARNING: {loop} loop ({v}) is unstable when closed: margins do not apply")


def run(args):
    """Compute and print the margins."""
    from drakecreep.servo.loops import analyze_loops, resonance_text

    params = params_from_args(args)
    scenario = scenario_from_args(args, params)
    summary = analyze_loops(params, scenario).summary()
    if args.json:
        print_json(to_jsonable(summary))
        return 0
    op = summary["operating_point"]
    print(f"operating point: feed {op['feed_mm_s']:g} mm/s, load case {scenario.load_case}, "
          f"K = {op['stiffness_N_per_um']:.4g} N/um, C1 = {op['friction_slope_C1_Ns_per_m']:.4g} N s/m, "
          f"zeta = {op['zeta']:.4g} (friction of the {op['friction_on_table']})")
    print_margins(summary)
    if "computation_delay_samples" in summary:
        print(f"computation delay: {summary['computation_delay_samples']:g} velocity samples "
              f"({summary['computation_delay_ms']:.3g} ms; controller.computation_delay), in the sampled loops")
    unstable = "n/a (unstable when closed: no margins)"
    if "sampling_phase_cost_deg" in summary:
        c = summary["sampling_phase_cost_deg"]
        print("phase lost to sampling, hold and computation delay: " + ", ".join(
            f"{loop} " + (unstable if c[loop] is None else f"{c[loop]:.1f} deg") for loop in ("velocity", "position")))
    if "computation_delay_cost" in summary:
        c = summary["computation_delay_cost"]
        print("of which the computation delay: " + ", ".join(
            f"{loop} " + (unstable if c[loop] is None else f"{c[loop]['phase_margin_deg']:.2f} deg PM, "
                          f"{c[loop]['gain_margin_dB']:.2f} dB GM, {c[loop]['delay_margin_ms']:.3g} ms delay margin")
            for loop in ("velocity", "position")))
    print(f"first mechanical resonance: {resonance_text(summary['resonance_Hz'], summary['resonance_damping'], '.4g')}")
    return 0
