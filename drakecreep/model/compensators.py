"""Friction compensation: torque added to the cascade controller's command (Drake ``Adder``).

Every compensator is a ``TemplateSystem`` (float, AutoDiffXd, Expression) with continuous states
only, so :func:`drakecreep.sim.compiled.compile_diagram` still turns the diagram into symbolic systems
(the fast path allows one sample rate, the controller's). They run in continuous time, i.e. as a
compensation added at the current-loop rate, and read what the drive has: the reference
``[x_ref, v_ref]``, the motor encoder port ``[counted angle, motor speed]`` (its speed is the
unquantized motor speed, an ideal tachometer; the table speed is not measured in the semi-closed
loop) and, for the disturbance observer, the controller's torque command.

Their friction model is the plant's nominal law -- levels ``Fc, Fs`` of the load case
(:func:`drakecreep.model.nut_table.friction_levels`), shape from ``params.friction`` -- times the mismatch
factors of :class:`drakecreep.params.CompensationParams`.

Methods
-------
static
    Stribeck + viscous feedforward ``g(v_c) tanh(v_c / v_reg) + Fv v_c`` at the reference speed
    (``velocity_blend`` mixes in the measured motor speed; the :data:`VARIANTS` entry
    ``"static-measured"`` is the model on the measured speed alone, i.e. model-based feedback).
lugre
    LuGre model with a friction-state observer (Canudas de Wit, Olsson, Astrom, Lischinsky, IEEE TAC
    40(3), 1995): ``dz/dt = v - sigma0 |v| z / g(v) - k (v - v_ref)`` driven by the measured speed,
    ``F = sigma0 z + sigma1 dz/dt + Fv v``. The state is stored as ``w = sigma0 z / Fc`` as in
    :class:`drakecreep.model.friction.LuGreFriction`.
dob
    Disturbance observer (Ohnishi): ``d = Q(s) (tau - J_n s omega)`` with ``Q = L / (s + L)`` on the
    motor-side rigid-body inertia ``J_n`` (motor, coupling, screw and the reflected table mass);
    ``d`` is added to the command.
dither
    A sinusoidal force ``A Fc sin(2 pi f t)`` (no model of the speed at all); it breaks static
    friction by keeping the contact moving and adds its own ripple.

The study that compares them is :mod:`drakecreep.studies.compensation`.
"""

import dataclasses
import math

from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.primitives import Adder
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import exp, fabs, tanh
from drakecreep.model.disturbances import sin
from drakecreep.errors import InputError
from drakecreep.params import COMPENSATION_METHODS
from drakecreep.model.screw import screw_inertia
from drakecreep.model.nut_table import friction_levels, moving_mass

__all__ = [
    "FrictionModel",
    "compensator_model",
    "StaticCompensator",
    "StaticCompensator_",
    "LuGreCompensator",
    "LuGreCompensator_",
    "DisturbanceObserver",
    "DisturbanceObserver_",
    "DitherCompensator",
    "DitherCompensator_",
    "make_compensator",
    "add_compensation",
    "rigid_inertia",
]


@dataclasses.dataclass(frozen=True)
class FrictionModel:
    """The compensator's friction model, table side (N, m/s)."""

    fc: float
    fs: float
    stribeck_velocity: float
    exponent: float
    viscous: float
    sigma0: float
    sigma1: float
    regularization_velocity: float

    def g(self, v):
        """Stribeck curve ``Fc + (Fs - Fc) exp(-|v/vs|^delta)`` for any scalar type."""
        if self.exponent == 2.0:
            return self.fc + (self.fs - self.fc) * exp(-((v / self.stribeck_velocity) ** 2))
        return self.fc + (self.fs - self.fc) * exp(-(fabs(v / self.stribeck_velocity) ** self.exponent))


def compensator_model(params, load_case):
    """:class:`FrictionModel` of the compensator: the plant's nominal friction times the mismatch factors."""
    c = params.compensation
    f = params.friction
    fc, fs = friction_levels(params, params.load_case(load_case))
    return FrictionModel(
        fc=fc * c.coulomb_factor, fs=fs * c.static_factor,
        stribeck_velocity=f.stribeck_velocity * c.stribeck_velocity_factor, exponent=f.stribeck_exponent,
        viscous=f.viscous * c.viscous_factor, sigma0=f.bristle_stiffness * c.bristle_stiffness_factor,
        sigma1=f.bristle_damping * c.bristle_damping_factor, regularization_velocity=f.regularization_velocity,
    )


