"""The multibody feed drive in closed loop: the project's controller, sensors and friction on the MultibodyPlant.

::

    FeedReference -> CascadeController -> torque_limit -> current_loop --+
                         ^        ^                                      |  tau on screw_0 (roll)
                   MotorEncoder  LinearScale                             v
                         ^        ^          guide_friction --F--> applied_forces --> plant
                      motor     table  <---- state_select <----------- plant.state
                                              nut_friction --tau--^    (+ the load case)

* The motor: the torque command passes the peak-torque limit (``Saturation``) and the closed current
  loop (``FirstOrderLowPassFilter`` of ``motor.current_loop_time_constant``; the two-mass
  :class:`~drakecreep.model.motor.Motor` applies the same clip and lag) and acts as a torque about x on
  the first screw segment, which carries the rotor and coupling inertia. The motor's viscous drag is
  the thrust bearing's torque damping in the plant.
* Friction, from the project's TemplateSystem :class:`~drakecreep.model.nut_friction.NutFriction`
  (one law, ``params.friction``, levels from the load case as in the two-mass model):

  - guides (``guide_friction``): the guides' share (:func:`~drakecreep.model.nut_table.table_friction_levels`:
    seals + ``mu (|m g + Fz| + |Fy|)``) at the table's speed along x, applied to the table at the
    height of the slider contacts (a force along -x and its pitch moment about the table's centre
    of mass). ``NutFriction`` with ``lead = 2 pi`` is the law at ratio 1: input ``[x, v]``, output N.
  - nut (``nut_friction``, when ``friction.nut_friction_on == "screw"``): the drag torque of the nut's
    share (preload + ``mu_nut |Fx|``) at the screw's speed relative to the nut, applied as a
    generalized force of the ``ScrewJoint`` (equal and opposite on screw and nut). With
    ``nut_friction_on: table`` the nut's share is lumped into ``guide_friction`` as in the two-mass model.

* Load case (Table 7): ``Fx`` opposing the feed, ``Fz`` pressing down and ``Fy`` lateral, constant
  forces at the table's centre of mass (the air cylinders' point of action is not given; with rigid
  joints the table slides on a prismatic joint and only ``Fx`` acts).
* Initial state: the static equilibrium at rest under gravity and the load case with the table at x = 0
  and the motor holding the torque that balances it (:func:`loaded_equilibrium`; ``Fx Ph / 2 pi`` within
  ~1e-5 of it: the deformed rig couples the vertical loads into the feed slightly), as the two-mass
  diagram starts; the controller's integrator and the current loop carry that torque.

Signals are exported under the two-mass diagram's names (``table.table_state``, ``motor.motor_state``,
``controller.*``, ...; :data:`drakecreep.model.diagram.SIGNALS`), so :mod:`drakecreep.sim.simulation` and
the metrics read both models alike. ``spring_force`` is the axial force the screw puts on the nut
(the ``ScrewJoint``'s reaction force); ``table_position`` is the table's centre of mass along x.

The nut rides on the screw segment it was built on (``table_position`` of the build): the feeds
simulated move it by millimetres, against segments of ``L / N`` (50 mm at N = 12 on the paper preset);
a run that travels further than one segment is refused (:func:`build_multibody_diagram`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import (
    Adder,
    ConstantVectorSource,
    FirstOrderLowPassFilter,
    MatrixGain,
    Multiplexer,
    Saturation,
)

from drakecreep.errors import InputError
from drakecreep.model.controller import CascadeController, force_limit
from drakecreep.model.diagram import SIGNALS, FeedDrive
from drakecreep.model.disturbances import LoadRipple
from drakecreep.model.nut_friction import NutFriction, nut_friction_levels, nut_friction_params
from drakecreep.model.nut_table import table_friction_levels
from drakecreep.model.reference import FeedReference
from drakecreep.model.sensors import LinearScale, MotorEncoder, encoder_resolution, quantize
from drakecreep.multibody.plant import build_multibody
from drakecreep.params import two_mass_effects

__all__ = ["MultibodyOptions", "MultibodyFeedDrive", "build_multibody_diagram", "loaded_equilibrium",
           "DEFAULT_SEGMENTS", "INTEGRATORS"]

#: Drake integrators a multibody run may use (names of ``ResetIntegratorFromFlags``)
INTEGRATORS = ("velocity_implicit_euler", "implicit_euler", "radau3", "runge_kutta3", "runge_kutta2")

#: screw segments of a closed-loop run (modal convergence: 0.8 % at N = 6 with the fixed joints of
#: Table 1, 1.1 % with rigid joints, against N = 24; docs/multibody.md)
DEFAULT_SEGMENTS = 6
#: why the multibody plant has no such effect, where it is not only that the effect is the two-mass model's
#: (:func:`drakecreep.params.two_mass_effects`)
_WHY_NOT = {"the lead error": "its ScrewJoint has an exact lead; ",
            "the nut's lost motion": "its ScrewJoint has no lost motion; ",
            "the structural mode on the table": "its table is one rigid body; "}


@dataclass(frozen=True)
class MultibodyOptions:
    """How the multibody model of a closed-loop run is built.

    Attributes
    ----------
    n_segments : int
        Screw segments (2-400). The stiffest mode of the screw grows with N (segment stiffness ``EA/l``
        on segment mass ``~l``), so the run's cost grows with N; see :data:`DEFAULT_SEGMENTS`.
    rigid_joints : bool
        Fixed joints of Tables 1-2 rigid (the two-mass model's assumption); see
        :func:`drakecreep.multibody.build_multibody`.
    friction : bool
        False removes the guides' and the nut's friction (for comparisons with the frictionless chain).
    rigid_twist_factor : float
        With rigid joints, the nut's spin spring (:func:`drakecreep.multibody.build_multibody`). Default
        :data:`SIM_TWIST_FACTOR`: its compliance is 1e-3 of the nut's, and its mode falls from
        ~6e5 to ~2e4 rad/s, below the screw's own stiffest modes.
    integrator : str
        Drake integrator of the run (:data:`INTEGRATORS`). Default (``""``): ``runge_kutta3`` with rigid
        joints, ``velocity_implicit_euler`` with the fixed joints of Table 1, whose overdamped motions
        (eigenvalues to ~2.6e6 1/s) would hold an explicit integrator to steps of ~1 us. Measured on the
        paper preset (load case 3, 0.2 mm/s, rigid joints, N = 3): RK3 stick-slips as the two-mass model
        does (0.230 vs 0.231 mm/s, 71 vs 72 cycles) where velocity-implicit Euler at 1e-4 slides smoothly:
        its numerical damping can hide stick-slip; keep the convergence check on with it. On the rigid-joint
        model (N = 3, axial screw) the check catches it: the 1e-4 run's check at 1e-5 disagrees, the rerun at
        1e-5 stick-slips (0.228 mm/s, 71 cycles, RK3 0.230) and passes at 1e-6; with
        ``simulation.max_step`` 2e-5 s it stick-slips at 1e-4 already (0.2295 mm/s). A smooth verdict of an
        implicit integrator is safest checked with a small ``max_step`` too (docs/multibody.md).
    screw_bending : bool
        False: the screw segments only slide along and turn about the screw axis (no bending, shear or
        sag; :func:`drakecreep.multibody.build_multibody`). Removes the screw's bending modes, lateral
        motions that do not couple to the feed, and makes a run cheaper (fewer degrees of freedom, a
        lower stiffest mode). Measured: docs/multibody.md ("Benchmark").
    """

    n_segments: int = DEFAULT_SEGMENTS
    rigid_joints: bool = False
    friction: bool = True
    rigid_twist_factor: float = 1e3
    integrator: str = ""
    screw_bending: bool = True

    def __post_init__(self):
        if isinstance(self.n_segments, bool) or not isinstance(self.n_segments, int) \
                or not 2 <= self.n_segments <= 400:
            raise InputError("multibody.n_segments", self.n_segments, "an integer in [2, 400]")
        for name in ("rigid_joints", "friction", "screw_bending"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"multibody.{name}", getattr(self, name), "true or false")
        if isinstance(self.rigid_twist_factor, bool) or not isinstance(self.rigid_twist_factor, (int, float)) \
                or not 1.0 <= self.rigid_twist_factor <= 1e12:
            raise InputError("multibody.rigid_twist_factor", self.rigid_twist_factor, "a number in [1, 1e12]")
        if not self.screw_bending and not self.rigid_joints:
            raise InputError("multibody.screw_bending", self.screw_bending, "true unless rigid_joints is true")
        if self.integrator == "":
            object.__setattr__(self, "integrator", "runge_kutta3" if self.rigid_joints else "velocity_implicit_euler")
        if self.integrator not in INTEGRATORS:
            raise InputError("multibody.integrator", self.integrator, ", ".join(INTEGRATORS))


@dataclass
class MultibodyFeedDrive(FeedDrive):
    """A :class:`~drakecreep.model.diagram.FeedDrive` whose mechanics is a MultibodyPlant.

    Extra attributes: ``drive`` (the :class:`~drakecreep.multibody.plant.MultibodyDrive`), ``options``,
    ``q0`` (plant positions at the loaded equilibrium), ``equilibrium_residual`` (N or N m),
    ``initial_torque`` (N m, held by the current loop at t = 0), ``compiled`` (the
    :class:`~drakecreep.sim.compiled.CompiledDrive` of the loop when it was compiled, else None).
    """

    drive: object = None
    options: MultibodyOptions = None
    q0: np.ndarray = None
    equilibrium_residual: float = 0.0
    initial_torque: float = 0.0
    compiled: object = None

    def set_initial_state(self, context):
        """Set the current loop's torque in ``context`` (the diagram's); the plant's positions are its defaults."""
        if self.compiled is not None:
            self.compiled.set_initial_state(self.diagram.GetMutableSubsystemContext(self.compiled.diagram, context))
            return
        if "current_loop" in self.systems:
            lag = self.systems["current_loop"]
            lag.set_initial_output_value(self.diagram.GetMutableSubsystemContext(lag, context),
                                         [self.initial_torque])


