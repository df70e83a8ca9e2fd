"""Linearize the feed drive at a sliding operating point into python-control ``StateSpace`` models.

A drive feeding at constant speed is no equilibrium (the positions ramp), so the Drake diagram is
linearized with :func:`pydrake.systems.primitives.FirstOrderTaylorApproximation` at a point of the
steady sliding trajectory; the drift ``f(x0, u0)`` (the ramp itself) is dropped and the ``(A, B, C, D)``
that remain are the dynamics of the deviations from the trajectory (error coordinates). The Jacobians
come from AutoDiff on the very same ``TemplateSystem`` sources the simulation runs: nothing is written
twice.

Operating point (:func:`operating_point`, constructed analytically, checked against the diagram's
derivatives and against a simulation in the tests): table at the feed speed ``v``, motor at
``v / (Ph / 2 pi)``; friction at its steady-state value ``F(v)`` (LuGre: bristle load ``w = g(v)/Fc``);
the screw stretched to carry ``Fx + F(v)`` (with a lost motion ``nut.backlash``, its gap closed: the small-signal
model sees the chain's stiffness, not the gap); the motor torque balancing the screw and its own drag;
the velocity-loop integrator holding that force; the position error ``(1 - ff) v / kp``.

The friction law enters through its slope at the operating speed: for the static laws (Coulomb,
Stribeck) that is the paper's ``C1 = dF/dv`` directly; LuGre adds the bristle state, whose
low-frequency slope is again ``C1`` and whose high-frequency slope is ``sigma1 + Fv``.

Models (all with named signals, SI units):

* :func:`linearize_plant` -- ``build_plant``: input ``torque_command``; outputs motor angle/speed, table
  position/speed, spring and friction force.
* :func:`linearize_controller` -- the continuous ``CascadeController``: inputs ``x_ref, v_ref,
  encoder_angle, motor_speed_measured, scale_position``; output ``torque_command``.
* :func:`linearize_closed_loop` -- the whole ``build_diagram(..., continuous=True, ideal_sensors=True)``
  (no inputs; outputs = the recorded signals); its eigenvalues are the closed-loop poles.
* :func:`linearize_mechanism` -- screw + table with the motor motion as an input: the paper's
  mechanism (Fig. 2, driving part prescribed), whose poles obey ``M s^2 + (C + C1) s + K``.
* :func:`two_mass_model` -- the analytic two-mass transfer functions, for the cross-check.
"""

import dataclasses
import math
from dataclasses import dataclass

import control
import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import Demultiplexer, FirstOrderTaylorApproximation, Multiplexer

from drakecreep.model.controller import CascadeController, force_limit
from drakecreep.paper.creep import friction_slope
from drakecreep.model.diagram import build_diagram, build_plant
from drakecreep.errors import InputError
from drakecreep.model.friction import make_friction_law
from drakecreep.model.motor import motor_inertia
from drakecreep.model.screw import ScrewDrive, axial_damping, axial_stiffness, chain_stretch, screw_inertia
from drakecreep.model.nut_table import NutTable, moving_mass
from drakecreep.model.steady import nut_on_table, steady_sliding

__all__ = [
    "OperatingPoint",
    "operating_point",
    "linearize_plant",
    "linearize_controller",
    "linearize_closed_loop",
    "linearize_mechanism",
    "closed_loop_from_parts",
    "two_mass_model",
    "finite_difference_jacobian",
    "closed_loop_derivatives",
    "PLANT_OUTPUTS",
    "CONTROLLER_INPUTS",
]

#: outputs of :func:`linearize_plant`, in order
PLANT_OUTPUTS = ("motor_angle", "motor_speed", "table_position", "table_speed", "spring_force", "friction_force")
#: inputs of :func:`linearize_controller`, in order
CONTROLLER_INPUTS = ("x_ref", "v_ref", "encoder_angle", "motor_speed_measured", "scale_position")


