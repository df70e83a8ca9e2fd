"""``drakecreep margins``: gain, phase and delay margins, crossover, bandwidth and Ms of both servo loops."""

import math

from drakecreep.cli._common import (POSITIVE_FEED, add_params_options, check_feed, feed_from_mm_s, number,
                                    params_from_args, print_json)
from drakecreep.errors import InputError
from drakecreep.files import to_jsonable

__all__ = ["add_parser", "run", "scenario_from_args"]

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
