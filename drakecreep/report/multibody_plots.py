"""Pictures of the multibody model: mode shapes (side and top views), the mechanism in 3-D, its Graphviz diagram.

* :func:`plot_mode_shapes` -- for each of the first modes, the rig's outline points (screw segment ends,
  table and nut seat corners, nut, bearing seats) undeformed (grey) and displaced along the mode (colour),
  side view (x-z) above top view (x-y). The displacement of a point is the translational velocity
  Jacobian of that point times the mode shape (Drake's ``CalcJacobianTranslationalVelocity``), scaled so
  that the largest displacement is a fixed share of the rig's length: a picture of the shape, not of
  an amplitude.
* :func:`plot_mechanism` -- the bodies as boxes and cylinders from the rig geometry (matplotlib 3-D).
* :func:`save_graphviz` -- ``diagram.GetGraphvizString()`` rendered by Graphviz ``dot`` to PNG when it
  is installed, else saved as ``.dot``.
"""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np

__all__ = ["plot_mode_shapes", "plot_mechanism", "save_graphviz", "outline_points"]


def _box_corners(center, size):
    c, (a, b, h) = np.asarray(center, float), size
    return [c + np.array([sx * a / 2, sy * b / 2, sz * h / 2]) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]


def outline_points(drive):
    """Points (world, undeformed) that draw the rig: ``{body name: [(label, point), ...]}`` and the lines.

    Returns
    -------
    points : dict
        Body name -> list of world points on it (m).
    """
    rig, params = drive.rig, drive.params
    plant = drive.plant
    points = {}
    seg = drive.segment_length
    for i in range(drive.n_segments):
        x0 = i * seg
        points[f"screw_{i}"] = [np.array([x0, 0.0, 0.0]), np.array([x0 + seg, 0.0, 0.0])]
    table_home = drive.home["table"]
    points["table"] = _box_corners(table_home, (rig.table_length, rig.table_width, rig.table_thickness))
    points["nut"] = [drive.home["nut"] + np.array([dx, 0.0, 0.0]) for dx in (-rig.nut_length / 2, rig.nut_length / 2)]
    if plant.HasBodyNamed("nut_seat"):
        s = rig.nut_seat_face
        points["nut_seat"] = _box_corners(drive.home["nut_seat"], (s, s, 2 * rig.table_bottom_height))
    for side in (0, 1):
        name = f"bearing_seat_{side}"
        if plant.HasBodyNamed(name):
            points[name] = _box_corners(drive.home[name], (rig.bearing_seat_face_x, rig.bearing_seat_face_y,
                                                           rig.bearing_seat_height))
    del params
    return points


def _displacements(drive, context, shape, points):
    from pydrake.multibody.tree import JacobianWrtVariable

    plant = drive.plant
    world = plant.world_frame()
    out = {}
    for name, pts in points.items():
        body = plant.GetBodyByName(name)
        X_WB = plant.EvalBodyPoseInWorld(context, body)
        rows = []
        for p in pts:
            p_B = X_WB.inverse().multiply(p)
            J = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV, body.body_frame(), p_B,
                                                        world, world)
            rows.append(J @ shape)
        out[name] = np.array(rows)
    return out


def _draw_body(ax, name, pts, axes, **style):
    """Outline of one body in the view plane ``axes`` (two world indices)."""
    pts = np.asarray(pts)[:, axes]
    if name.startswith("screw") or name == "nut":
        ax.plot(pts[:, 0], pts[:, 1], **style)
        return
    # box: convex hull of the projected corners (a rectangle in these views)
    from scipy.spatial import ConvexHull

    hull = ConvexHull(pts)
    loop = np.r_[hull.vertices, hull.vertices[:1]]
    ax.plot(pts[loop, 0], pts[loop, 1], **style)


