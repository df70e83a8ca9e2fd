"""The rig's geometry and the joint data of the multibody model: what the paper gives and what is assumed.

The seed paper (Figs. 1, 10) shows the machine but prints no dimensions, masses or inertias of its
bodies; it gives the joints' stiffness and damping (Tables 1-2: fixed joints, Tables 4-6: moving
joints). :class:`RigGeometry` holds every geometric value the multibody model needs, each an
assumption with its source and plausible range in the field's metadata (``doc``), validated like
:mod:`drakecreep.params`. :func:`paper_joints` reads Tables 1, 2 and 4-6 from the package's CSVs (SI).

Axes: x along the screw (the feed), y lateral, z vertical (up); the screw axis is the line y = z = 0
and the thrust bearing is at x = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import lru_cache

import pandas as pd

from drakecreep.data import paper_data_dir
from drakecreep.errors import InputError

__all__ = ["RigGeometry", "JointData", "paper_joints", "series", "series_damping", "face_joint"]


def _g(default, lo, hi, doc, unit="m"):
    return field(default=default, metadata=dict(unit=unit, lo=lo, hi=hi, doc=doc))


@dataclass(frozen=True)
class RigGeometry:
    """Dimensions and masses of the rig's bodies that the paper does not print (all assumptions, SI).

    Every field's ``metadata["doc"]`` names the source of the value and its plausible range is the
    allowed range ``[lo, hi]``. The masses of the table group add up to ``params.table.mass``
    (table, nut seat and sliders, the two-mass model's value), so both models carry the same mass.
    """

    table_length: float = _g(0.40, 0.1, 2.0, "workbench plate along x; [assumed] a 40 kg steel plate "
                             "0.40 x 0.30 x 0.042 m, the size of a 25 mm-screw laboratory axis (0.2-1 m)")
    table_width: float = _g(0.30, 0.1, 2.0, "workbench plate along y; [assumed] as table_length (0.2-1 m)")
    table_thickness: float = _g(0.042, 0.01, 0.3, "workbench plate along z; [assumed] 40 kg / (7850 kg/m^3 "
                                "x 0.40 x 0.30) = 0.042 m (0.02-0.1 m)")
    table_bottom_height: float = _g(0.05, 0.02, 0.3, "underside of the plate above the screw axis = nut seat "
                                    "height; [assumed] screw-support catalogs: axis 40-60 mm below the bed")
    slider_spacing_x: float = _g(0.20, 0.02, 2.0, "distance between the two sliders on one guide; [assumed] "
                                 "half the plate length (0.1-0.4 m)")
    guide_spacing_y: float = _g(0.20, 0.02, 2.0, "distance between the two guides; [assumed] two thirds of the "
                                "plate width (0.1-0.3 m)")
    slider_height: float = _g(0.03, 0.0, 0.3, "height of the guide-slider contact above the screw axis; "
                              "[assumed] 25-size guide blocks (HIWIN HGH25: H = 40 mm) under the plate (0.01-0.05 m)")
    nut_seat_mass: float = _g(1.5, 0.01, 100.0, "nut seat, kg; [assumed] steel block ~80 x 60 x 50 mm with a "
                              "40 mm bore (1-3 kg); taken out of params.table.mass", "kg")
    nut_seat_face: float = _g(0.07, 0.01, 0.5, "side of the square bolted face nut seat-workbench; [assumed] "
                              "(0.05-0.1 m)")
    nut_outer_diameter: float = _g(0.040, 0.026, 0.2, "nut body diameter (rotary inertia); [assumed] 25x5 nut, "
                                   "DIN 69051 form B: D1 = 40 mm")
    nut_length: float = _g(0.040, 0.01, 0.3, "nut length (tilt stiffness k_r L^2/12 of the screw-nut pair); "
                           "[assumed] 25x5 nut with 47 balls [paper T3] over ~3 turns (0.03-0.06 m)")
    nut_flange_face: float = _g(0.05, 0.01, 0.3, "side of the square bolted face nut-nut seat (flange); "
                                "[assumed] DIN 69051 flange 62 mm, square equivalent 50 mm")
    bearing_seat_mass: float = _g(2.0, 0.01, 100.0, "each bearing seat, kg; [assumed] screw support unit of "
                                  "a 25 mm screw (THK BK20/BF20 class: 1-3 kg)", "kg")
    bearing_seat_height: float = _g(0.05, 0.01, 0.5, "bolted face seat-base below the screw axis; [assumed] "
                                    "= table_bottom_height (0.03-0.07 m)")
    bearing_seat_face_x: float = _g(0.04, 0.01, 0.5, "bolted face seat-base along x; [assumed] support unit "
                                    "width 30-50 mm")
    bearing_seat_face_y: float = _g(0.10, 0.01, 0.5, "bolted face seat-base along y; [assumed] support unit "
                                    "length 80-120 mm")

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            lo, hi = f.metadata["lo"], f.metadata["hi"]
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                    or not lo <= value <= hi:
                raise InputError(f"rig.{f.name}", value, f"a finite number in [{lo}, {hi}] {f.metadata['unit']}")
            object.__setattr__(self, f.name, float(value))


@dataclass(frozen=True)
class JointData:
    """Stiffness (N/m) and damping (N s/m) of one joint, normal/tangential (fixed) or per direction (moving)."""

    kn: float
    cn: float
    kt: float
    ct: float


@lru_cache(maxsize=1)
def paper_joints():
    """The paper's joint tables in SI, keyed by joint name.

    Returns
    -------
    dict of str -> JointData
        Table 1 rows (``"base-guide"``, ``"base-bearing seat"``, ``"workbench-slider"``,
        ``"workbench-nut seat"``, ``"nut-nut seat"``): normal ``kn, cn`` and tangential ``kt, ct``.
        Table 2 rows (``"bearing seat-outer ring"``, ``"inner ring-screw shaft"``): ``kn, cn`` = radial,
        ``kt, ct`` = axial. Tables 4-6 (``"screw-nut"``, ``"bearing"``): ``kn, cn`` = radial,
        ``kt, ct`` = axial; ``"guide-slider"``: ``kn, cn`` = vertical, ``kt, ct`` = lateral.

    Notes
    -----
    The CSV of Table 1 warns that the text extraction may have shuffled its columns (Kt is almost equal
    to Cn in every row, so the tangential stiffness reads ~1e-4 of the normal one). The values are used
    as printed; ``rigid_joints=True`` in :func:`drakecreep.multibody.build_multibody` removes them.
    """
    folder = paper_data_dir()
    out = {}
    t1 = pd.read_csv(folder / "table1_bolted_fixed_joints.csv", comment="#")
    for r in t1.itertuples(index=False):
        out[r.joint] = JointData(kn=r.Kn_1e10_N_per_m * 1e10, cn=r.Cn_1e8_Ns_per_m * 1e8,
                                 kt=r.Kt_1e10_N_per_m * 1e10, ct=r.Ct_1e8_Ns_per_m * 1e8)
    t2 = pd.read_csv(folder / "table2_interference_fit_joints.csv", comment="#")
    for r in t2.itertuples(index=False):
        out[r.joint] = JointData(kn=r.Kr_1e10_N_per_m * 1e10, cn=r.Cr_1e8_Ns_per_m * 1e8,
                                 kt=r.Ka_1e10_N_per_m * 1e10, ct=r.Ca_1e8_Ns_per_m * 1e8)
    t4 = pd.read_csv(folder / "table4_6_moving_joints_experimental.csv", comment="#")
    rows = {(r.pair, r.direction): (r.stiffness_N_per_m, r.damping_Ns_per_m) for r in t4.itertuples(index=False)}
    for pair, normal, tangential in (("screw-nut", "radial", "axial"), ("bearing", "radial", "axial"),
                                     ("guide-slider", "vertical", "lateral")):
        (kn, cn), (kt, ct) = rows[(pair, normal)], rows[(pair, tangential)]
        out[pair] = JointData(kn=float(kn), cn=float(cn), kt=float(kt), ct=float(ct))
    return out


def series(*stiffnesses):
    """Stiffness of springs in series, ``1 / sum(1 / k_i)``; ``inf`` terms are rigid, a 0 term frees it."""
    if any(k == 0.0 for k in stiffnesses):
        return 0.0
    compliance = sum(1.0 / k for k in stiffnesses if math.isfinite(k))
    return math.inf if compliance == 0.0 else 1.0 / compliance


def series_damping(pairs):
    """Damping of Kelvin-Voigt elements ``(k_i, c_i)`` in series, light-damping form ``K^2 sum(c_i / k_i^2)``.

    The same combination as :func:`drakecreep.model.screw.axial_damping` (each element's loss factor
    weighted by its share of the compliance); rigid (``inf``) elements contribute nothing.
    """
    k = series(*(k for k, _ in pairs))
    if k == 0.0:
        return 0.0
    return k**2 * sum(c / ki**2 for ki, c in pairs if math.isfinite(ki))


def face_joint(kn, kt, normal, extent):
    """Six stiffnesses of a flat bolted face with uniform pressure, in the world axes.

    Parameters
    ----------
    kn, kt : float
        Normal and tangential stiffness of the whole face (N/m), or damping (N s/m): the same map.
    normal : int
        Axis (0 = x, 1 = y, 2 = z) of the face normal.
    extent : tuple of two floats
        The face's sides (m) along the other two axes, in increasing axis order.

    Returns
    -------
    torque, force : list of 3 floats
        Rocking about an in-plane axis: ``kn b^2 / 12`` with ``b`` the side across that axis (uniform
        pressure over a rectangle); twist about the normal: ``kt (a^2 + b^2) / 12``; forces: ``kn``
        along the normal, ``kt`` in the plane.
    """
    others = [i for i in range(3) if i != normal]
    side = dict(zip(others, extent))
    torque, force = [0.0] * 3, [0.0] * 3
    force[normal] = kn
    torque[normal] = kt * (extent[0] ** 2 + extent[1] ** 2) / 12.0
    for axis in others:
        across = side[[o for o in others if o != axis][0]]
        force[axis] = kt
        torque[axis] = kn * across**2 / 12.0
    return torque, force
