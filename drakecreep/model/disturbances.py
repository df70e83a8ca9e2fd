"""Periodic disturbances of a real feed drive that the base model leaves out (off by default).

All are written once for float, AutoDiffXd and symbolic Expression, so the compiled fast path keeps
working; :func:`add_disturbances` wires them into the diagram only when their amplitude is non-zero
(the diagram of the ``paper`` preset is unchanged).

LeadError
    Kinematic error of the screw-nut pair: the nut advances ``u(theta) = r theta + e(theta)`` with
    ``r = Ph / 2 pi``, ``psi = 2 pi r (theta - theta0) / P`` and
    ``e = a [sin(psi + phi) - sin(phi)] + a2 [sin(2 psi + phi2) - sin(phi2)]`` (a lead-error harmonic of travel
    period ``P``, e.g. the waviness left by ball passage in the nut, and its second harmonic; ``phi``, ``phi2``
    their phases at the start angle ``theta0``, where ``e`` is counted from so the screw starts relaxed). The screw's spring sees ``u``
    instead of ``r theta``, and by virtual work the motor carries ``F du/dtheta = F (r + e')``; the
    screw already returns ``F r``, this system adds ``F e'``. A semi-closed loop (motor encoder)
    cannot see the error, so the table speed carries a ripple ``2 pi a / P`` of the feed, whatever
    the feed.
LoadRipple
    A force ``-(A + r_l Fx) sin(2 pi f t + phi)`` added to the screw's push on the table: ``A`` a vibration of
    fixed frequency that does not depend on the load, ``r_l Fx`` a pulsation of the axial load of the
    load case (the paper's air cylinders). The table-speed ripple it causes does not depend on the feed.
Cogging
    A load torque on the motor fixed to its angle, ``r F(x)`` with ``r = Ph / 2 pi``, ``x = r theta`` the motor's
    travel and ``F(x) = c sin(psi + phi) + c2 sin(2 psi + phi2)``, ``psi = 2 pi x / P`` (:func:`cogging_force`:
    a servo motor's cogging or a support bearing's defect, at ``P`` = the lead over its order per motor
    revolution, and its second harmonic; ``phi``, ``phi2`` their phases at the screw's position 0). The motor
    encoder sees the motion it causes; its force does not depend on the feed, its frequency does.
"""

import math
import sys

import numpy as np
import pydrake.math as dmath
from pydrake.systems.framework import LeafSystem_
from pydrake.systems.primitives import Adder
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import vector

__all__ = ["LeadError", "LeadError_", "LoadRipple", "LoadRipple_", "Cogging", "Cogging_", "cogging_force",
           "add_disturbances", "add_load_torque", "sin", "cos"]


def sin(x):
    """Sine of a float, numpy array, AutoDiffXd or Expression."""
    return np.sin(x) if isinstance(x, (float, int, np.floating, np.ndarray)) else dmath.sin(x)


def cos(x):
    """Cosine of a float, numpy array, AutoDiffXd or Expression."""
    return np.cos(x) if isinstance(x, (float, int, np.floating, np.ndarray)) else dmath.cos(x)