@dataclass(frozen=True)
class OperatingPoint:
    """A point of steady sliding at constant feed (SI units).

    Attributes
    ----------
    time : float
        Time on the reference at which the point is taken (after the acceleration ramp).
    feed : float
        Table speed ``v`` (m/s).
    x_ref : float
        Reference position at ``time`` (m).
    controller, motor, table : tuple of float
        Continuous states of each subsystem: ``[integrator]``, ``[theta, omega(, tau)]``,
        ``[x, v(, w)]``.
    torque : float
        Motor torque (N m) = torque command.
    spring_force, friction_force : float
        Screw force on the table and friction force (N).
    stiffness, damping, mass : float
        Axial stiffness ``K`` (N/m) and damping ``C`` (N s/m) of the screw chain at the table
        position, moving mass ``M`` (kg).
    friction_slope : float
        ``C1 = dF/dv`` of the steady-state friction curve at ``v`` (N s/m).
    Fc, Fs : float
        Coulomb and breakaway friction levels of the load case (N).
    """

    time: float
    feed: float
    x_ref: float
    controller: tuple
    motor: tuple
    table: tuple
    torque: float
    spring_force: float
    friction_force: float
    stiffness: float
    damping: float
    mass: float
    friction_slope: float
    Fc: float
    Fs: float

    @property
    def zeta(self):
        """The paper's damping ratio ``(C + C1) / (2 sqrt(K M))`` at this point."""
        return (self.damping + self.friction_slope) / (2.0 * math.sqrt(self.stiffness * self.mass))


def operating_point(params, scenario):
    """Steady sliding state of ``build_diagram(params, scenario, continuous=True, ideal_sensors=True)``.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    scenario : drakecreep.scenario.Scenario
        Its feed is the operating speed; its load case sets ``Fx`` and the friction levels.

    Returns
    -------
    OperatingPoint

    Raises
    ------
    InputError
        When no steady sliding exists: zero position gain without full feedforward, or a force
        beyond the drive's limit; for the GMS law (its elements switch between stick and slip: no
        smooth steady state to linearize about).
    """
    if params.friction.law == "gms":
        raise InputError("friction.law", "gms", "coulomb, stribeck or lugre (linearization needs a smooth law)")
    for k, a in enumerate(params.friction.position_map):
        if a != 0.0:  # its level moves with the table: sliding at a constant force is no steady state of it
            raise InputError(f"friction.position_map_{k}", a,
                             "0 for the linear analyses (a friction that changes along the travel has no steady "
                             "sliding to linearize about; simulate and diagnose take it)")
    if params.friction.time_drift != 0.0:  # its level moves with time: no steady sliding either
        raise InputError("friction.time_drift", params.friction.time_drift,
                         "0 for the linear analyses (a friction that drifts over time has no steady sliding to "
                         "linearize about; simulate and diagnose take it)")
    params = nut_on_table(params)
    g = params.controller
    v = scenario.feed
    ratio = params.screw.lead / (2.0 * math.pi)
    (law, fc, fs), friction, spring, torque, force_cmd = steady_sliding(params, scenario)
    omega = v / ratio
    if abs(force_cmd) >= force_limit(params):
        raise InputError("feed", v, f"a feed whose force {force_cmd:.4g} N is below the drive limit {force_limit(params):.4g} N")
    if g.position_gain == 0.0 and g.velocity_feedforward != 1.0:
        raise InputError("controller.position_gain", 0.0, "> 0 (or velocity_feedforward = 1) for steady sliding")
    lag = (1.0 - g.velocity_feedforward) * v / g.position_gain if g.position_gain > 0 else 0.0

    ta = params.simulation.acceleration_time
    t0 = 2.0 * ta if ta > 0 else 0.0
    from drakecreep.model.diagram import initial_conditions

    x_ref = initial_conditions(params, scenario)["x_ref0"] + v * (t0 - 0.5 * ta)
    # the position the feedback reads lags the reference by `lag`; the spring stretch depends on the
    # nut position (stiffness varies along the screw): fixed-point iteration, converges in a few steps
    measured = x_ref - lag
    x = measured
    for _ in range(50):
        k = float(axial_stiffness(params.screw, params.nut, x))
        stretch = chain_stretch(spring, k, params.nut.backlash)
        theta = (measured / ratio) if g.position_feedback == "motor" else (x + stretch) / ratio
        x_new = measured if g.position_feedback == "table" else theta * ratio - stretch
        if abs(x_new - x) < 1e-15:
            break
        x = x_new
    k = float(axial_stiffness(params.screw, params.nut, x))
    c = float(axial_damping(params.screw, params.nut, x))
    stretch = chain_stretch(spring, k, params.nut.backlash)  # the chain bears the sliding force: its gap is closed
    theta = measured / ratio if g.position_feedback == "motor" else (x + stretch) / ratio
    motor = (theta, omega) + ((torque,) if params.motor.current_loop_time_constant > 0 else ())
    table = (x, v) + ((float(law.sliding_level(v, fc, fs)) * math.copysign(1.0, v) / fc,) if law.num_states else ())
    table += (0.0, 0.0) if params.table.mode_mass_share > 0.0 else ()  # the structural mode's deflection: none
    # central difference with a small relative step: truncation ~1e-10, round-off ~1e-10 of C1 here
    c1 = float(friction_slope(lambda s: law.steady_state_force(s, fc, fs), v, step=1e-5 * abs(v)))
    return OperatingPoint(
        time=t0, feed=v, x_ref=x_ref, controller=(force_cmd,), motor=motor, table=table, torque=torque,
        spring_force=spring, friction_force=friction, stiffness=k, damping=c, mass=moving_mass(params),
        friction_slope=c1, Fc=fc, Fs=fs,
    )


