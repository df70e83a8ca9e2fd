"""The multibody model's README figures: mode shapes, the mechanism in 3-D and the closed-loop Graphviz diagram.

Writes ``multibody_modes.png`` (paper preset, N = 12, fixed joints of Tables 1-2, first four modes),
``multibody_mechanism.png`` and ``multibody_diagram.png`` (``dot`` rendering of the diagram that
``simulate(model="multibody")`` runs; ``.dot`` when Graphviz is not installed) into ``--out``
(default ``docs/img``).

    python analysis/multibody_figures.py [--out docs/img]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from drakecreep.multibody import build_multibody, modal_analysis
from drakecreep.multibody.diagram import MultibodyOptions, build_multibody_diagram
from drakecreep.params import preset
from drakecreep.report.multibody_plots import plot_mechanism, plot_mode_shapes, save_graphviz
from drakecreep.scenario import Scenario

__all__ = ["main"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="docs/img")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    params = preset("paper")
    drive = build_multibody(params, n_segments=12)
    context = drive.diagram.CreateDefaultContext()
    result = modal_analysis(drive, num_modes=10, context=context)
    written = [plot_mode_shapes(drive, result, out / "multibody_modes.png", num_modes=4,
                                context=drive.plant.GetMyContextFromRoot(context)),
               plot_mechanism(drive, out / "multibody_mechanism.png")]
    closed = build_multibody_diagram(params, Scenario(feed=1e-3, load_case=3, duration=1.0), MultibodyOptions())
    written.append(save_graphviz(closed.diagram, out / "multibody_diagram.png"))
    print("wrote " + ", ".join(str(p) for p in written))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
