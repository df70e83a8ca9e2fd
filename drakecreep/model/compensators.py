"""Friction compensation: torque added to the cascade controller's command (Drake ``Adder``).

Every compensator is a ``TemplateSystem`` (float, AutoDiffXd, Expression) and reads what the drive has:
the reference ``[x_ref, v_ref]``, the motor encoder port ``[counted angle, motor speed]``, the linear
scale and, for the disturbance observer, the torque the controller applies. Two ways to run
(``compensation.speed_source``):

``encoder`` (the default with a sampled controller, issue 15)
    As a drive runs them: at the velocity-loop instants ``t_k = k h``, on the speed the controller has,
    the backward difference of the counts ``r (theta_k - theta_{k-1}) / h`` (or of the scale reading
    with ``velocity_source: table``); the output is held between samples and applied after the same
    ``controller.computation_delay`` as the controller's command (:class:`drakecreep.model.delay.OutputDelay`).
    Discrete state ``[position_prev, own states..., newest output, delay queue...]``, one group with
    the controller's period and offset, so the compiled fast path runs it (several groups, one timing).
``ideal``
    Continuous states, as a compensation at the current-loop rate on the unquantized motor speed (an
    ideal tachometer). Also what a continuous controller (``controller.sampled: false``) gets.

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
    :class:`drakecreep.model.friction.LuGreFriction`. Sampled: ``F_k`` from ``w_k`` and ``v_k``, then
    ``w`` advanced over the period with ``v_k`` held by the exact solution of its linear ODE
    (``w_{k+1} = w_k e^{-b h} + a (1 - e^{-b h}) / b``, stable at any stiffness).
dob
    Disturbance observer (Ohnishi): ``d = Q(s) (tau - J_n s omega)`` with ``Q = L / (s + L)`` on the
    motor-side rigid-body inertia ``J_n`` (motor, coupling, screw and the reflected table mass);
    ``d`` is added to the command. Sampled: ``raw_k = (tau_{k-1} + tau_{k-2}) / 2 - J_n (omega_k -
    omega_{k-1}) / h`` with ``omega_k`` the count difference (exact for a rigid body under held torques),
    then ``d_k = d_{k-1} + (1 - e^{-L h}) (raw_k - d_{k-1})`` (the Q filter, ZOH-discretized).
dither
    A sinusoidal force ``A Fc sin(2 pi f t)`` (no model of the speed at all); it breaks static
    friction by keeping the contact moving and adds its own ripple. Always continuous (no speed input).

The study that compares them is :mod:`drakecreep.studies.compensation`.
"""

import dataclasses
import math
import sys

from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.primitives import Adder
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import exp, fabs, tanh, vector, where
from drakecreep.model.delay import OutputDelay
from drakecreep.model.disturbances import sin
from drakecreep.errors import InputError
from drakecreep.params import COMPENSATION_METHODS
from drakecreep.model.screw import screw_inertia
from drakecreep.model.nut_table import friction_levels, moving_mass