class _ReactionForce(LeafSystem):
    """Axial force (N) of the screw on the nut: the x force of the ``ScrewJoint``'s reaction on the nut."""

    def __init__(self, joint_index):
        super().__init__()
        self._index = int(joint_index)
        from pydrake.common.value import Value
        from pydrake.multibody.math import SpatialForce

        self._u = self.DeclareAbstractInputPort("reaction_forces", Value([SpatialForce()]))
        self.DeclareVectorOutputPort("axial_force", 1, self._calc)

    def _calc(self, context, output):
        forces = self._u.Eval(context)
        # F_CJc_Jc: on the nut (child) at its frame, in the nut's axes (x along the screw)
        output.SetAtIndex(0, float(forces[self._index].translational()[0]))


def _indices(drive):
    """Position and velocity indices of the coordinates the loop reads and drives."""
    plant = drive.plant
    seg = plant.GetJointByName("screw_0_free" if drive.screw_bending else "screw_0_spin")  # rotation about x first
    nut = plant.GetJointByName("screw_nut")
    if drive.rigid_joints:
        slide = plant.GetJointByName("table_slide")
        table = dict(qx=slide.position_start(), vx=slide.velocity_start(), vy=None, vz=None, wy=None)
    else:
        free = plant.GetJointByName("table_free")
        q0, v0 = free.position_start(), free.velocity_start()  # q = [rpy, xyz], v = [w, v] (parent axes)
        table = dict(qx=q0 + 3, vx=v0 + 3, vy=v0 + 4, vz=v0 + 5, wy=v0 + 1)
    return dict(table=table, motor_q=seg.position_start(), motor_v=seg.velocity_start(),
                nut_q=nut.position_start(), nut_v=nut.velocity_start(), nut_joint=nut.index())