# --------------------------------------------------------------------------- Drake wrapping

def _wrap(system, in_ports, out_ports):
    """``system`` inside a diagram with one vector input (demultiplexed) and one vector output (muxed)."""
    b = DiagramBuilder()
    sub = b.AddSystem(system)
    if in_ports:
        demux = b.AddSystem(Demultiplexer([p.size() for p in in_ports]))
        for i, p in enumerate(in_ports):
            b.Connect(demux.get_output_port(i), p)
        b.ExportInput(demux.get_input_port(0), "u")
    mux = b.AddSystem(Multiplexer([p.size() for p in out_ports]))
    for i, p in enumerate(out_ports):
        b.Connect(p, mux.get_input_port(i))
    b.ExportOutput(mux.get_output_port(0), "y")
    return b.Build(), sub


def _taylor(wrapper, context, u0=None):
    if u0 is not None:
        wrapper.get_input_port(0).FixValue(context, np.asarray(u0, dtype=float))
    lin = FirstOrderTaylorApproximation(wrapper, context)
    n = lin.num_continuous_states()
    B = lin.B() if u0 is not None else np.zeros((n, 0))
    D = lin.D() if u0 is not None else np.zeros((lin.C().shape[0], 0))
    return lin.A(), B, lin.C(), D, lin.f0()


def _state_names(params, with_controller=True):
    law = make_friction_law(params.friction)
    names = ["controller.integrator"] if with_controller else []
    names += ["motor.theta", "motor.omega"] + (["motor.tau"] if params.motor.current_loop_time_constant > 0 else [])
    return names + _table_state_names(params, law)


def _table_state_names(params, law):
    """The table's states: position, speed, the friction law's (``w``) and the structural mode's."""
    return (["table.x", "table.v"] + (["table.w"] if law.num_states else [])
            + (["table.mode_deflection", "table.mode_rate"] if params.table.mode_mass_share > 0.0 else []))


