"""``drakecreep diagram``: draw the feed-drive diagram (Graphviz, from Drake)."""

__all__ = ["add_parser", "run", "controller_caption"]


def add_parser(subparsers):
    from drakecreep.cli._common import add_params_options

    p = subparsers.add_parser(
        "diagram",
        help="draw the Drake system diagram to SVG/PNG/PDF/DOT",
        description="Build the feed-drive diagram from the parameters and draw it with Graphviz "
        "(SVG, PNG and PDF need Graphviz's 'dot'; the .dot source is always written).",
    )
    add_params_options(p)
    p.add_argument("--out", default="out/feed_drive.svg", metavar="FILE",
                   help="output file: .svg, .png, .pdf or .dot (default out/feed_drive.svg)")
    p.add_argument("--controller", choices=("sampled", "continuous"), help="controller variant to draw")
    p.set_defaults(func=run)
    return p


def run(args):
    from drakecreep.cli._common import params_from_args
    from drakecreep.model.diagram import build_diagram
    from drakecreep.report.drawing import draw_diagram
    from drakecreep.scenario import Scenario

    from drakecreep.files import check_output_file

    check_output_file(args.out)  # before the diagram is built: the folder, writable
    params = params_from_args(args)
    continuous = None if args.controller is None else args.controller == "continuous"
    # the default scenario's load case, or the last one a params file has (one without load cases said
    # 'load_case: got 3', an option diagram does not have): the blocks drawn are the same for every load case
    scenario = Scenario(load_case=min(Scenario().load_case, len(params.loads.cases)))
    drive = build_diagram(params, scenario, continuous=continuous)
    source = args.params or f"preset {args.preset}"
    path = draw_diagram(drive.diagram, args.out, title=f"{source}: {controller_caption(params, continuous)}")
    dot = path.with_suffix(".dot")
    print(f"wrote {path}" + (f", {dot}" if dot != path else ""))  # the Graphviz source is written beside it too
    return 0


def controller_caption(params, continuous=None):
    """The controller variant drawn, in words: one :class:`~drakecreep.model.controller.CascadeController` block
    either way, so the drawing's caption says which (``--controller continuous`` drew the same picture as
    ``sampled``)."""
    g = params.controller
    if continuous if continuous is not None else not g.sampled:
        return "continuous PI cascade controller"
    return (f"sampled PI cascade controller: velocity loop every {g.velocity_period * 1e3:g} ms, position loop every "
            f"{g.position_period * 1e3:g} ms, computation delay {g.computation_delay:g} velocity samples")