def _applied_map(drive, idx):
    """``nv x 4`` map of ``[motor torque (N m), guide friction (N), nut joint torque (N m), force ripple (N)]`` to
    generalized forces (the ripple along +x at the table's centre of mass)."""
    nv = drive.plant.num_velocities()
    gain = np.zeros((nv, 4))
    gain[idx["motor_v"], 0] = 1.0
    t = idx["table"]
    gain[t["vx"], 1] = -1.0
    if t["wy"] is not None:
        # friction at the slider contacts, below the table's centre of mass: moment r x (-F x) about y
        dz = drive.rig.slider_height - drive.home["table"][2]
        gain[t["wy"], 1] = -dz
    gain[idx["nut_v"], 2] = 1.0
    gain[t["vx"], 3] = 1.0
    return gain


def _load_forces(drive, idx, load):
    """Generalized forces (nv) of the load case on the table: ``-Fx`` along x, ``-Fz`` (down), ``Fy``."""
    f = np.zeros(drive.plant.num_velocities())
    t = idx["table"]
    f[t["vx"]] = -load.fx
    if t["vz"] is not None:
        f[t["vz"]] = -load.fz
        f[t["vy"]] = load.fy
    return f


def loaded_equilibrium(drive, applied, torque_map, fixed, torque=0.0, context=None, tolerance=1e-6,
                       max_iterations=20):
    """Static equilibrium of ``drive`` under gravity, its force elements, constant loads and a holding torque.

    Newton (chord) steps with the stiffness of :func:`drakecreep.multibody.modes.linearize_mechanics`:
    the coordinate ``fixed`` (a velocity index whose position is held: the table's x, which removes the
    free feed motion) is replaced by the unknown holding torque, so the system is square.

    Parameters
    ----------
    drive : MultibodyDrive
    applied : numpy.ndarray
        Constant generalized forces (nv): the load case.
    torque_map : numpy.ndarray
        Generalized forces (nv) per N m of the holding (motor) torque.
    fixed : int
        Velocity index held.
    torque : float
        Start value of the holding torque (N m).
    context : Context, optional
        The plant's context to move (default: a new one at the default positions).

    Returns
    -------
    q : numpy.ndarray
        Positions at the equilibrium.
    torque : float
        Holding torque (N m).
    residual : float
        Largest generalized force left (N or N m).
    """
    from drakecreep.multibody.modes import _generalized_forces, linearize_mechanics

    plant = drive.plant
    nv = plant.num_velocities()
    pc = plant.CreateDefaultContext() if context is None else context
    plant.SetVelocities(pc, np.zeros(nv))
    _, stiffness, _ = linearize_mechanics(drive, pc)
    keep = np.array([i for i in range(nv) if i != fixed])
    jac = np.column_stack([stiffness[:, keep], -np.asarray(torque_map)])
    torque = float(torque)
    residual = math.inf
    for _ in range(max_iterations):
        f = _generalized_forces(plant, pc) + applied + torque * torque_map
        residual = float(np.max(np.abs(f)))
        if residual <= tolerance:
            return plant.GetPositions(pc), torque, residual
        delta = np.linalg.solve(jac, f)
        step = np.zeros(nv)
        step[keep] = delta[:-1]
        torque += delta[-1]
        plant.SetPositions(pc, plant.GetPositions(pc) + plant.MapVelocityToQDot(pc, step))
    raise RuntimeError(f"loaded equilibrium not reached: residual {residual:.3g} after {max_iterations} steps")