def _diagram_state_names(feed_drive):
    """State names in the diagram's order (subsystems in the order the diagram holds them)."""
    table = _table_state_names(feed_drive.params, make_friction_law(feed_drive.params.friction))
    known = {"controller": ["integrator"], "motor": ["theta", "omega", "tau"], "table": [n[6:] for n in table]}
    context = feed_drive.diagram.CreateDefaultContext()
    names = []
    for system in feed_drive.diagram.GetSystems():
        n = feed_drive.diagram.GetSubsystemContext(system, context).num_continuous_states()
        labels = known.get(system.get_name(), [])
        names += [f"{system.get_name()}.{labels[i] if i < len(labels) else 'x%d' % i}" for i in range(n)]
    return names


def linearize_plant(params, scenario, op=None):
    """The mechanics (``build_plant``) linearized at steady sliding.

    Parameters
    ----------
    params, scenario
        As for :func:`operating_point`.
    op : OperatingPoint, optional
        Default ``operating_point(params, scenario)``.

    Returns
    -------
    control.StateSpace
        Input ``torque_command`` (N m); outputs :data:`PLANT_OUTPUTS` (rad, rad/s, m, m/s, N, N);
        states ``motor.theta, motor.omega(, motor.tau), table.x, table.v(, table.w)``.
    """
    params = nut_on_table(params)
    op = op or operating_point(params, scenario)
    plant = build_plant(params, scenario.load_case)
    ports = [plant.GetOutputPort(n) for n in ("motor_state", "table_state", "axial_force", "friction_force")]
    wrapper, sub = _wrap(plant, [plant.GetInputPort("torque_command")], ports)
    context = wrapper.CreateDefaultContext()
    context.SetTime(op.time)
    sub.GetMyMutableContextFromRoot(context).SetContinuousState(np.r_[op.motor, op.table])
    A, B, C, D, _ = _taylor(wrapper, context, [op.torque])
    return control.ss(A, B, C, D, inputs=["torque_command"], outputs=list(PLANT_OUTPUTS),
                      states=_state_names(params, with_controller=False), name="plant")


def _continuous_gains(params):
    return dataclasses.replace(params.controller, sampled=False)


def linearize_controller(params, scenario, op=None):
    """The continuous PI cascade (``CascadeController``) linearized at steady sliding.

    Returns
    -------
    control.StateSpace
        Inputs :data:`CONTROLLER_INPUTS` (m, m/s, rad, rad/s, m); output ``torque_command`` (N m);
        state ``controller.integrator`` (N). Unsaturated, so the anti-windup term has no slope.
    """
    params = nut_on_table(params)
    op = op or operating_point(params, scenario)
    ctrl = CascadeController(_continuous_gains(params), params.screw.lead, force_limit(params),
                             initial_force=op.controller[0])
    ins = [ctrl.GetInputPort(n) for n in ("reference", "motor_measured", "table_position_measured")]
    wrapper, sub = _wrap(ctrl, ins, [ctrl.GetOutputPort("torque_command")])
    context = wrapper.CreateDefaultContext()
    context.SetTime(op.time)
    sub.GetMyMutableContextFromRoot(context).SetContinuousState(np.asarray(op.controller))
    u0 = [op.x_ref, op.feed, op.motor[0], op.motor[1], op.table[0]]
    A, B, C, D, _ = _taylor(wrapper, context, u0)
    return control.ss(A, B, C, D, inputs=list(CONTROLLER_INPUTS), outputs=["torque_command"],
                      states=["controller.integrator"], name="controller")


def _set_diagram_state(feed_drive, context, op):
    s = feed_drive.systems
    s["controller"].GetMyMutableContextFromRoot(context).SetContinuousState(np.asarray(op.controller))
    s["motor"].GetMyMutableContextFromRoot(context).SetContinuousState(np.asarray(op.motor))
    s["table"].GetMyMutableContextFromRoot(context).SetContinuousState(np.asarray(op.table))