@TemplateSystem.define("LeadError_", scope=sys.modules[__name__])
def LeadError_(T):
    class Impl(LeafSystem_[T]):
        """Kinematic lead error between the motor rotation and the nut.

        Input ports
        -----------
        motor_state : 2, ``[theta (rad), omega (rad/s)]``
        axial_force : 1, screw force on the table (N)

        Output ports
        ------------
        nut_motion : 2, ``[u / r (rad), du/dt / r (rad/s)]``: the rotation an error-free screw would
            need for the nut's actual travel (feeds the screw's ``motor_state`` input)
        torque : 1, ``F e'(theta)`` (N m), the reaction torque the screw's ``F r`` leaves out
        """

        def _construct(self, amplitude, period, lead, angle0=0.0, phase=0.0, amplitude2=0.0, phase2=0.0,
                       converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.amplitude = float(amplitude)
            self.period = float(period)
            self.lead = float(lead)
            self.angle0 = float(angle0)
            self.phase = float(phase)
            self.amplitude2 = float(amplitude2)
            self.phase2 = float(phase2)
            self.ratio = self.lead / (2.0 * math.pi)
            self._u_motor_state = self.DeclareVectorInputPort("motor_state", 2)
            self._u_axial_force = self.DeclareVectorInputPort("axial_force", 1)
            self.DeclareVectorOutputPort("nut_motion", 2, self._calc_motion)
            self.DeclareVectorOutputPort("torque", 1, self._calc_torque)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.amplitude, other.period, other.lead, other.angle0, other.phase,
                            other.amplitude2, other.phase2, converter=converter)

        def _angle(self, theta):
            """``psi``: the fundamental's angle of travel since the start angle."""
            return 2.0 * math.pi * self.ratio * (theta - self.angle0) / self.period

        def error(self, theta):
            """``e(theta)`` (m), 0 at the start angle."""
            psi = self._angle(theta)
            e = self.amplitude * (sin(psi + self.phase) - math.sin(self.phase))
            if self.amplitude2 > 0.0:
                e = e + self.amplitude2 * (sin(2.0 * psi + self.phase2) - math.sin(self.phase2))
            return e

        def slope(self, theta):
            """``de/dtheta`` (m/rad)."""
            psi = self._angle(theta)
            k = 2.0 * math.pi * self.ratio / self.period
            s = self.amplitude * k * cos(psi + self.phase)
            if self.amplitude2 > 0.0:
                s = s + self.amplitude2 * 2.0 * k * cos(2.0 * psi + self.phase2)
            return s

        def _calc_motion(self, context, output):
            theta, omega = self._u_motor_state.Eval(context)
            error = self.error(theta)
            output.SetFromVector(vector([theta + error / self.ratio, omega * (1.0 + self.slope(theta) / self.ratio)]))

        def _calc_torque(self, context, output):
            theta = self._u_motor_state.Eval(context)[0]
            force = self._u_axial_force.Eval(context)[0]
            output.SetAtIndex(0, force * self.slope(theta))

    return Impl


@TemplateSystem.define("LoadRipple_", scope=sys.modules[__name__])
def LoadRipple_(T):
    class Impl(LeafSystem_[T]):
        """Force ripple on the table: output ``force`` (1, N) ``= -amplitude sin(2 pi f t + phase)``, added to the
        push."""

        def _construct(self, amplitude, frequency, phase=0.0, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.amplitude = float(amplitude)
            self.frequency = float(frequency)
            self.phase = float(phase)
            self.DeclareVectorOutputPort("force", 1, self._calc, prerequisites_of_calc={self.time_ticket()})

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.amplitude, other.frequency, other.phase, converter=converter)

        def _calc(self, context, output):
            t = context.get_time()
            output.SetAtIndex(0, -self.amplitude * sin(2.0 * math.pi * self.frequency * t + self.phase))

    return Impl


def cogging_force(disturbance, x):
    """The cogging's load [N, at the table's scale] at the motor's travel ``x`` [m] (``theta Ph / 2 pi``) for
    :class:`~drakecreep.params.DisturbanceParams` ``disturbance``; ``x`` a float, numpy array, AutoDiffXd or
    Expression (the one implementation: :class:`Cogging` and the start equilibrium use it)."""
    d = disturbance
    psi = 2.0 * math.pi * x / d.cogging_period
    force = d.cogging_force * sin(psi + d.cogging_phase)
    if d.cogging_2_force > 0.0:
        force = force + d.cogging_2_force * sin(2.0 * psi + d.cogging_2_phase)
    return force


@TemplateSystem.define("Cogging_", scope=sys.modules[__name__])
def Cogging_(T):
    class Impl(LeafSystem_[T]):
        """Cogging load torque on the motor: input ``motor_state`` (2, ``[theta (rad), omega (rad/s)]``), output
        ``torque`` (1, N m) ``= (Ph / 2 pi) F(theta Ph / 2 pi)`` (:func:`cogging_force`), added to the load."""

        def _construct(self, disturbance, lead, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.disturbance = disturbance
            self.lead = float(lead)
            self.ratio = self.lead / (2.0 * math.pi)
            self._u_motor_state = self.DeclareVectorInputPort("motor_state", 2)
            self.DeclareVectorOutputPort("torque", 1, self._calc)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.disturbance, other.lead, converter=converter)

        def _calc(self, context, output):
            theta = self._u_motor_state.Eval(context)[0]
            output.SetAtIndex(0, self.ratio * cogging_force(self.disturbance, self.ratio * theta))

    return Impl