def build_multibody_diagram(params, scenario, options=None, *, continuous=None, ideal_sensors=False,
                            open_loop=False, compiler=None):
    """Wire the multibody feed drive for ``scenario`` from ``params``: the two-mass diagram's loop on the plant.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    scenario : drakecreep.scenario.Scenario
    options : MultibodyOptions, optional
    continuous : bool, optional
        Force the continuous (True) or sampled (False) controller; default ``params.controller.sampled``.
    ideal_sensors : bool
        Unquantized encoder and scale.
    open_loop : bool
        The mechanics alone (for linearization, :mod:`drakecreep.multibody.linear`): no reference,
        controller or sensors; input port ``torque_command`` (N m, into the torque limit and current
        loop); first output ``plant_outputs`` = ``[motor angle, motor speed, table position, table speed]``.
    compiler : callable, optional
        :func:`drakecreep.sim.compiled.compile_diagram` (passed in: ``multibody`` may not import ``sim``).
        When given, every system of the loop but the plant (reference, controller, sensors, torque limit,
        current loop, the friction laws) is compiled into ``SymbolicVectorSystem``s, so the only system
        evaluated in Python during a run is the reaction-force reader at the log's samples; the same
        equations (``tests/multibody/test_diagram.py`` compares the derivatives). Ignored with ``open_loop``.

    Returns
    -------
    MultibodyFeedDrive
        ``diagram`` exports the signals of :data:`drakecreep.model.diagram.SIGNALS` under the same names
        (plus ``nut_friction.friction_force`` with the nut on the screw).
    """
    import dataclasses

    options = MultibodyOptions() if options is None else options
    if getattr(scenario, "drive", "cascade") != "cascade":
        raise InputError("drive", scenario.drive, "cascade (the multibody model runs with the controller)")
    travel = abs(scenario.feed) * scenario.duration
    segment = params.screw.length / options.n_segments
    if travel > segment * (1.0 + 1e-9):
        raise InputError("duration", scenario.duration,
                         f"<= {segment / abs(scenario.feed):.4g} s at {scenario.feed * 1e3:g} mm/s: the nut rides on "
                         f"one screw segment ({segment * 1e3:.4g} mm) in the multibody model")
    gains = params.controller
    if continuous is not None:
        gains = dataclasses.replace(gains, sampled=not continuous)
    load = params.load_case(scenario.load_case)
    ratio = params.screw.lead / (2.0 * math.pi)

    builder = DiagramBuilder()
    drive = build_multibody(params, n_segments=options.n_segments, rigid_joints=options.rigid_joints,
                            table_position=0.0, builder=builder, rigid_twist_factor=options.rigid_twist_factor,
                            screw_bending=options.screw_bending)
    plant = drive.plant
    idx = _indices(drive)
    nq, nv = plant.num_positions(), plant.num_velocities()

    # static equilibrium under the load case, the motor holding Fx through the lead
    loads = _load_forces(drive, idx, load)
    q0, torque0, residual = loaded_equilibrium(drive, loads, _applied_map(drive, idx)[:, 0], idx["table"]["vx"],
                                               torque=load.fx * ratio)
    plant.SetDefaultPositions(q0)
    theta0 = float(q0[idx["motor_q"]])
    theta_counted = quantize(theta0, encoder_resolution(0 if ideal_sensors else params.sensors.encoder_counts_per_rev))
    x_ref0 = theta_counted * ratio if gains.position_feedback == "motor" else 0.0

    s = {}

    def add(name, system, into=builder):
        system.set_name(name)
        s[name] = into.AddSystem(system)
        return s[name]

    def select(name, rows):
        """A MatrixGain picking plant-state entries (index, sign) -> its output."""
        gain = np.zeros((len(rows), nq + nv))
        for r, (i, sign) in enumerate(rows):
            gain[r, i] = sign
        sys = add(name, MatrixGain(gain))
        builder.Connect(plant.get_state_output_port(), sys.get_input_port())
        return sys

    t = idx["table"]
    # the coordinates the loop reads: motor [angle, speed], table [x, v], the screw relative to the nut
    # [-(ScrewJoint angle), -(its speed)] (+theta of the screw feeds +x)
    rows = {"motor": [(idx["motor_q"], 1.0), (nq + idx["motor_v"], 1.0)],
            "table": [(t["qx"], 1.0), (nq + t["vx"], 1.0)],
            "nut_motion": [(idx["nut_q"], -1.0), (nq + idx["nut_v"], -1.0)]}
    table = select("table", rows["table"])
    motor = select("motor", rows["motor"])
    setup = dict(params=params, scenario=scenario, gains=gains, load=load, ideal_sensors=ideal_sensors,
                 theta_counted=theta_counted, x_ref0=x_ref0, torque0=torque0, options=options)
    compiled = None
    if open_loop or compiler is None:
        coords = {"motor": motor.get_output_port(), "table": table.get_output_port(),
                  "nut_motion": (lambda: select("nut_motion", rows["nut_motion"]).get_output_port())}
        ports = _add_controls(builder, add, coords, open_loop=open_loop, **setup)
        applied = ports.pop("applied")
    else:
        compiled, applied, ports = _compiled_controls(builder, add, select, rows, setup, compiler)

    if open_loop:
        outputs = add("plant_outputs", Multiplexer([2, 2]))
        builder.Connect(motor.get_output_port(), outputs.get_input_port(0))
        builder.Connect(table.get_output_port(), outputs.get_input_port(1))
        builder.ExportOutput(outputs.get_output_port(0), "plant_outputs")
    to_forces = add("applied_forces", MatrixGain(_applied_map(drive, idx)))
    builder.Connect(applied, to_forces.get_input_port())
    load_source = add("load_case", ConstantVectorSource(loads))
    total = add("generalized_forces", Adder(2, nv))
    builder.Connect(to_forces.get_output_port(), total.get_input_port(0))
    builder.Connect(load_source.get_output_port(), total.get_input_port(1))
    builder.Connect(total.get_output_port(), plant.get_applied_generalized_force_input_port())

    extra = dict(drive=drive, options=options, q0=q0, equilibrium_residual=residual, initial_torque=torque0,
                 compiled=compiled)
    if open_loop:
        builder.ExportInput(ports["torque_command_in"], "torque_command")
        diagram = builder.Build()
        diagram.set_name("multibody_feed_drive_plant")
        drive.diagram = diagram
        return MultibodyFeedDrive(diagram=diagram, systems=s, params=params, scenario=scenario, signals=(), **extra)

    reaction = add("screw", _ReactionForce(idx["nut_joint"]))
    builder.Connect(plant.get_reaction_forces_output_port(), reaction.get_input_port())
    exports = {("motor", "motor_state"): motor.get_output_port(), ("table", "table_state"): table.get_output_port(),
               ("screw", "axial_force"): reaction.get_output_port(0)}
    exports.update(ports)
    for (system, port), out in exports.items():
        builder.ExportOutput(out, f"{system}.{port}")
    signals = SIGNALS
    if ("nut_friction", "friction_force") in exports:
        signals = signals + (("nut_friction_force", ("nut_friction", "friction_force", 0), "N"),)
    diagram = builder.Build()
    diagram.set_name("multibody_feed_drive")
    drive.diagram = diagram
    return MultibodyFeedDrive(diagram=diagram, systems=s, params=params, scenario=scenario, signals=signals, **extra)