def plot_mode_shapes(drive, result, path, num_modes=4, context=None, scale=0.08):
    """Side (x-z) and top (x-y) views of the first ``num_modes`` flexible modes of ``result``.

    Parameters
    ----------
    drive : MultibodyDrive
    result : drakecreep.multibody.modes.ModalResult
        From :func:`drakecreep.multibody.modal_analysis` on ``drive`` (its shapes are in ``drive``'s velocities).
    path : path-like
        PNG to write.
    num_modes : int
    context : Context, optional
        The plant context of the equilibrium (default: the undeformed rig; the shapes are small-motion
        fields either way).
    scale : float
        Largest drawn displacement as a share of the screw length.
    """
    import matplotlib.pyplot as plt

    plant = drive.plant
    pc = plant.CreateDefaultContext() if context is None else context
    points = outline_points(drive)
    modes = list(result.modes[:num_modes])
    fig, axes = plt.subplots(2, len(modes), figsize=(3.6 * len(modes), 4.3), squeeze=False)
    length = drive.params.screw.length
    for col, mode in enumerate(modes):
        disp = _displacements(drive, pc, mode.shape, points)
        biggest = max(float(np.max(np.linalg.norm(d, axis=1))) for d in disp.values())
        k = scale * length / biggest if biggest > 0 else 0.0
        for row, (view, label) in enumerate((((0, 2), "z (mm)"), ((0, 1), "y (mm)"))):
            ax = axes[row, col]
            for name, pts in points.items():
                p0 = np.asarray(pts) * 1e3
                p1 = (np.asarray(pts) + k * disp[name]) * 1e3
                colour = "tab:blue" if name.startswith("screw") else (
                    "tab:orange" if name in ("table", "nut_seat") else ("tab:red" if name == "nut" else "tab:green"))
                _draw_body(ax, name, p0, list(view), color="0.75", lw=1.0)
                _draw_body(ax, name, p1, list(view), color=colour, lw=1.6 if name.startswith("screw") else 1.2)
            ax.set_aspect("equal")
            ax.grid(True, lw=0.3, alpha=0.5)
            ax.set_xlabel("x (mm)")
            if col == 0:
                ax.set_ylabel(("side view\n" if row == 0 else "top view\n") + label)
            ax.tick_params(labelsize=7)
        share = 100.0 * mode.shares[mode.label]
        axes[0, col].set_title(f"mode {col + 1}: {mode.frequency:.1f} Hz\n{mode.label} ({share:.0f} %)"
                               + ("  [two-mass]" if mode.two_mass else ""), fontsize=9)
    joints = "rigid fixed joints" if drive.rigid_joints else "fixed joints of Tables 1-2"
    fig.suptitle(f"Multibody modes ({drive.n_segments} screw segments, {joints}); grey: undeformed, "
                 f"colour: mode shape (exaggerated)\nblue screw, orange table + nut seat, red nut, green bearing seats",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return Path(path)


def _cylinder_x(ax, x0, x1, radius, colour, n=24):
    t = np.linspace(0, 2 * math.pi, n)
    xs = np.array([x0, x1])
    T, X = np.meshgrid(t, xs)
    ax.plot_surface(X * 1e3, radius * np.cos(T) * 1e3, radius * np.sin(T) * 1e3, color=colour, alpha=0.9,
                    linewidth=0, shade=True)


def _box(ax, center, size, colour, alpha=0.35):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    c = np.asarray(center, float) * 1e3
    a, b, h = (s * 1e3 / 2 for s in size)
    v = np.array([[c[0] + sx * a, c[1] + sy * b, c[2] + sz * h] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    ax.add_collection3d(Poly3DCollection([v[f] for f in faces], facecolor=colour, edgecolor="0.3", linewidths=0.4,
                                         alpha=alpha))


def plot_mechanism(drive, path):
    """A static 3-D picture of the rig's bodies from the geometry of ``drive`` (mm)."""
    import matplotlib.pyplot as plt

    rig, params = drive.rig, drive.params
    L = params.screw.length
    fig = plt.figure(figsize=(9, 5.5))
    ax = fig.add_subplot(projection="3d")
    _cylinder_x(ax, 0.0, L, params.screw.nominal_diameter / 2, "tab:blue")
    nut_x = drive.home["nut"][0]
    _cylinder_x(ax, nut_x - rig.nut_length / 2, nut_x + rig.nut_length / 2, rig.nut_outer_diameter / 2, "tab:red")
    _cylinder_x(ax, -0.09, -0.01, 0.04, "0.35")  # motor (drawing only)
    table = drive.home["table"]
    _box(ax, table, (rig.table_length, rig.table_width, rig.table_thickness), "tab:orange")
    s = rig.nut_seat_face
    _box(ax, [nut_x, 0.0, 0.0], (s, s, 2 * rig.table_bottom_height), "tab:orange", alpha=0.5)
    for x_b in (0.0, L):
        _box(ax, [x_b, 0.0, -rig.bearing_seat_height / 2],
             (rig.bearing_seat_face_x, rig.bearing_seat_face_y, rig.bearing_seat_height), "tab:green", alpha=0.6)
    for y in (-rig.guide_spacing_y / 2, rig.guide_spacing_y / 2):
        _box(ax, [L / 2, y, rig.slider_height - 0.01], (L + 0.1, 0.023, 0.02), "0.6", alpha=0.5)  # guide rails
        for dx in (-rig.slider_spacing_x / 2, rig.slider_spacing_x / 2):
            _box(ax, [table[0] + dx, y, rig.slider_height + 0.005], (0.06, 0.048, 0.03), "tab:purple", alpha=0.7)
    _box(ax, [L / 2, 0.0, -rig.bearing_seat_height - 0.01], (L + 0.2, 0.32, 0.02), "0.85", alpha=0.3)  # base
    ax.set_xlabel("x (mm), feed")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_xlim(-100, L * 1e3 + 50)
    ax.set_ylim(-250, 250)
    ax.set_zlim(-120, 150)
    ax.set_box_aspect((L * 1e3 + 150, 500, 270))
    ax.view_init(elev=22, azim=-60)
    ax.set_title("The multibody rig (paper Fig. 1): screw (blue) on bearing seats (green), nut (red) in its seat, "
                 "\nworkbench (orange) on four sliders (purple) on two guides (grey); motor at x < 0 (drawing only)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return Path(path)


def save_graphviz(diagram, path, max_depth=1):
    """Write ``diagram``'s Graphviz graph: ``path`` (PNG) rendered by ``dot`` if installed, else ``path`` with ``.dot``.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    path = Path(path)
    text = diagram.GetGraphvizString(max_depth=max_depth)
    dot = shutil.which("dot")
    if dot is None:
        out = path.with_suffix(".dot")
        out.write_text(text)
        return out
    subprocess.run([dot, "-Tpng", "-Gdpi=90", "-o", str(path)], input=text.encode(), check=True)
    return path
