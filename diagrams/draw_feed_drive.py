"""Draw the feed-drive diagrams (Graphviz, from Drake) into this folder.

Writes, for the paper preset: ``feed_drive.svg/png`` (sampled cascade), ``feed_drive_continuous.svg``
(the variant that is linearized), ``plant.svg`` (motor + screw + table) and ``feed_drive_compiled.svg``
(the symbolic fast path). Needs Graphviz's ``dot`` for SVG/PNG; the ``.dot`` sources are always written.

Run: ``python diagrams/draw_feed_drive.py [--params FILE] [--out DIR]``
"""

import argparse
from pathlib import Path

from drakecreep.sim.compiled import compile_diagram
from drakecreep.model.diagram import build_diagram, build_plant
from drakecreep.report.drawing import draw_diagram
from drakecreep.params import load_params, preset
from drakecreep.scenario import Scenario


def main(argv=None):
    parser = argparse.ArgumentParser(description="Draw the feed-drive diagrams.")
    parser.add_argument("--params", help="parameter file (default: paper preset)")
    parser.add_argument("--out", default=str(Path(__file__).parent), help="output folder (default: diagrams/)")
    args = parser.parse_args(argv)
    params = load_params(args.params) if args.params else preset("paper")
    out = Path(args.out)
    scenario = Scenario()
    drive = build_diagram(params, scenario)
    written = [
        draw_diagram(drive.diagram, out / "feed_drive.svg"),
        draw_diagram(drive.diagram, out / "feed_drive.png"),
        draw_diagram(build_diagram(params, scenario, continuous=True).diagram, out / "feed_drive_continuous.svg"),
        draw_diagram(build_plant(params, scenario.load_case), out / "plant.svg"),
        draw_diagram(compile_diagram(drive).diagram, out / "feed_drive_compiled.svg"),
    ]
    for path in written:
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
