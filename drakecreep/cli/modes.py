"""``drakecreep modes``: natural modes of the multibody model (the paper's Fig. 1 rig) vs the two-mass model.

Builds :func:`drakecreep.multibody.build_multibody` from the preset or ``--params``, finds its static
equilibrium under gravity and prints the first flexible modes: frequency (Hz), modal damping ratio,
dominant motion, and whether the two-mass model represents it (only its axial mode, whose two-mass
frequency is printed beside it). See ``docs/multibody.md``.
"""

from drakecreep.cli._common import add_params_options, number, params_from_args, print_json
from drakecreep.errors import InputError

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Register ``modes``."""
    p = subparsers.add_parser("modes", help="natural modes of the multibody model vs the two-mass model",
                              description=__doc__.split("\n\n")[0])
    add_params_options(p, friction=False)
    p.add_argument("--segments", type=int, default=12, metavar="N",
                   help="rigid segments of the screw (default 12: converged to 0.2 %%, see "
                        "analysis/multibody_convergence.py)")
    p.add_argument("--rigid-joints", action="store_true",
                   help="make the fixed joints of Tables 1-2 rigid (the two-mass model's assumption)")
    p.add_argument("--table-position", type=number, default=0.0, metavar="MM",
                   help="table position in mm (default 0: the nut at screw.nut_start_distance)")
    p.add_argument("--modes", type=int, default=10, metavar="K", help="flexible modes to list (default 10)")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.add_argument("--out", metavar="DIR",
                   help="also write modes.png (side and top views of the first four mode shapes) and "
                        "mechanism.png (the rig in 3-D) into DIR")
    p.set_defaults(func=run)
    return p


def run(args):
    """Build, analyse, print."""
    from drakecreep.multibody import build_multibody, modal_analysis, not_in_multibody, two_mass_axial_frequency

    if not 2 <= args.segments <= 400:
        raise InputError("--segments", args.segments, "an integer in [2, 400]")
    if not 1 <= args.modes <= 100:
        raise InputError("--modes", args.modes, "an integer in [1, 100]")
    params = params_from_args(args)
    start, length = params.screw.nut_start_distance * 1e3, params.screw.length * 1e3
    if not -start < args.table_position < length - start:
        raise InputError("--table-position", args.table_position,
                         f"in ({-start:g}, {length - start:g}) mm (the nut stays on the screw)")
    x = args.table_position * 1e-3
    if args.out:
        from drakecreep.files import check_output_dir

        check_output_dir(args.out)
    drive = build_multibody(params, n_segments=args.segments, rigid_joints=args.rigid_joints, table_position=x)
    context = drive.diagram.CreateDefaultContext()
    result = modal_analysis(drive, num_modes=args.modes, context=context)
    written = []
    if args.out:
        from pathlib import Path

        from drakecreep.report.multibody_plots import plot_mechanism, plot_mode_shapes

        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        written = [plot_mode_shapes(drive, result, out / "modes.png", num_modes=min(4, args.modes),
                                    context=drive.plant.GetMyContextFromRoot(context)),
                   plot_mechanism(drive, out / "mechanism.png")]
    two_mass = two_mass_axial_frequency(params, x)
    if args.json:
        out = result.to_dict()
        out["table_position_mm"] = args.table_position
        out["two_mass_axial_frequency_Hz"] = two_mass
        out["not_in_model"] = [{"field": f, "value": v, "what": w} for f, v, w in not_in_multibody(params)]
        if written:
            out["figures"] = [str(p) for p in written]
        print_json(out)
        return 0
    source = args.params or f"preset {args.preset}"
    joints = "rigid fixed joints" if args.rigid_joints else "fixed joints of Tables 1-2"
    print(f"multibody modes: {source}, {args.segments} screw segments, {joints}, table at {args.table_position:g} mm")
    print(f"rigid-body modes (< 1 Hz): {result.rigid_body_modes}  (the feed)")
    print(f"{'mode':>4}  {'f (Hz)':>9}  {'zeta':>7}  {'dominant motion':<16}  {'share':>5}  two-mass model")
    for i, m in enumerate(result.modes, 1):
        share = 100.0 * m.shares[m.label]
        flag = f"yes: {two_mass:.2f} Hz" if m.two_mass else "no"
        print(f"{i:>4}  {m.frequency:>9.2f}  {m.damping_ratio:>7.4f}  {m.label:<16}  {share:>4.0f}%  {flag}")
    for field, value, what in not_in_multibody(params):
        print(f"not in this model: {field}: {what}")
    if written:
        print("wrote " + ", ".join(str(p) for p in written))
    if any(m.damping_ratio > 1.0 for m in result.modes):
        print("zeta > 1: the modal (proportional) damping estimate does not hold there; Table 1's damping "
              "columns are suspect (see docs/multibody.md)")
    return 0