def closed_loop_derivatives(params, scenario, op=None, state=None):
    """Time derivatives of the continuous closed-loop diagram at ``op`` (or at ``state``) -- float path.

    Returns
    -------
    (ndarray, ndarray)
        The state vector used and its time derivative, in the diagram's state order.
    """
    params = nut_on_table(params)
    op = op or operating_point(params, scenario)
    fd = build_diagram(params, scenario, continuous=True, ideal_sensors=True)
    context = fd.diagram.CreateDefaultContext()
    context.SetTime(op.time)
    _set_diagram_state(fd, context, op)
    if state is not None:
        context.SetContinuousState(np.asarray(state, dtype=float))
    x = context.get_continuous_state_vector().CopyToVector()
    return x, fd.diagram.EvalTimeDerivatives(context).CopyToVector()


def linearize_closed_loop(params, scenario, op=None):
    """The whole continuous-controller diagram linearized at steady sliding (AutoDiff).

    Returns
    -------
    control.StateSpace
        No inputs (the reference is inside the diagram); outputs the diagram's recorded signals
        (:data:`drakecreep.model.diagram.SIGNALS` names); its poles are the closed-loop poles.
    """
    params = nut_on_table(params)
    op = op or operating_point(params, scenario)
    fd = build_diagram(params, scenario, continuous=True, ideal_sensors=True)
    d = fd.diagram
    keys = []
    for _, (system, port, _), _ in fd.signals:
        if f"{system}.{port}" not in keys:
            keys.append(f"{system}.{port}")
    ports = [d.GetOutputPort(k) for k in keys]
    state_names = _diagram_state_names(fd)
    wrapper, sub = _wrap(d, [], ports)
    context = wrapper.CreateDefaultContext()
    context.SetTime(op.time)
    _set_diagram_state(fd, context, op)
    A, B, C, D, _ = _taylor(wrapper, context)
    # reorder the muxed outputs into signal order
    offsets, start = {}, 0
    for k, p in zip(keys, ports):
        offsets[k] = start
        start += p.size()
    rows = [offsets[f"{sys_}.{port}"] + i for _, (sys_, port, i), _ in fd.signals]
    return control.ss(A, B, C[rows], D[rows], outputs=list(fd.signal_names),
                      states=state_names, name="closed_loop")


def closed_loop_from_parts(plant, controller, position_feedback="motor"):
    """Plant and controller linearizations wired as the diagram wires them (python-control ``interconnect``).

    Returns
    -------
    control.StateSpace
        Inputs ``x_ref, v_ref``; outputs the plant outputs and ``torque_command``.
    """
    sensors = control.ss([], [], [], np.eye(3), inputs=["motor_angle", "motor_speed", "table_position"],
                         outputs=["encoder_angle", "motor_speed_measured", "scale_position"], name="sensors")
    return control.interconnect(
        [plant, controller, sensors], inplist=["x_ref", "v_ref"],
        outlist=list(PLANT_OUTPUTS) + ["torque_command"], name="closed_loop_parts",
    )


def linearize_mechanism(params, scenario, op=None):
    """The paper's mechanism (Fig. 2): screw + table with the motor motion prescribed.

    The same ``ScrewDrive`` and ``NutTable`` systems, the motor state ``[theta, omega]`` as the
    input (the "driving part A" of the paper moving at constant speed).

    Returns
    -------
    control.StateSpace
        Inputs ``motor_angle, motor_speed``; outputs ``table_position, table_speed, spring_force,
        friction_force``; for a static friction law its poles are the roots of
        ``M s^2 + (C + C1) s + K`` (paper eq. 2).
    """
    params = nut_on_table(params)
    op = op or operating_point(params, scenario)
    b = DiagramBuilder()
    screw = b.AddSystem(ScrewDrive(params.screw, params.nut))
    table = b.AddSystem(NutTable(params, params.load_case(scenario.load_case)))
    b.Connect(table.GetOutputPort("table_state"), screw.GetInputPort("table_state"))
    b.Connect(screw.GetOutputPort("axial_force"), table.GetInputPort("axial_force"))
    b.ExportInput(screw.GetInputPort("motor_state"), "motor_state")
    for sys_, port in ((table, "table_state"), (screw, "axial_force"), (table, "friction_force")):
        b.ExportOutput(sys_.GetOutputPort(port), port)
    mech = b.Build()
    ports = [mech.get_output_port(i) for i in range(3)]
    wrapper, sub = _wrap(mech, [mech.get_input_port(0)], ports)
    context = wrapper.CreateDefaultContext()
    context.SetTime(op.time)
    table.GetMyMutableContextFromRoot(context).SetContinuousState(np.asarray(op.table))
    A, B, C, D, _ = _taylor(wrapper, context, op.motor[:2])
    law = make_friction_law(params.friction)
    return control.ss(A, B, C, D, inputs=["motor_angle", "motor_speed"],
                      outputs=["table_position", "table_speed", "spring_force", "friction_force"],
                      states=_table_state_names(params, law), name="mechanism")


