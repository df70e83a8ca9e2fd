"""Pictures of the multibody model."""

import numpy as np
import pytest

from drakecreep.multibody import build_multibody, modal_analysis
from drakecreep.report.multibody_plots import (
    _displacements,
    outline_points,
    plot_mechanism,
    plot_mode_shapes,
    save_graphviz,
)


@pytest.fixture(scope="module")
def analysed(paper):
    drive = build_multibody(paper, n_segments=4)
    context = drive.diagram.CreateDefaultContext()
    result = modal_analysis(drive, num_modes=4, context=context)
    return drive, result, drive.plant.GetMyContextFromRoot(context)


def test_axial_mode_moves_the_table_along_x_and_yaw_mode_turns_it(analysed):
    """The drawn displacements are the mode's: axial -> table corners move along x alike; yaw -> opposite in y."""
    drive, result, pc = analysed
    points = outline_points(drive)
    axial = _displacements(drive, pc, result.axial_mode().shape, {"table": points["table"]})["table"]
    assert np.all(np.abs(axial[:, 0]) > 5 * np.abs(axial[:, 1:]).max())
    assert np.ptp(axial[:, 0]) < 0.2 * np.abs(axial[:, 0]).max()
    yaw = next(m for m in result.modes if m.label == "table yaw")
    d = _displacements(drive, pc, yaw.shape, {"table": points["table"]})["table"]
    front = [i for i, p in enumerate(points["table"]) if p[0] > drive.home["table"][0]]
    back = [i for i, p in enumerate(points["table"]) if p[0] < drive.home["table"][0]]
    assert np.sign(d[front, 1].mean()) == -np.sign(d[back, 1].mean())


def test_figures_are_written(analysed, tmp_path):
    drive, result, pc = analysed
    for path in (plot_mode_shapes(drive, result, tmp_path / "modes.png", num_modes=3, context=pc),
                 plot_mechanism(drive, tmp_path / "mechanism.png")):
        assert path.exists() and path.stat().st_size > 10_000
    out = save_graphviz(drive.diagram, tmp_path / "diagram.png")
    assert out.exists() and out.suffix in (".png", ".dot")