__all__ = [
    "FrictionModel",
    "Sampling",
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
    "compensator_sampling",
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


@dataclasses.dataclass(frozen=True)
class Sampling:
    """How a compensator runs at the velocity-loop rate (``compensation.speed_source: encoder``).

    Attributes
    ----------
    period : float
        Velocity-loop period ``h`` (s).
    delay : float
        Computation delay (samples), the controller's.
    angle0 : float
        Counted encoder angle at ``t = 0`` (rad): the first backward difference starts from it.
    position0 : float
        Scale reading at ``t = 0`` (m), for ``velocity_source: table``.
    torque0 : float
        Torque applied before ``t = 0`` (N m), the DOB's ``tau_{-2}``.
    """

    period: float
    delay: float = 0.0
    angle0: float = 0.0
    position0: float = 0.0
    torque0: float = 0.0


def _declare_inputs(system):
    system._u_reference = system.DeclareVectorInputPort("reference", 2)
    system._u_motor_measured = system.DeclareVectorInputPort("motor_measured", 2)
    system._u_torque_command = system.DeclareVectorInputPort("torque_command", 1)
    system._u_table_state = system.DeclareVectorInputPort("table_state", 2)
    system._u_table_position_measured = system.DeclareVectorInputPort("table_position_measured", 1)


def _declare_sampled(system, sampling, own0, output0=0.0):
    """Discrete state ``[position_prev, *own0, newest output, delay queue]``, events and the held output."""
    system.delay = OutputDelay(sampling.delay)
    system.n_own = len(own0)
    start = sampling.position0 if getattr(system, "velocity_source", "motor") == "table" else sampling.angle0
    system.initial_state = [start] + [float(v) for v in own0] + [output0] + system.delay.initial(output0)
    system.DeclareDiscreteState(BasicVector_[system._T](system.initial_state))
    system.delay.declare(system, sampling.period, system._sampled_update, system._sampled_switch)
    system.DeclareVectorOutputPort("torque", 1, system._sampled_output, prerequisites_of_calc={system.xd_ticket()})


def _split(system, context):
    x = context.get_discrete_state_vector().CopyToVector()
    k = system.n_own
    return x[0], list(x[1:1 + k]), x[1 + k], list(x[2 + k:])


def _count_speed(system, context, previous):
    """``(position, speed)``: the counts now and the backward difference over one period (m/s, table side)."""
    h = system.sampling.period
    if getattr(system, "velocity_source", "motor") == "table":
        position = system._u_table_position_measured.Eval(context)[0]
        return position, (position - previous) / h
    angle = system._u_motor_measured.Eval(context)[0]
    return angle, (angle - previous) / h * system.ratio


def _sampled_update(system, context, discrete_state):
    previous, own, newest, extra = _split(system, context)
    position, speed = _count_speed(system, context, previous)
    own_next, output = system._step(context, speed, own, system.delay.applied(newest, extra))
    discrete_state.get_mutable_vector().SetFromVector(
        vector([position] + list(own_next) + [output] + system.delay.advance(newest, extra)))


def _sampled_switch(system, context, discrete_state):
    previous, own, newest, extra = _split(system, context)
    discrete_state.get_mutable_vector().SetFromVector(
        vector([previous] + own + [newest] + system.delay.switched(newest, extra)))


def _sampled_output(system, context, output):
    _, _, newest, extra = _split(system, context)
    output.SetAtIndex(0, system.delay.applied(newest, extra))


class _SampledMixin:
    """The sampled compensators' shared event handlers (see :class:`Sampling`)."""

    def _sampled_update(self, context, discrete_state):
        _sampled_update(self, context, discrete_state)

    def _sampled_switch(self, context, discrete_state):
        _sampled_switch(self, context, discrete_state)

    def _sampled_output(self, context, output):
        _sampled_output(self, context, output)


def _measured_speed(system, context):
    """Speed the compensator uses (m/s, table side): motor speed through the lead, or the table's."""
    if system.velocity_source == "table":
        return system._u_table_state.Eval(context)[1]
    return system._u_motor_measured.Eval(context)[1] * system.ratio


@TemplateSystem.define("StaticCompensator_", scope=sys.modules[__name__])
def StaticCompensator_(T):
    class Impl(_SampledMixin, LeafSystem_[T]):
        """Stribeck + viscous friction feedforward.

        Input ports ``reference`` (2), ``motor_measured`` (2), ``torque_command`` (1, unused);
        output ``torque`` (1, N m). ``sampling``: run at the loop rate (:class:`Sampling`), else continuous.
        """

        def _construct(self, model, lead, velocity_blend=0.0, velocity_source="motor", sampling=None,
                       converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self._T = T
            self.model, self.lead, self.velocity_blend = model, float(lead), float(velocity_blend)
            self.velocity_source = velocity_source
            self.sampling = sampling
            self.ratio = self.lead / (2.0 * math.pi)
            _declare_inputs(self)
            if sampling is None:
                self.DeclareVectorOutputPort("torque", 1, self._calc)
            else:
                _declare_sampled(self, sampling, [])

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.model, other.lead, other.velocity_blend, other.velocity_source,
                            other.sampling, converter=converter)

        def _law(self, v):
            m = self.model
            return m.g(v) * tanh(v / m.regularization_velocity) + m.viscous * v

        def force(self, context):
            v_ref = self._u_reference.Eval(context)[1]
            v = v_ref
            if self.velocity_blend > 0.0:
                v = (1.0 - self.velocity_blend) * v_ref + self.velocity_blend * _measured_speed(self, context)
            return self._law(v)

        def _step(self, context, speed, own, applied):
            v_ref = self._u_reference.Eval(context)[1]
            v = (1.0 - self.velocity_blend) * v_ref + self.velocity_blend * speed if self.velocity_blend > 0 else v_ref
            return [], self._law(v) * self.ratio

        def _calc(self, context, output):
            output.SetAtIndex(0, self.force(context) * self.ratio)

    return Impl


@TemplateSystem.define("LuGreCompensator_", scope=sys.modules[__name__])
def LuGreCompensator_(T):
    class Impl(_SampledMixin, LeafSystem_[T]):
        """LuGre friction compensation with a friction-state observer; state ``w = sigma0 z / Fc``.

        Input ports ``reference`` (2), ``motor_measured`` (2), ``torque_command`` (1, unused);
        output ``torque`` (1, N m). ``sampling``: run at the loop rate (:class:`Sampling`), else continuous.
        """

        def _construct(self, model, lead, observer_gain=0.0, velocity_source="motor", sampling=None,
                       converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self._T = T
            self.model, self.lead, self.observer_gain = model, float(lead), float(observer_gain)
            self.velocity_source = velocity_source
            self.sampling = sampling
            self.ratio = self.lead / (2.0 * math.pi)
            _declare_inputs(self)
            if sampling is None:
                self.DeclareContinuousState(BasicVector_[T]([0.0]))
                self.DeclareVectorOutputPort("torque", 1, self._calc)
            else:
                _declare_sampled(self, sampling, [0.0])

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.model, other.lead, other.observer_gain, other.velocity_source,
                            other.sampling, converter=converter)

        def _step(self, context, v, own, applied):
            m = self.model
            (w,) = own
            v_ref = self._u_reference.Eval(context)[1]
            zdot = v - fabs(v) * w * m.fc / m.g(v) - self.observer_gain * (v - v_ref)
            force = m.fc * w + m.sigma1 * zdot + m.viscous * v
            # dw/dt = a - b w with v held over the period: exact step
            a = m.sigma0 / m.fc * (v - self.observer_gain * (v - v_ref))
            b = m.sigma0 * fabs(v) / m.g(v)
            h = self.sampling.period
            small = b * h < 1e-9
            b_safe = where(small, 1.0 + 0.0 * b, b)
            decay = exp(-b_safe * h)
            gain = where(small, h + 0.0 * b, (1.0 - decay) / b_safe)
            w_next = where(small, w + a * h, w * decay + a * gain)
            return [w_next], force * self.ratio

        def _rates(self, context):
            m = self.model
            v_ref = self._u_reference.Eval(context)[1]
            v = _measured_speed(self, context)
            w = context.get_continuous_state_vector().GetAtIndex(0)
            zdot = v - fabs(v) * w * m.fc / m.g(v) - self.observer_gain * (v - v_ref)
            return v, w, zdot

        def DoCalcTimeDerivatives(self, context, derivatives):
            if self.sampling is not None:
                return
            _, _, zdot = self._rates(context)
            derivatives.get_mutable_vector().SetAtIndex(0, self.model.sigma0 / self.model.fc * zdot)

        def force(self, context):
            v, w, zdot = self._rates(context)
            m = self.model
            return m.fc * w + m.sigma1 * zdot + m.viscous * v

        def _calc(self, context, output):
            output.SetAtIndex(0, self.force(context) * self.ratio)

    return Impl


@TemplateSystem.define("DisturbanceObserver_", scope=sys.modules[__name__])
def DisturbanceObserver_(T):
    class Impl(_SampledMixin, LeafSystem_[T]):
        """First-order disturbance observer on the motor; state ``p`` with ``d = p - L J_n omega``.

        ``dp/dt = L (tau - p + L J_n omega)``, ``tau`` the torque sent to the motor (controller command
        plus ``d``), so that ``d = L/(s+L) (tau - J_n s omega)``. Output ``torque`` (1, N m) ``= d``.
        ``sampling``: the discrete observer of the module notes (:class:`Sampling`) instead.
        """

        def _construct(self, inertia, bandwidth, initial_torque=0.0, sampling=None, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self._T = T
            self.inertia, self.bandwidth = float(inertia), float(bandwidth)
            self.initial_torque = float(initial_torque)
            self.sampling = sampling
            self.ratio = 1.0  # the observer works on the motor angle (rad, rad/s)
            _declare_inputs(self)
            if sampling is None:
                self.DeclareContinuousState(BasicVector_[T]([self.initial_torque]))
                self.DeclareVectorOutputPort(
                    "torque", 1, self._calc,
                    prerequisites_of_calc={self.xc_ticket(),
                                           self.input_port_ticket(self._u_motor_measured.get_index())},
                )
            else:
                # own states [omega_{k-1}, tau_{k-2}]; at rest before t = 0 under the held torque
                _declare_sampled(self, sampling, [0.0, sampling.torque0], self.initial_torque)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.inertia, other.bandwidth, other.initial_torque, other.sampling,
                            converter=converter)

        def _step(self, context, omega, own, applied):
            omega_prev, tau_before = own
            h = self.sampling.period
            tau = self._u_torque_command.Eval(context)[0] + applied  # what the motor got over [t_{k-1}, t_k]
            raw = 0.5 * (tau + tau_before) - self.inertia * (omega - omega_prev) / h
            _, _, d, _ = _split(self, context)
            alpha = 1.0 - math.exp(-self.bandwidth * h)
            return [omega, tau], d + alpha * (raw - d)

        def _estimate(self, context):
            p = context.get_continuous_state_vector().GetAtIndex(0)
            omega = self._u_motor_measured.Eval(context)[1]
            return p, omega, p - self.bandwidth * self.inertia * omega

        def DoCalcTimeDerivatives(self, context, derivatives):
            if self.sampling is not None:
                return
            p, omega, d = self._estimate(context)
            tau = self._u_torque_command.Eval(context)[0] + d
            L = self.bandwidth
            derivatives.get_mutable_vector().SetAtIndex(0, L * (tau - p + L * self.inertia * omega))

        def _calc(self, context, output):
            output.SetAtIndex(0, self._estimate(context)[2])

    return Impl


@TemplateSystem.define("DitherCompensator_", scope=sys.modules[__name__])
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


def compensator_sampling(params, angle0=0.0, position0=0.0, torque0=0.0):
    """:class:`Sampling` when the compensator runs at the loop rate (sampled controller, ``speed_source:
    encoder``), else None (continuous, ideal tachometer)."""
    g = params.controller
    if not (g.sampled and params.compensation.speed_source == "encoder"):
        return None
    return Sampling(period=g.velocity_period, delay=g.computation_delay, angle0=float(angle0),
                    position0=float(position0), torque0=float(torque0))


def make_compensator(params, scenario, angle0=0.0, position0=0.0, torque0=0.0):
    """The compensator system for ``params.compensation.method`` (None for ``"none"``).

    ``angle0`` (rad, counted), ``position0`` (m, scale reading) and ``torque0`` (N m, held torque) are the
    drive's state at ``t = 0``, for the sampled compensators (:func:`compensator_sampling`).
    """
    c = params.compensation
    if c.method == "none":
        return None
    model = compensator_model(params, scenario.load_case)
    lead = params.screw.lead
    sampling = compensator_sampling(params, angle0, position0, torque0)
    if c.method == "static":
        return StaticCompensator(model, lead, c.velocity_blend, c.velocity_source, sampling)
    if c.method == "lugre":
        return LuGreCompensator(model, lead, c.observer_gain, c.velocity_source, sampling)
    if c.method == "dob":
        return DisturbanceObserver(rigid_inertia(params) * c.inertia_factor, c.dob_bandwidth, sampling=sampling)
    if c.method == "dither":
        return DitherCompensator(c.dither_amplitude * model.fc, c.dither_frequency, lead)
    raise InputError("compensation.method", c.method, "one of " + ", ".join(COMPENSATION_METHODS))


def add_compensation(builder, systems, params, scenario, ports, angle0=0.0, torque0=0.0):
    """Add the compensator and an ``Adder`` in front of the motor's torque input, when a method is set.

    ``angle0`` (counted encoder angle, rad) and ``torque0`` (held torque, N m) at ``t = 0`` start the
    sampled compensators' backward difference and observer (the table and its scale start at 0).

    Returns
    -------
    dict
        ``ports`` with ``torque`` replaced by the adder's input the controller's command goes to.
    """
    compensator = make_compensator(params, scenario, angle0=angle0, torque0=torque0)
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
    c(systems["scale"].GetOutputPort("table_position_measured"), compensator.GetInputPort("table_position_measured"))
    c(compensator.GetOutputPort("torque"), adder.get_input_port(1))
    c(adder.get_output_port(0), ports["torque"])
    ports["torque"] = adder.get_input_port(0)
    return ports