def _add_controls(builder, add, coords, *, params, scenario, gains, load, ideal_sensors, theta_counted, x_ref0,
                  torque0, options, open_loop=False):
    """Add everything of the loop but the plant: reference, controller, sensors, torque limit, current loop, friction.

    ``coords``: output ports ``motor`` and ``table`` (``[position, speed]``) and ``nut_motion`` (a callable
    giving the port of the screw's motion relative to the nut, asked for only when the nut has friction).
    Returns ``{"applied": port of [motor torque (N m), guide friction (N), nut joint torque (N m)],
    (system, port): output port}`` of the recorded signals, or with ``open_loop`` the key
    ``"torque_command_in"`` (the torque limit's input) instead of the signals.
    """
    for path, value, what in two_mass_effects(params):  # the first of them, by name
        raise InputError(path, value, f"0 with the multibody model ({_WHY_NOT.get(what, '')}{what} is a two-mass "
                                      "model effect)")
    s = {}

    def put(name, system):
        s[name] = add(name, system, builder)
        return s[name]

    ratio = params.screw.lead / (2.0 * math.pi)
    if not open_loop:
        put("reference", FeedReference(scenario.feed, params.simulation.acceleration_time, x_ref0))
        put("controller", CascadeController(gains, params.screw.lead, force_limit(params),
                                            initial_force=torque0 / ratio, initial_angle=theta_counted))
        put("encoder", MotorEncoder(0 if ideal_sensors else params.sensors.encoder_counts_per_rev))
        put("scale", LinearScale(0.0 if ideal_sensors else params.sensors.scale_resolution))
    limit = put("torque_limit", Saturation([-params.motor.peak_torque], [params.motor.peak_torque]))
    torque_out = limit.get_output_port()
    tau_c = params.motor.current_loop_time_constant
    if tau_c > 0:
        lag = put("current_loop", FirstOrderLowPassFilter(tau_c, 1))
        builder.Connect(limit.get_output_port(), lag.get_input_port())
        torque_out = lag.get_output_port()

    # friction: the guides on the table, the nut on the screw (the two-mass split of the levels)
    mux = put("applied_inputs", Multiplexer([1, 1, 1, 1]))
    zero = None
    if options.friction:
        fc, fs = table_friction_levels(params, load)
        guide = put("guide_friction", NutFriction(params.friction, fc, fs, 2.0 * math.pi))
        builder.Connect(coords["table"], guide.GetInputPort("motor_state"))
        builder.Connect(guide.GetOutputPort("friction_torque"), mux.get_input_port(1))
        fc_n, fs_n = nut_friction_levels(params, load)
    else:
        fc_n = 0.0
        zero = put("no_friction", ConstantVectorSource([0.0]))
        builder.Connect(zero.get_output_port(), mux.get_input_port(1))
    if fc_n > 0.0:
        nut = put("nut_friction", NutFriction(nut_friction_params(params.friction), fc_n, fs_n, params.screw.lead))
        builder.Connect(coords["nut_motion"](), nut.GetInputPort("motor_state"))
        builder.Connect(nut.GetOutputPort("friction_torque"), mux.get_input_port(2))
    else:
        zero = zero or put("no_friction", ConstantVectorSource([0.0]))
        builder.Connect(zero.get_output_port(), mux.get_input_port(2))
    builder.Connect(torque_out, mux.get_input_port(0))
    d = params.disturbance
    amplitude = d.force_ripple + d.load_ripple * abs(load.fx)
    if amplitude > 0.0:
        # the two-mass model's force ripple (model.disturbances.LoadRipple), on the table along x
        ripple = put("load_ripple", LoadRipple(amplitude, d.ripple_frequency, d.ripple_phase))
        builder.Connect(ripple.get_output_port(0), mux.get_input_port(3))
    else:
        zero = zero or put("no_friction", ConstantVectorSource([0.0]))
        builder.Connect(zero.get_output_port(), mux.get_input_port(3))
    ports = {"applied": mux.get_output_port()}
    if open_loop:
        ports["torque_command_in"] = limit.get_input_port()
        return ports

    c = builder.Connect
    c(s["reference"].get_output_port(0), s["controller"].GetInputPort("reference"))
    c(s["encoder"].GetOutputPort("motor_measured"), s["controller"].GetInputPort("motor_measured"))
    c(s["scale"].GetOutputPort("table_position_measured"), s["controller"].GetInputPort("table_position_measured"))
    c(s["controller"].GetOutputPort("torque_command"), limit.get_input_port())
    c(coords["motor"], s["encoder"].GetInputPort("motor_state"))
    c(coords["table"], s["scale"].GetInputPort("table_state"))
    ports.update({
        ("reference", "reference"): s["reference"].get_output_port(0),
        ("table", "friction_force"): (s["guide_friction"].GetOutputPort("friction_force")
                                      if "guide_friction" in s else zero.get_output_port()),
        ("motor", "motor_torque"): torque_out,
        ("controller", "torque_command"): s["controller"].GetOutputPort("torque_command"),
        ("controller", "controller_signals"): s["controller"].GetOutputPort("controller_signals"),
        ("encoder", "motor_measured"): s["encoder"].GetOutputPort("motor_measured"),
        ("scale", "table_position_measured"): s["scale"].GetOutputPort("table_position_measured"),
    })
    if "nut_friction" in s:
        ports[("nut_friction", "friction_force")] = s["nut_friction"].GetOutputPort("friction_force")
    return ports


