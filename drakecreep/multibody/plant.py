"""The seed paper's rigid-flexible feed system (its Figs. 1 and 10) as a Drake ``MultibodyPlant``.

Bodies (x along the screw, z up, the thrust bearing at x = 0)::

    base/guides (world) ==4 slider bushings== table ==bolted face== nut seat ==flange+balls== nut
                                                                                             | ScrewJoint
    world ==(base-seat face)== bearing seat 0 ==thrust bearing== screw_0 ~ screw_1 ~ ... ~ screw_{N-1}
                                                                                  == floating bearing == bearing seat 1

* The screw is ``N`` rigid segments (solid cylinders of the nominal diameter, as the two-mass model's
  rotary inertia) joined by ``LinearBushingRollPitchYaw`` elements with the section's stiffness at the
  root diameter: axial ``E A / l``, torsion ``G J / l``, bending ``E I / l`` and Timoshenko shear
  ``kappa G A / l`` (the rigid-finite-element method; ``l = L / N``). The motor rotor and coupling are
  rigidly attached to the first segment (the two-mass model's assumption), as a thin disc (its tilt
  inertia ``J / 2`` keeps the segment's inertia physical; the thrust bearing is at that segment).
* Axial stiffness and damping of the thrust bearing and of the screw-nut pair come from the parameters
  (``screw.bearing_*``, ``nut.axial_*``: the two-mass chain's values, Tables 4 and 6 in the paper preset);
  every other joint value comes from the paper's tables (:func:`drakecreep.multibody.rig.paper_joints`).
* The nut rides on the segment under it through a ``ScrewJoint`` (kinematic lead; ``+theta`` of the screw
  feeds ``+x``, as in the two-mass model); the compliance of the ball contacts (Table 4) sits in the
  bushing nut - nut seat, in series with the flange's bolted face (Table 1, "nut-nut seat").
* Bearings (Table 6) in series with the ring fits (Table 2) connect the screw ends to the bearing
  seats; the seats sit on the base through their bolted faces (Table 1). The far bearing is axially free
  for ``mounting: fixed-free``. Bearings carry no moment (the screw is simply supported) and no torque
  (the motor's ``viscous_damping`` acts there).
* The table rests on the guides through four slider bushings: guide-slider (Table 5) in series with the
  workbench-slider face and half of the base-guide face (Table 1); free along x (friction and the feed
  are for a later session). Sliders' masses are lumped into the table.

With ``rigid_joints=True`` every fixed joint of Tables 1-2 is rigid: the bearing seats are the base,
the nut seat is part of the table and the table slides on a ``PrismaticJoint``; what is left is the
two-mass model's axial chain (bearing, shaft, screw-nut) plus the screw's own flexibility and mass.

Free bodies use ``RpyFloatingJoint`` (no quaternions), so ``nq == nv`` and the velocity-to-qdot map is
the identity at the undeformed pose: a clean setting for :mod:`drakecreep.multibody.modes`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    LinearBushingRollPitchYaw,
    PrismaticJoint,
    PrismaticSpring,
    RevoluteJoint,
    RevoluteSpring,
    RotationalInertia,
    RpyFloatingJoint,
    ScrewJoint,
    SpatialInertia,
)
from pydrake.systems.framework import DiagramBuilder

from drakecreep.errors import InputError
from drakecreep.model.motor import motor_inertia
from drakecreep.multibody.rig import RigGeometry, face_joint, paper_joints, series, series_damping

__all__ = ["MultibodyDrive", "build_multibody", "BodyGroup", "POISSON_RATIO", "RIGID_TWIST_FACTOR",
           "shear_coefficient"]

#: [assumed] Poisson's ratio of the screw steel, handbook value (0.27-0.30)
POISSON_RATIO = 0.3
#: with rigid joints the nut's spin is held by a torsional spring this many times the screw-nut axial
#: stiffness seen through the lead (``k_axial (Ph / 2 pi)^2``): its share of the chain's compliance is
#: then 1e-6 of the nut's (a ScrewJoint needs something to stop the nut turning)
RIGID_TWIST_FACTOR = 1e6


def shear_coefficient(nu):
    """Timoshenko shear coefficient of a solid circular section, ``6 (1 + nu) / (7 + 6 nu)`` (Cowper 1966)."""
    return 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)


class BodyGroup:
    """Names of the body groups (for labelling mode shapes)."""

    SCREW = "screw"
    NUT = "nut"
    TABLE = "table"
    BEARING_SEAT = "bearing_seat"


@dataclass
class MultibodyDrive:
    """A built multibody feed drive.

    Attributes
    ----------
    diagram : pydrake.systems.framework.Diagram
        Holds the plant (named ``"plant"``); later sessions wire the controller to it.
    plant : MultibodyPlant
        Continuous time, finalized.
    params : DriveParams
    rig : RigGeometry
    n_segments : int
    rigid_joints : bool
    table_position : float
        x (m) at which the model was built (the nut sits ``nut_start_distance + x`` from the bearing).
    groups : dict
        Body name -> :class:`BodyGroup` name.
    joints : dict
        Bushing name -> ``{"force_stiffness", "torque_stiffness", "force_damping", "torque_damping"}``
        (lists of 3, N/m, N m/rad, N s/m, N m s/rad, in the bushing's axes = world axes).
    home : dict
        Body name -> position (m, world) of its origin (centre of mass) in the undeformed rig.
    screw_bending : bool
        False when the screw segments only slide along and turn about x (:func:`build_multibody`).
    """

    diagram: object
    plant: MultibodyPlant
    params: object
    rig: RigGeometry
    n_segments: int
    rigid_joints: bool
    table_position: float
    groups: dict = field(default_factory=dict)
    joints: dict = field(default_factory=dict)
    home: dict = field(default_factory=dict)
    screw_bending: bool = True

    @property
    def segment_length(self):
        """Length (m) of one screw segment."""
        return self.params.screw.length / self.n_segments

    def total_mass(self, group):
        """Sum of the masses (kg) of a body group."""
        return sum(self.plant.GetBodyByName(n).default_mass() for n, g in self.groups.items() if g == group)


def _box_inertia(mass, a, b, c):
    return SpatialInertia.MakeFromCentralInertia(
        mass, np.zeros(3),
        RotationalInertia(mass * (b * b + c * c) / 12.0, mass * (a * a + c * c) / 12.0, mass * (a * a + b * b) / 12.0))


def _cylinder_x(mass, r_out, r_in, length, extra_ixx=0.0):
    """Central inertia of a tube along x; ``extra_ixx`` is added as a thin disc (``Iyy = Izz = extra / 2``)."""
    ixx = mass * (r_out**2 + r_in**2) / 2.0 + extra_ixx
    iyy = mass * (3.0 * (r_out**2 + r_in**2) + length**2) / 12.0 + extra_ixx / 2.0
    return SpatialInertia.MakeFromCentralInertia(mass, np.zeros(3), RotationalInertia(ixx, iyy, iyy))


def build_multibody(params, n_segments=12, rigid_joints=False, table_position=0.0, rig=None, builder=None,
                    rigid_twist_factor=RIGID_TWIST_FACTOR, screw_bending=True):
    """Build the multibody feed drive of ``params`` (continuous-time ``MultibodyPlant`` in a diagram).

    Parameters
    ----------
    params : DriveParams
        The same parameters as the two-mass model (screw, nut, table, motor inertia, gravity).
    n_segments : int
        Rigid segments of the screw (>= 2); see ``analysis/multibody_convergence.py`` for the choice.
    rigid_joints : bool
        Make the fixed joints of Tables 1-2 rigid (see the module docstring).
    table_position : float
        Table position x (m); the nut is ``screw.nut_start_distance + x`` from the thrust bearing.
    rig : RigGeometry, optional
        Geometry and masses the paper does not give; defaults to :class:`RigGeometry`'s assumptions.
    rigid_twist_factor : float
        With ``rigid_joints``: the nut's spin spring in units of the screw-nut axial stiffness seen through
        the lead (:data:`RIGID_TWIST_FACTOR`, >= 1); its share of the axial chain's compliance is
        ``1 / factor`` of the nut's. Its mode (~6e5 rad/s at 1e6) sets the step of an explicit integrator.
    screw_bending : bool
        False (with ``rigid_joints`` only): each screw segment moves only along and about the screw's axis,
        relative to the segment before it (a ``PrismaticJoint`` to a massless carrier, then a
        ``RevoluteJoint``; 2 instead of 6 degrees of freedom). The shaft sections become a
        ``PrismaticSpring`` (``EA/l``) and a ``RevoluteSpring`` (``GJ/l``) on those coordinates, the thrust
        bearing a ``PrismaticSpring`` with joint damping on the first segment, the motor's drag joint damping:
        the same axial and torsion forces as the bushings, at a fraction of their cost (a
        ``LinearBushingRollPitchYaw`` costs ~10 us per evaluation). No bending, shear or lateral sag: the
        screw's bending modes (from ~100 Hz, lateral, not coupled to the feed's axial motion) are gone.
        For closed-loop runs of the axial dynamics (creep); ``tests/multibody/test_modes.py`` and
        ``tests/multibody/test_diagram.py`` check the axial mode and a stick-slip run against the full screw.
    builder : DiagramBuilder, optional
        Add the plant to this builder (the caller wires and builds the diagram; ``drive.diagram`` is then
        None). Default: a diagram of the plant alone.

    Returns
    -------
    MultibodyDrive
    """
    if isinstance(n_segments, bool) or not isinstance(n_segments, int) or not 2 <= n_segments <= 400:
        raise InputError("n_segments", n_segments, "an integer in [2, 400]")
    if not isinstance(rigid_joints, bool):
        raise InputError("rigid_joints", rigid_joints, "true or false")
    if not isinstance(screw_bending, bool):
        raise InputError("screw_bending", screw_bending, "true or false")
    if not screw_bending and not rigid_joints:
        raise InputError("screw_bending", screw_bending, "true with the fixed joints of Tables 1-2 (false needs "
                         "rigid_joints: the axial screw hangs on the world)")
    if isinstance(rigid_twist_factor, bool) or not isinstance(rigid_twist_factor, (int, float)) \
            or not 1.0 <= rigid_twist_factor <= 1e12:
        raise InputError("rigid_twist_factor", rigid_twist_factor, "a number in [1, 1e12]")
    rig = RigGeometry() if rig is None else rig
    screw, nut, table = params.screw, params.nut, params.table
    a_nut = screw.nut_start_distance + float(table_position)
    if not (math.isfinite(a_nut) and 0.0 < a_nut < screw.length):
        raise InputError("table_position", table_position,
                         f"in (-{screw.nut_start_distance}, {screw.length - screw.nut_start_distance}) m "
                         "(the nut stays on the screw)")
    if not rigid_joints and rig.nut_seat_mass >= table.mass:
        raise InputError("rig.nut_seat_mass", rig.nut_seat_mass, f"< table.mass ({table.mass} kg)")
    jd = paper_joints()

    own_builder = builder is None
    builder = DiagramBuilder() if own_builder else builder
    plant = builder.AddSystem(MultibodyPlant(0.0))
    plant.set_name("plant")
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -params.loads.gravity])
    drive = MultibodyDrive(diagram=None, plant=plant, params=params, rig=rig, n_segments=n_segments,
                           rigid_joints=rigid_joints, table_position=float(table_position),
                           screw_bending=screw_bending)
    world = plant.world_frame()
    home = {}

    def free_body(name, group, inertia, p):
        body = plant.AddRigidBody(name, inertia)
        frame = plant.AddFrame(FixedOffsetFrame(f"{name}_home", world, RigidTransform(np.asarray(p, float))))
        plant.AddJoint(RpyFloatingJoint(f"{name}_free", frame, body.body_frame()))
        drive.groups[name] = group
        home[name] = np.asarray(p, float)
        return body

    def axial_segment(i, inertia, p, previous):
        """Segment ``i`` sliding along and turning about x relative to the one before (the world for i = 0):
        ``PrismaticJoint`` to a massless carrier, ``RevoluteJoint`` on it; the shaft springs act on them."""
        name = f"screw_{i}"
        body = plant.AddRigidBody(name, inertia)
        carrier = plant.AddRigidBody(f"{name}_carrier", SpatialInertia.Zero())
        if previous is None:
            parent = plant.AddFrame(FixedOffsetFrame(f"{name}_home", world, RigidTransform(np.asarray(p, float))))
        else:
            parent = plant.AddFrame(FixedOffsetFrame(f"{name}_home", previous.body_frame(),
                                                     RigidTransform(np.asarray(p, float) - home[previous.name()])))
        plant.AddJoint(PrismaticJoint(f"{name}_slide", parent, carrier.body_frame(), [1.0, 0.0, 0.0]))
        plant.AddJoint(RevoluteJoint(f"{name}_spin", carrier.body_frame(), body.body_frame(), [1.0, 0.0, 0.0]))
        drive.groups[name] = BodyGroup.SCREW
        home[name] = np.asarray(p, float)
        return body

    def frame_at(body, p, tag):
        """A frame on ``body`` (or the world, ``body=None``) at world point ``p`` of the undeformed rig."""
        if body is None:
            return plant.AddFrame(FixedOffsetFrame(f"world_{tag}", world, RigidTransform(np.asarray(p, float))))
        offset = np.asarray(p, float) - home[body.name()]
        return plant.AddFrame(FixedOffsetFrame(f"{body.name()}_{tag}", body.body_frame(), RigidTransform(offset)))

    def bushing(name, frame_a, frame_c, k_torque, c_torque, k_force, c_force):
        values = [list(map(float, v)) for v in (k_torque, c_torque, k_force, c_force)]
        for v in values:
            if not all(math.isfinite(x) and x >= 0.0 for x in v):  # pragma: no cover - a modelling bug
                raise ValueError(f"bushing {name}: {values}")
        plant.AddForceElement(LinearBushingRollPitchYaw(frame_a, frame_c, *[np.array(v) for v in values]))
        drive.joints[name] = dict(torque_stiffness=values[0], torque_damping=values[1],
                                  force_stiffness=values[2], force_damping=values[3])

    # ------------------------------------------------------------------ screw segments
    n, length = n_segments, screw.length
    seg = length / n
    r_nom = screw.nominal_diameter / 2.0
    m_seg = screw.density * math.pi * r_nom**2 * seg
    area = math.pi / 4.0 * screw.root_diameter**2
    second_moment = math.pi / 64.0 * screw.root_diameter**4
    e_mod = screw.youngs_modulus
    g_mod = e_mod / (2.0 * (1.0 + POISSON_RATIO))
    kappa = shear_coefficient(POISSON_RATIO)
    rotor = motor_inertia(params.motor)
    segments = []
    for i in range(n):
        inertia = _cylinder_x(m_seg, r_nom, 0.0, seg, extra_ixx=rotor if i == 0 else 0.0)
        p_seg = [(i + 0.5) * seg, 0.0, 0.0]
        if screw_bending:
            segments.append(free_body(f"screw_{i}", BodyGroup.SCREW, inertia, p_seg))
        else:
            segments.append(axial_segment(i, inertia, p_seg, segments[-1] if segments else None))
    k_seg_force = [e_mod * area / seg, kappa * g_mod * area / seg, kappa * g_mod * area / seg]
    k_seg_torque = [g_mod * 2.0 * second_moment / seg, e_mod * second_moment / seg, e_mod * second_moment / seg]
    for i in range(n - 1):
        p = [(i + 1) * seg, 0.0, 0.0]
        if screw_bending:
            bushing(f"shaft_{i}", frame_at(segments[i], p, "right"), frame_at(segments[i + 1], p, "left"),
                    k_seg_torque, [0.0] * 3, k_seg_force, [0.0] * 3)
        else:
            # the same shaft section on the chain's relative coordinates (exactly the bushing's axial and
            # torsion terms; its shear and bending terms act on motions this screw does not have)
            plant.AddForceElement(PrismaticSpring(plant.GetJointByName(f"screw_{i + 1}_slide"), 0.0, k_seg_force[0]))
            plant.AddForceElement(RevoluteSpring(plant.GetJointByName(f"screw_{i + 1}_spin"), 0.0, k_seg_torque[0]))
            drive.joints[f"shaft_{i}"] = dict(torque_stiffness=[k_seg_torque[0], 0.0, 0.0], torque_damping=[0.0] * 3,
                                              force_stiffness=[k_seg_force[0], 0.0, 0.0], force_damping=[0.0] * 3)

    # ------------------------------------------------------------------ bearings and their seats
    # axial values from the parameters (the two-mass chain's), radial ones from Table 6
    bearing = dataclasses.replace(jd["bearing"], kt=screw.bearing_stiffness, ct=screw.bearing_damping)
    outer, inner = jd["bearing seat-outer ring"], jd["inner ring-screw shaft"]
    fits = [] if rigid_joints else [outer, inner]
    k_ax = series(bearing.kt, *(f.kt for f in fits))
    c_ax = series_damping([(bearing.kt, bearing.ct)] + [(f.kt, f.ct) for f in fits])
    k_rad = series(bearing.kn, *(f.kn for f in fits))
    c_rad = series_damping([(bearing.kn, bearing.cn)] + [(f.kn, f.cn) for f in fits])
    seat_joint = jd["base-bearing seat"]
    for side, (x_b, shaft_body, end) in enumerate(((0.0, segments[0], "left_end"),
                                                   (length, segments[-1], "right_end"))):
        axial = side == 0 or screw.mounting == "fixed-fixed"
        if rigid_joints:
            base = frame_at(None, [x_b, 0.0, 0.0], f"bearing_{side}")
        else:
            h = rig.bearing_seat_height
            seat = free_body(f"bearing_seat_{side}", BodyGroup.BEARING_SEAT,
                             _box_inertia(rig.bearing_seat_mass, rig.bearing_seat_face_x, rig.bearing_seat_face_y, h),
                             [x_b, 0.0, -h / 2.0])
            extent = (rig.bearing_seat_face_x, rig.bearing_seat_face_y)
            kt_, kf_ = face_joint(seat_joint.kn, seat_joint.kt, 2, extent)
            ct_, cf_ = face_joint(seat_joint.cn, seat_joint.ct, 2, extent)
            p_face = [x_b, 0.0, -h]
            bushing(f"base-bearing_seat_{side}", frame_at(None, p_face, f"seat_{side}"),
                    frame_at(seat, p_face, "face"), kt_, ct_, kf_, cf_)
            base = frame_at(seat, [x_b, 0.0, 0.0], "bearing")
        if not screw_bending and side == 0:
            # the thrust bearing on the first segment's coordinates (absolute: its carrier slides on the world,
            # and does not turn): axial spring and damper, the motor's viscous drag on the rotation
            slide, spin = plant.GetJointByName("screw_0_slide"), plant.GetJointByName("screw_0_spin")
            plant.AddForceElement(PrismaticSpring(slide, 0.0, k_ax))
            slide.set_default_damping(c_ax)
            spin.set_default_damping(params.motor.viscous_damping)
            drive.joints["bearing_0"] = dict(torque_stiffness=[0.0] * 3, torque_damping=[params.motor.viscous_damping, 0, 0],
                                             force_stiffness=[k_ax, 0.0, 0.0], force_damping=[c_ax, 0.0, 0.0])
            continue
        if not screw_bending and not axial:
            continue  # the floating bearing's radial support acts on motions this screw does not have
        bushing(f"bearing_{side}", base, frame_at(shaft_body, [x_b, 0.0, 0.0], end),
                [0.0] * 3, [params.motor.viscous_damping if side == 0 else 0.0, 0.0, 0.0],
                [k_ax if axial else 0.0, k_rad, k_rad], [c_ax if axial else 0.0, c_rad, c_rad])

    # ------------------------------------------------------------------ table (and nut seat)
    table_home = [a_nut, 0.0, rig.table_bottom_height + rig.table_thickness / 2.0]
    table_dims = (rig.table_length, rig.table_width, rig.table_thickness)
    if rigid_joints:
        body = plant.AddRigidBody("table", _box_inertia(table.mass, *table_dims))
        frame = plant.AddFrame(FixedOffsetFrame("table_home", world, RigidTransform(np.array(table_home))))
        plant.AddJoint(PrismaticJoint("table_slide", frame, body.body_frame(), [1.0, 0.0, 0.0]))
        drive.groups["table"] = BodyGroup.TABLE
        home["table"] = np.array(table_home)
        table_body = holder = body
    else:
        table_body = free_body("table", BodyGroup.TABLE, _box_inertia(table.mass - rig.nut_seat_mass, *table_dims),
                               table_home)
        guide, wb_slider, base_guide = jd["guide-slider"], jd["workbench-slider"], jd["base-guide"]
        vertical = [(guide.kn, guide.cn), (wb_slider.kn, wb_slider.cn), (base_guide.kn / 2.0, base_guide.cn / 2.0)]
        lateral = [(guide.kt, guide.ct), (wb_slider.kt, wb_slider.ct), (base_guide.kt / 2.0, base_guide.ct / 2.0)]
        k_force = [0.0, series(*(k for k, _ in lateral)), series(*(k for k, _ in vertical))]
        c_force = [0.0, series_damping(lateral), series_damping(vertical)]
        for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (-1, 1), (1, 1))):
            p = [a_nut + sx * rig.slider_spacing_x / 2.0, sy * rig.guide_spacing_y / 2.0, rig.slider_height]
            bushing(f"slider_{i}", frame_at(None, p, f"guide_{i}"), frame_at(table_body, p, f"slider_{i}"),
                    [0.0] * 3, [0.0] * 3, k_force, c_force)
        s = rig.nut_seat_face
        holder = free_body("nut_seat", BodyGroup.TABLE, _box_inertia(rig.nut_seat_mass, s, s, 2.0 * rig.table_bottom_height),
                           [a_nut, 0.0, 0.0])
        face = jd["workbench-nut seat"]
        kt_, kf_ = face_joint(face.kn, face.kt, 2, (s, s))
        ct_, cf_ = face_joint(face.cn, face.ct, 2, (s, s))
        p_face = [a_nut, 0.0, rig.table_bottom_height]
        bushing("workbench-nut_seat", frame_at(table_body, p_face, "nut_seat_face"), frame_at(holder, p_face, "face"),
                kt_, ct_, kf_, cf_)

    # ------------------------------------------------------------------ nut on the screw
    j = min(int(a_nut / seg), n - 1)
    nut_body = plant.AddRigidBody("nut", _cylinder_x(nut.mass, rig.nut_outer_diameter / 2.0, r_nom, rig.nut_length))
    drive.groups["nut"] = BodyGroup.NUT
    home["nut"] = np.array([a_nut, 0.0, 0.0])
    plant.AddJoint(ScrewJoint("screw_nut", frame_at(segments[j], [a_nut, 0.0, 0.0], "nut"), nut_body.body_frame(),
                              [1.0, 0.0, 0.0], -screw.lead, 0.0))
    sn = dataclasses.replace(jd["screw-nut"], kt=nut.axial_stiffness, ct=nut.axial_damping)  # radial: Table 4
    tilt, tilt_c = sn.kn * rig.nut_length**2 / 12.0, sn.cn * rig.nut_length**2 / 12.0
    ratio = screw.lead / (2.0 * math.pi)
    if rigid_joints:
        k_force, c_force = [sn.kt, sn.kn, sn.kn], [sn.ct, sn.cn, sn.cn]
        k_torque = [float(rigid_twist_factor) * sn.kt * ratio**2, tilt, tilt]
        c_torque = [0.0, tilt_c, tilt_c]
    else:
        flange = jd["nut-nut seat"]
        f = rig.nut_flange_face
        kt_, kf_ = face_joint(flange.kn, flange.kt, 0, (f, f))
        ct_, cf_ = face_joint(flange.cn, flange.ct, 0, (f, f))
        contact_force = [(sn.kt, sn.ct), (sn.kn, sn.cn), (sn.kn, sn.cn)]
        contact_torque = [(math.inf, 0.0), (tilt, tilt_c), (tilt, tilt_c)]
        k_force = [series(kc, kfl) for (kc, _), kfl in zip(contact_force, kf_)]
        c_force = [series_damping([pc, (kfl, cfl)]) for pc, kfl, cfl in zip(contact_force, kf_, cf_)]
        k_torque = [series(kc, kfl) for (kc, _), kfl in zip(contact_torque, kt_)]
        c_torque = [series_damping([pc, (kfl, cfl)]) for pc, kfl, cfl in zip(contact_torque, kt_, ct_)]
    p_nut = [a_nut, 0.0, 0.0]
    bushing("nut-nut_seat", frame_at(holder, p_nut, "nut"), frame_at(nut_body, p_nut, "flange"),
            k_torque, c_torque, k_force, c_force)

    plant.Finalize()
    drive.home = home
    drive.diagram = builder.Build() if own_builder else None
    return drive