def two_mass_model(params, scenario, op=None):
    """Analytic two-mass model (hand-derived, for cross-checking the AutoDiff linearization).

    Motor side ``J_total`` with viscous drag ``b`` and the current loop ``1 / (T s + 1)``; screw spring
    ``K`` and damper ``C`` at the lead ratio ``r = Ph / 2 pi``; table mass ``M`` with the friction slope
    ``C1`` (static laws only -- LuGre adds a bristle state this model does not have). Stiffness
    variation along the screw is neglected (it makes a tiny position-dependent term).

    Returns
    -------
    control.StateSpace
        Input ``torque_command``; outputs ``motor_speed`` (rad/s) and ``table_speed`` (m/s).
    """
    params = nut_on_table(params)
    op = op or operating_point(params, scenario)
    r = params.screw.lead / (2.0 * math.pi)
    J = motor_inertia(params.motor, screw_inertia(params.screw))
    b, T = params.motor.viscous_damping, params.motor.current_loop_time_constant
    K, C, M, C1 = op.stiffness, op.damping, op.mass, op.friction_slope
    # states: theta, omega, x, v (+ tau)
    A = np.array([
        [0, 1, 0, 0],
        [-K * r * r / J, -(b + C * r * r) / J, K * r / J, C * r / J],
        [0, 0, 0, 1],
        [K * r / M, C * r / M, -K / M, -(C + C1) / M],
    ], dtype=float)
    Bm = np.array([[0], [1 / J], [0], [0]], dtype=float)
    if T > 0:
        A = np.block([[A, Bm], [np.zeros((1, 4)), -1 / T * np.ones((1, 1))]])
        Bm = np.array([[0], [0], [0], [0], [1 / T]])
    Cm = np.zeros((2, A.shape[0]))
    Cm[0, 1] = 1.0
    Cm[1, 3] = 1.0
    return control.ss(A, Bm, Cm, np.zeros((2, 1)), inputs=["torque_command"],
                      outputs=["motor_speed", "table_speed"], name="two_mass")


def finite_difference_jacobian(params, scenario, op=None, rel_step=1e-6):
    """``d xdot / d x`` of the closed-loop diagram by central differences on the float path.

    Step ``rel_step * max(|x_i|, 1e-3)`` per state (relative to the state's own size).

    Returns
    -------
    ndarray
        ``n x n``, in the diagram's state order (compare with ``linearize_closed_loop(...).A``).
    """
    params = nut_on_table(params)
    op = op or operating_point(params, scenario)
    x0, _ = closed_loop_derivatives(params, scenario, op)
    fd = build_diagram(params, scenario, continuous=True, ideal_sensors=True)
    context = fd.diagram.CreateDefaultContext()
    context.SetTime(op.time)
    n = len(x0)
    J = np.zeros((n, n))
    for i in range(n):
        h = rel_step * max(abs(x0[i]), 1e-3)
        cols = []
        for sgn in (1.0, -1.0):
            x = x0.copy()
            x[i] += sgn * h
            context.SetContinuousState(x)
            cols.append(fd.diagram.EvalTimeDerivatives(context).CopyToVector())
        J[:, i] = (cols[0] - cols[1]) / (2 * h)
    return J