def _declare_inputs(system):
    system._u_reference = system.DeclareVectorInputPort("reference", 2)
    system._u_motor_measured = system.DeclareVectorInputPort("motor_measured", 2)
    system._u_torque_command = system.DeclareVectorInputPort("torque_command", 1)
    system._u_table_state = system.DeclareVectorInputPort("table_state", 2)


def _measured_speed(system, context):
    """Speed the compensator uses (m/s, table side): motor speed through the lead, or the table's."""
    if system.velocity_source == "table":
        return system._u_table_state.Eval(context)[1]
    return system._u_motor_measured.Eval(context)[1] * system.ratio


@TemplateSystem.define("StaticCompensator_")
def StaticCompensator_(T):
    class Impl(LeafSystem_[T]):
        """Stribeck + viscous friction feedforward.

        Input ports ``reference`` (2), ``motor_measured`` (2), ``torque_command`` (1, unused);
        output ``torque`` (1, N m).
        """

        def _construct(self, model, lead, velocity_blend=0.0, velocity_source="motor", converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.model, self.lead, self.velocity_blend = model, float(lead), float(velocity_blend)
            self.velocity_source = velocity_source
            self.ratio = self.lead / (2.0 * math.pi)
            _declare_inputs(self)
            self.DeclareVectorOutputPort("torque", 1, self._calc)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.model, other.lead, other.velocity_blend, other.velocity_source,
                            converter=converter)

        def force(self, context):
            v_ref = self._u_reference.Eval(context)[1]
            v = v_ref
            if self.velocity_blend > 0.0:
                v = (1.0 - self.velocity_blend) * v_ref + self.velocity_blend * _measured_speed(self, context)
            m = self.model
            return m.g(v) * tanh(v / m.regularization_velocity) + m.viscous * v

        def _calc(self, context, output):
            output.SetAtIndex(0, self.force(context) * self.ratio)

    return Impl


@TemplateSystem.define("LuGreCompensator_")
def LuGreCompensator_(T):
    class Impl(LeafSystem_[T]):
        """LuGre friction compensation with a friction-state observer; state ``w = sigma0 z / Fc``.

        Input ports ``reference`` (2), ``motor_measured`` (2), ``torque_command`` (1, unused);
        output ``torque`` (1, N m).
        """

        def _construct(self, model, lead, observer_gain=0.0, velocity_source="motor", converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.model, self.lead, self.observer_gain = model, float(lead), float(observer_gain)
            self.velocity_source = velocity_source
            self.ratio = self.lead / (2.0 * math.pi)
            _declare_inputs(self)
            self.DeclareContinuousState(BasicVector_[T]([0.0]))
            self.DeclareVectorOutputPort("torque", 1, self._calc)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.model, other.lead, other.observer_gain, other.velocity_source,
                            converter=converter)

        def _rates(self, context):
            m = self.model
            v_ref = self._u_reference.Eval(context)[1]
            v = _measured_speed(self, context)
            w = context.get_continuous_state_vector().GetAtIndex(0)
            zdot = v - fabs(v) * w * m.fc / m.g(v) - self.observer_gain * (v - v_ref)
            return v, w, zdot

        def DoCalcTimeDerivatives(self, context, derivatives):
            _, _, zdot = self._rates(context)
            derivatives.get_mutable_vector().SetAtIndex(0, self.model.sigma0 / self.model.fc * zdot)

        def force(self, context):
            v, w, zdot = self._rates(context)
            m = self.model
            return m.fc * w + m.sigma1 * zdot + m.viscous * v

        def _calc(self, context, output):
            output.SetAtIndex(0, self.force(context) * self.ratio)

    return Impl