LeadError = LeadError_[None]
LoadRipple = LoadRipple_[None]
Cogging = Cogging_[None]


def add_load_torque(builder, systems, ports, system, name, output, sum_name):
    """Add ``system`` (named ``name``, fed the motor's state on its ``motor_state`` input) whose ``output`` port is
    a torque on the motor's load, through an adder ``sum_name`` before ``ports["load_torque"]``; return the
    updated ports (``load_torque``: the adder's other input)."""
    system = builder.AddSystem(system)
    system.set_name(name)
    total = builder.AddSystem(Adder(2, 1))
    total.set_name(sum_name)
    systems[name], systems[sum_name] = system, total
    builder.Connect(systems["motor"].GetOutputPort("motor_state"), system.GetInputPort("motor_state"))
    builder.Connect(system.GetOutputPort(output), total.get_input_port(1))
    builder.Connect(total.get_output_port(0), ports["load_torque"])
    return dict(ports, load_torque=total.get_input_port(0))


def add_disturbances(builder, systems, params, scenario, ports, angle0=0.0):
    """Add the disturbances ``params.disturbance`` switches on; return the ports the plant's signals now feed.

    Parameters
    ----------
    builder : DiagramBuilder
    systems : dict
        The diagram's systems by role (``motor``, ``screw``, ``table``); added systems go in here too.
    params : drakecreep.params.DriveParams
    scenario : drakecreep.scenario.Scenario
    ports : dict
        ``nut_motion`` (where the motor state goes for the screw), ``axial_force`` (where the screw
        force goes for the table), ``load_torque`` (where the screw's reaction goes for the motor).
    angle0 : float
        Motor angle at the start (rad), the phase reference of the lead error.

    Returns
    -------
    dict
        ``ports`` with the entries replaced by the inputs of the added systems.
    """
    d = params.disturbance
    ports = dict(ports)
    if d.has_lead_error:
        lead = builder.AddSystem(LeadError(d.lead_error_amplitude, d.lead_error_period, params.screw.lead, angle0,
                                           d.lead_error_phase, d.lead_error_2_amplitude, d.lead_error_2_phase))
        lead.set_name("lead_error")
        torque_sum = builder.AddSystem(Adder(2, 1))
        torque_sum.set_name("load_torque_sum")
        systems["lead_error"], systems["load_torque_sum"] = lead, torque_sum
        builder.Connect(lead.GetOutputPort("nut_motion"), ports["nut_motion"])
        builder.Connect(systems["screw"].GetOutputPort("axial_force"), lead.GetInputPort("axial_force"))
        builder.Connect(lead.GetOutputPort("torque"), torque_sum.get_input_port(1))
        builder.Connect(torque_sum.get_output_port(0), ports["load_torque"])
        ports["nut_motion"] = lead.GetInputPort("motor_state")
        ports["load_torque"] = torque_sum.get_input_port(0)
    if d.has_cogging:
        ports = add_load_torque(builder, systems, ports, Cogging(d, params.screw.lead), "cogging", "torque",
                                "cogging_torque_sum")
    amplitude = d.force_ripple + d.load_ripple * abs(params.load_case(scenario.load_case).fx)
    if amplitude > 0.0:
        ripple = builder.AddSystem(LoadRipple(amplitude, d.ripple_frequency, d.ripple_phase))
        ripple.set_name("load_ripple")
        push_sum = builder.AddSystem(Adder(2, 1))
        push_sum.set_name("push_sum")
        systems["load_ripple"], systems["push_sum"] = ripple, push_sum
        builder.Connect(ripple.get_output_port(0), push_sum.get_input_port(1))
        builder.Connect(push_sum.get_output_port(0), ports["axial_force"])
        ports["axial_force"] = push_sum.get_input_port(0)
    return ports