@dataclass
class _Controls:
    """The loop's systems alone, in the form :func:`drakecreep.sim.compiled.compile_diagram` takes."""

    diagram: object
    signals: tuple

    @property
    def signal_names(self):
        return [name for name, _, _ in self.signals]


#: name of the placeholder source of the plant coordinates in the loop's own diagram
_COORDINATES = "plant_coordinates"


def _compiled_controls(builder, add, select, rows, setup, compiler):
    """The loop's systems compiled by ``compiler`` (:func:`drakecreep.sim.compiled.compile_diagram`), wired to the plant.

    The same systems as the leaf path (:func:`_add_controls`) are built into a diagram of their own whose
    plant coordinates come from a ``ConstantVectorSource`` placeholder; that diagram is compiled with the
    placeholder as its input. In ``builder``: plant state -> ``MatrixGain`` (the six coordinates) ->
    compiled loop -> ``MatrixGain`` selections of the applied inputs and of each recorded signal port.

    Returns ``(compiled, applied port, {(system, port): output port})``.
    """
    inner = DiagramBuilder()
    source = inner.AddSystem(ConstantVectorSource(np.zeros(6)))
    source.set_name(_COORDINATES)
    split = {}
    for k, name in enumerate(("motor", "table", "nut_motion")):
        gain = np.zeros((2, 6))
        gain[0, 2 * k], gain[1, 2 * k + 1] = 1.0, 1.0
        split[name] = inner.AddSystem(MatrixGain(gain))
        split[name].set_name(f"{name}_coordinates")
        inner.Connect(source.get_output_port(), split[name].get_input_port())
    local = {}

    def add_inner(name, system, into):
        system.set_name(name)
        local[name] = into.AddSystem(system)
        return local[name]

    coords = {"motor": split["motor"].get_output_port(), "table": split["table"].get_output_port(),
              "nut_motion": lambda: split["nut_motion"].get_output_port()}
    ports = _add_controls(inner, add_inner, coords, **setup)
    ports[("applied", "inputs")] = ports.pop("applied")
    signals, sizes = [], {}
    for (system, port), out in ports.items():
        inner.ExportOutput(out, f"{system}.{port}")
        sizes[(system, port)] = out.size()
        signals.extend((f"{system}.{port}[{i}]", (system, port, i), "") for i in range(out.size()))
    controls = _Controls(diagram=inner.Build(), signals=tuple(signals))
    compiled = compiler(controls, inputs=(_COORDINATES,))
    if "current_loop" in local:
        # the current loop starts holding the equilibrium torque (set in a context, not a default)
        ctx = controls.diagram.CreateDefaultContext()
        lag = local["current_loop"]
        lag.set_initial_output_value(controls.diagram.GetMutableSubsystemContext(lag, ctx), [setup["torque0"]])
        compiled.equations.xc0 = ctx.get_continuous_state_vector().CopyToVector()

    loop = add("controls", compiled.diagram)
    coordinates = select(_COORDINATES, rows["motor"] + rows["table"] + rows["nut_motion"])
    builder.Connect(coordinates.get_output_port(), loop.get_input_port(0))
    width = loop.get_output_port(0).size()
    out, start = {}, 0
    for key, n in sizes.items():
        gain = np.zeros((n, width))
        gain[:, start:start + n] = np.eye(n)
        pick = add(f"{key[0]}.{key[1]}", MatrixGain(gain))
        builder.Connect(loop.get_output_port(0), pick.get_input_port())
        out[key] = pick.get_output_port()
        start += n
    applied = out.pop(("applied", "inputs"))
    return compiled, applied, out
