"""The feed-drive diagram: parameters + scenario -> wired Drake systems with named ports.

::

    FeedReference --reference--> CascadeController --torque_command--> Motor --motor_state--> ScrewDrive
          ^                         ^          ^                          ^                     |  |
          |                 motor_measured  table_position_measured   load_torque <-------------+  |
          |                         |          |                                                   |
          |                   MotorEncoder  LinearScale <--table_state-- NutTable <--axial_force--+

The initial state is a static equilibrium at rest under the load case: the screw is stretched by
``Fx / K``, the motor holds ``Fx Ph / 2 pi`` and the controller's integrator already carries ``Fx``,
so a run starts without a transient that is not the feed's own.
"""

import math
from dataclasses import dataclass, field

from pydrake.systems.framework import DiagramBuilder

from drakecreep.errors import InputError
from drakecreep.model.compensators import add_compensation
from drakecreep.model.controller import CascadeController, force_limit
from drakecreep.model.disturbances import add_disturbances, cogging_force
from drakecreep.model.motor import Motor, commanded_torque
from drakecreep.model.nut_friction import add_nut_friction
from drakecreep.model.reference import FeedReference
from drakecreep.model.screw import ScrewDrive, axial_stiffness, chain_stretch, screw_inertia
from drakecreep.model.sensors import LinearScale, MotorEncoder, encoder_resolution, quantize
from drakecreep.model.nut_table import NutTable

__all__ = ["FeedDrive", "build_diagram", "build_plant", "SIGNALS", "initial_conditions"]

#: recorded signals: name, (system, output port, index), unit
SIGNALS = (
    ("x_ref", ("reference", "reference", 0), "m"),
    ("v_ref", ("reference", "reference", 1), "m/s"),
    ("motor_angle", ("motor", "motor_state", 0), "rad"),
    ("motor_speed", ("motor", "motor_state", 1), "rad/s"),
    ("table_position", ("table", "table_state", 0), "m"),
    ("table_speed", ("table", "table_state", 1), "m/s"),
    ("spring_force", ("screw", "axial_force", 0), "N"),
    ("friction_force", ("table", "friction_force", 0), "N"),
    ("motor_torque", ("motor", "motor_torque", 0), "N m"),
    ("torque_command", ("controller", "torque_command", 0), "N m"),
    ("velocity_command", ("controller", "controller_signals", 0), "m/s"),
    ("force_command", ("controller", "controller_signals", 1), "N"),
    ("integrator", ("controller", "controller_signals", 2), "N"),
    ("encoder_angle", ("encoder", "motor_measured", 0), "rad"),
    ("scale_position", ("scale", "table_position_measured", 0), "m"),
)


@dataclass
class FeedDrive:
    """A built feed-drive diagram and what a caller needs to use it.

    Attributes
    ----------
    diagram : pydrake.systems.framework.Diagram
        The wired systems; output ports are exported under the names ``<system>.<port>``.
    systems : dict
        The subsystems by role: reference, controller, motor, screw, table, encoder, scale.
    params, scenario
        What it was built from.
    """

    diagram: object
    systems: dict
    params: object
    scenario: object
    signals: tuple = field(default=SIGNALS)

    @property
    def signal_names(self):
        """Names of the recorded signals, in order."""
        return [s[0] for s in self.signals]

    def signal_units(self):
        """``{name: unit}`` of the recorded signals."""
        return {s[0]: s[2] for s in self.signals}


def initial_conditions(params, scenario):
    """Equilibrium at rest under the scenario's load case.

    Returns
    -------
    dict
        ``theta0`` (rad), ``force0`` (N, screw force = axial load), ``torque0`` (N m, the motor torque that holds
        it: ``force0`` plus the cogging's load at ``theta0``, :func:`~drakecreep.model.disturbances.cogging_force`,
        through the lead), ``command0`` (N, the force command that makes the drive apply ``torque0``: the same force
        unless the drive saturates, :func:`~drakecreep.model.motor.commanded_torque`), ``x_ref0`` (m, where the
        position feedback reads at rest), ``theta_counted0`` (rad).
    """
    load = params.load_case(scenario.load_case)
    ratio = params.screw.lead / (2.0 * math.pi)
    force0 = load.fx
    stretch = chain_stretch(force0, axial_stiffness(params.screw, params.nut, 0.0), params.nut.backlash)
    theta0 = stretch / ratio
    theta_counted = quantize(theta0, encoder_resolution(params.sensors.encoder_counts_per_rev))
    x_ref0 = theta_counted * ratio if params.controller.position_feedback == "motor" else 0.0
    held = force0
    if params.disturbance.has_cogging:
        held = force0 + float(cogging_force(params.disturbance, theta0 * ratio))
    command0 = held if params.motor.saturation_torque == 0.0 else commanded_torque(params.motor, held * ratio) / ratio
    if not math.isfinite(command0):
        raise InputError("motor.saturation_torque", params.motor.saturation_torque,
                         f"above the {abs(held * ratio):.4g} N m that holds the load case at rest")
    return dict(theta0=theta0, force0=force0, torque0=held * ratio, command0=command0, x_ref0=x_ref0,
                theta_counted0=theta_counted)