@TemplateSystem.define("DisturbanceObserver_")
def DisturbanceObserver_(T):
    class Impl(LeafSystem_[T]):
        """First-order disturbance observer on the motor; state ``p`` with ``d = p - L J_n omega``.

        ``dp/dt = L (tau - p + L J_n omega)``, ``tau`` the torque sent to the motor (controller command
        plus ``d``), so that ``d = L/(s+L) (tau - J_n s omega)``. Output ``torque`` (1, N m) ``= d``.
        """

        def _construct(self, inertia, bandwidth, initial_torque=0.0, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.inertia, self.bandwidth = float(inertia), float(bandwidth)
            self.initial_torque = float(initial_torque)
            _declare_inputs(self)
            self.DeclareContinuousState(BasicVector_[T]([self.initial_torque]))
            self.DeclareVectorOutputPort(
                "torque", 1, self._calc,
                prerequisites_of_calc={self.xc_ticket(), self.input_port_ticket(self._u_motor_measured.get_index())},
            )

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.inertia, other.bandwidth, other.initial_torque, converter=converter)

        def _estimate(self, context):
            p = context.get_continuous_state_vector().GetAtIndex(0)
            omega = self._u_motor_measured.Eval(context)[1]
            return p, omega, p - self.bandwidth * self.inertia * omega

        def DoCalcTimeDerivatives(self, context, derivatives):
            p, omega, d = self._estimate(context)
            tau = self._u_torque_command.Eval(context)[0] + d
            L = self.bandwidth
            derivatives.get_mutable_vector().SetAtIndex(0, L * (tau - p + L * self.inertia * omega))

        def _calc(self, context, output):
            output.SetAtIndex(0, self._estimate(context)[2])

    return Impl


@TemplateSystem.define("DitherCompensator_")
def DitherCompensator_(T):
    class Impl(LeafSystem_[T]):
        """Sinusoidal dither force ``A sin(2 pi f t)`` through the lead; output ``torque`` (1, N m)."""

        def _construct(self, amplitude, frequency, lead, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.amplitude, self.frequency, self.lead = float(amplitude), float(frequency), float(lead)
            _declare_inputs(self)
            self.DeclareVectorOutputPort("torque", 1, self._calc, prerequisites_of_calc={self.time_ticket()})

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.amplitude, other.frequency, other.lead, converter=converter)

        def _calc(self, context, output):
            t = context.get_time()
            output.SetAtIndex(0, self.amplitude * sin(2.0 * math.pi * self.frequency * t) * self.lead / (2.0 * math.pi))

    return Impl


StaticCompensator = StaticCompensator_[None]
LuGreCompensator = LuGreCompensator_[None]
DisturbanceObserver = DisturbanceObserver_[None]
DitherCompensator = DitherCompensator_[None]


def rigid_inertia(params):
    """Motor-side rigid-body inertia (kg m^2): rotor, coupling, screw and the reflected table mass."""
    ratio = params.screw.lead / (2.0 * math.pi)
    return (params.motor.rotor_inertia + params.motor.coupling_inertia + screw_inertia(params.screw)
            + moving_mass(params) * ratio**2)


def make_compensator(params, scenario):
    """The compensator system for ``params.compensation.method`` (None for ``"none"``)."""
    c = params.compensation
    if c.method == "none":
        return None
    model = compensator_model(params, scenario.load_case)
    lead = params.screw.lead
    if c.method == "static":
        return StaticCompensator(model, lead, c.velocity_blend, c.velocity_source)
    if c.method == "lugre":
        return LuGreCompensator(model, lead, c.observer_gain, c.velocity_source)
    if c.method == "dob":
        return DisturbanceObserver(rigid_inertia(params) * c.inertia_factor, c.dob_bandwidth)
    if c.method == "dither":
        return DitherCompensator(c.dither_amplitude * model.fc, c.dither_frequency, lead)
    raise InputError("compensation.method", c.method, "one of " + ", ".join(COMPENSATION_METHODS))


def add_compensation(builder, systems, params, scenario, ports):
    """Add the compensator and an ``Adder`` in front of the motor's torque input, when a method is set.

    Returns
    -------
    dict
        ``ports`` with ``torque`` replaced by the adder's input the controller's command goes to.
    """
    compensator = make_compensator(params, scenario)
    ports = dict(ports)
    if compensator is None:
        return ports
    compensator.set_name("compensator")
    builder.AddSystem(compensator)
    adder = builder.AddSystem(Adder(2, 1))
    adder.set_name("torque_sum")
    systems["compensator"], systems["torque_sum"] = compensator, adder
    c = builder.Connect
    c(systems["reference"].GetOutputPort("reference"), compensator.GetInputPort("reference"))
    c(systems["encoder"].GetOutputPort("motor_measured"), compensator.GetInputPort("motor_measured"))
    c(systems["controller"].GetOutputPort("torque_command"), compensator.GetInputPort("torque_command"))
    c(systems["table"].GetOutputPort("table_state"), compensator.GetInputPort("table_state"))
    c(compensator.GetOutputPort("torque"), adder.get_input_port(1))
    c(adder.get_output_port(0), ports["torque"])
    ports["torque"] = adder.get_input_port(0)
    return ports