def build_diagram(params, scenario, *, continuous=None, ideal_sensors=False, drive=None, reference=None,
                  external_force=None):
    """Wire the feed drive for ``scenario`` from ``params``.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    scenario : drakecreep.scenario.Scenario
    continuous : bool, optional
        Force the continuous controller (``True``) or the sampled one (``False``); default from
        ``params.controller.sampled``.
    ideal_sensors : bool
        Unquantized encoder and scale (for linearization).
    drive : {"cascade", "constant_speed"}, optional
        ``"cascade"``: controller + motor (the machine). ``"constant_speed"``: no controller; the motor
        side turns at exactly the feed speed (:class:`~drakecreep.model.drive_source.ConstantSpeedDrive`, the
        paper's Fig. 2); the controller's signals are then not recorded. Default: ``scenario.drive`` if
        the scenario has one (:class:`~drakecreep.model.drive_source.DriveScenario`), else ``"cascade"``.
    reference : pydrake System, optional
        A system with one 2-vector output ``[x_ref (m), v_ref (m/s)]`` used instead of the ramp
        :class:`~drakecreep.model.reference.FeedReference` (e.g. a ``TrajectorySource`` of a measured
        reference, :mod:`drakecreep.gap.drake_replay`).
    external_force : pydrake System, optional
        A system with one 1-vector output, a force (N, +x) added to the push on the table.

    Returns
    -------
    FeedDrive
    """
    import dataclasses

    from drakecreep.model.drive_source import DRIVES, ConstantSpeedDrive, motor_speed_for
    from drakecreep.params import check_params
    from drakecreep.scenario import check_scenario

    check_params(params)
    check_scenario(scenario)
    drive = drive or getattr(scenario, "drive", "cascade")
    if drive not in DRIVES:
        raise InputError("drive", drive, "one of " + ", ".join(DRIVES))
    gains = params.controller
    if continuous is not None:
        gains = dataclasses.replace(gains, sampled=not continuous)
    load = params.load_case(scenario.load_case)
    ic = initial_conditions(params, scenario)

    builder = DiagramBuilder()
    motor_x0 = [ic["theta0"], 0.0] + (
        [ic["torque0"]] if params.motor.current_loop_time_constant > 0 else []
    )
    s = {}
    s["reference"] = (FeedReference(scenario.feed, params.simulation.acceleration_time, ic["x_ref0"])
                      if reference is None else reference)
    s["controller"] = CascadeController(
        gains, params.screw.lead, force_limit(params), initial_force=ic["command0"], initial_angle=ic["theta_counted0"]
    )
    s["motor"] = Motor(params.motor, load_inertia=screw_inertia(params.screw), initial_state=motor_x0)
    if drive == "constant_speed":
        del s["controller"]
        s["motor"] = ConstantSpeedDrive(motor_speed_for(scenario.feed, params.screw.lead), ic["theta0"])
    s["screw"] = ScrewDrive(params.screw, params.nut)
    s["table"] = NutTable(params, load)
    counts = 0 if ideal_sensors else params.sensors.encoder_counts_per_rev
    s["encoder"] = MotorEncoder(counts)
    sensors = params.sensors
    s["scale"] = (LinearScale(0.0) if ideal_sensors else
                  LinearScale(sensors.scale_resolution, sensors.scale_interpolation_error, sensors.scale_signal_period))
    for name, system in s.items():
        system.set_name(name)
        builder.AddSystem(system)

    # optional disturbances and friction compensation (drakecreep.model.disturbances, drakecreep.studies.compensation);
    # both off by default, and then these are the plain input ports and the diagram is unchanged
    ports = dict(
        torque=s["motor"].GetInputPort("torque_command") if "controller" in s else None,
        load_torque=s["motor"].GetInputPort("load_torque"),
        nut_motion=s["screw"].GetInputPort("motor_state"), axial_force=s["table"].GetInputPort("axial_force"),
    )
    ports = add_disturbances(builder, s, params, scenario, ports, angle0=ic["theta0"])
    if drive != "constant_speed":
        ports = add_nut_friction(builder, s, params, scenario, ports)
    if "controller" in s:
        ports = add_compensation(builder, s, params, scenario, ports, angle0=ic["theta_counted0"],
                                 torque0=ic["command0"] * params.screw.lead / (2 * math.pi))
    if external_force is not None:
        from pydrake.systems.primitives import Adder

        s["external_force"] = builder.AddSystem(external_force)
        s["external_force"].set_name("external_force")
        s["external_push_sum"] = push = builder.AddSystem(Adder(2, 1))
        push.set_name("external_push_sum")
        builder.Connect(external_force.get_output_port(0), push.get_input_port(1))
        builder.Connect(push.get_output_port(0), ports["axial_force"])
        ports["axial_force"] = push.get_input_port(0)

    c = builder.Connect
    if "controller" in s:
        c(s["reference"].get_output_port(0), s["controller"].GetInputPort("reference"))
        c(s["encoder"].GetOutputPort("motor_measured"), s["controller"].GetInputPort("motor_measured"))
        c(s["scale"].GetOutputPort("table_position_measured"), s["controller"].GetInputPort("table_position_measured"))
        c(s["controller"].GetOutputPort("torque_command"), ports["torque"])
    c(s["screw"].GetOutputPort("load_torque"), ports["load_torque"])
    c(s["motor"].GetOutputPort("motor_state"), ports["nut_motion"])
    c(s["table"].GetOutputPort("table_state"), s["screw"].GetInputPort("table_state"))
    c(s["screw"].GetOutputPort("axial_force"), ports["axial_force"])
    c(s["motor"].GetOutputPort("motor_state"), s["encoder"].GetInputPort("motor_state"))
    c(s["table"].GetOutputPort("table_state"), s["scale"].GetInputPort("table_state"))

    exported = set()
    signals = tuple(sig for sig in SIGNALS if sig[1][0] in s)
    for _, (system, port, _), _ in signals:
        if (system, port) not in exported:
            out = s[system].get_output_port(0) if system == "reference" else s[system].GetOutputPort(port)
            builder.ExportOutput(out, f"{system}.{port}")
            exported.add((system, port))
    if s["table"].law.num_states:
        builder.ExportOutput(s["table"].GetOutputPort("friction_state"), "table.friction_state")
    nut_signals = ()
    if "nut_friction" in s:
        builder.ExportOutput(s["nut_friction"].GetOutputPort("friction_force"), "nut_friction.friction_force")
        nut_signals = (("nut_friction_force", ("nut_friction", "friction_force", 0), "N"),)
    compensation_signals = ()
    if "compensator" in s:
        builder.ExportOutput(s["compensator"].GetOutputPort("torque"), "compensator.torque")
        compensation_signals = (("compensation_torque", ("compensator", "torque", 0), "N m"),)
    diagram = builder.Build()
    diagram.set_name("feed_drive")
    signals = signals + tuple(
        (f"friction_state_{i}", ("table", "friction_state", i), "-") for i in range(s["table"].law.num_states)
    )
    signals = signals + nut_signals + compensation_signals
    return FeedDrive(diagram=diagram, systems=s, params=params, scenario=scenario, signals=signals)


def build_plant(params, load_case=0):
    """The mechanics alone: motor, screw and table, with the motor torque command as the input.

    Input port ``torque_command`` (N m); output ports ``motor_state``, ``table_state``,
    ``axial_force``, ``friction_force``. State order: motor ``[theta, omega(, tau)]``, table
    ``[x, v, z...]``, all zero by default (no preload of the screw).

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    load_case : int
        Load case number (0 = unloaded).
    """
    builder = DiagramBuilder()
    motor = builder.AddSystem(Motor(params.motor, load_inertia=screw_inertia(params.screw)))
    motor.set_name("motor")
    screw = builder.AddSystem(ScrewDrive(params.screw, params.nut))
    screw.set_name("screw")
    table = builder.AddSystem(NutTable(params, params.load_case(load_case)))
    table.set_name("table")
    builder.Connect(screw.GetOutputPort("load_torque"), motor.GetInputPort("load_torque"))
    builder.Connect(motor.GetOutputPort("motor_state"), screw.GetInputPort("motor_state"))
    builder.Connect(table.GetOutputPort("table_state"), screw.GetInputPort("table_state"))
    builder.Connect(screw.GetOutputPort("axial_force"), table.GetInputPort("axial_force"))
    builder.ExportInput(motor.GetInputPort("torque_command"), "torque_command")
    builder.ExportOutput(motor.GetOutputPort("motor_state"), "motor_state")
    builder.ExportOutput(table.GetOutputPort("table_state"), "table_state")
    builder.ExportOutput(screw.GetOutputPort("axial_force"), "axial_force")
    builder.ExportOutput(table.GetOutputPort("friction_force"), "friction_force")
    diagram = builder.Build()
    diagram.set_name("feed_drive_plant")
    return diagram
