"""Servo motor: torque command -> torque through a torque limit and the closed current loop; rotor dynamics.

A drive whose torque constant falls off (``motor.saturation_torque`` ``tau_s`` > 0) applies
``tau / sqrt(1 + (tau / tau_s)^2)`` of the limited command ``tau`` (:func:`applied_torque`,
:func:`drakecreep.model.axis.saturating`): linear for small torques, saturating smoothly at ``tau_s``.

The rotating inertia is the rotor, the coupling and the screw shaft (passed in as ``load_inertia``),
so the motor side of the two-mass model lives here; the screw's elastic coupling to the table lives
in :mod:`drakecreep.model.screw`.
"""

import sys

import numpy as np
from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import clip, vector
from drakecreep.model.axis import saturating, unsaturated

__all__ = ["Motor", "Motor_", "motor_inertia", "applied_torque", "commanded_torque"]


def motor_inertia(motor, load_inertia=0.0):
    """Total rotating inertia (kg m^2) on the motor shaft: rotor + coupling + ``load_inertia``."""
    return motor.rotor_inertia + motor.coupling_inertia + load_inertia


def _inverse_saturation(motor):
    return 1.0 / motor.saturation_torque if motor.saturation_torque > 0.0 else 0.0


def applied_torque(motor, tau):
    """Torque [N m] the drive applies for the (limited) command ``tau`` [N m]: ``tau`` itself for a linear drive
    (``motor.saturation_torque`` 0), else ``tau / sqrt(1 + (tau / tau_s)^2)``; any Drake scalar."""
    return saturating(tau, _inverse_saturation(motor))


def commanded_torque(motor, applied):
    """The command [N m] whose :func:`applied_torque` is ``applied`` (a float; infinite where it is beyond
    ``motor.saturation_torque``)."""
    return unsaturated(applied, _inverse_saturation(motor))


@TemplateSystem.define("Motor_", scope=sys.modules[__name__])
def Motor_(T):
    class Impl(LeafSystem_[T]):
        """Motor with rotor state ``[theta, omega]`` (+ ``tau`` when the current loop has a lag).

        Input ports
        -----------
        torque_command : 1, N m (limited at the peak torque, then through the drive's saturation)
        load_torque : 1, N m (reaction of the screw on the rotor)

        Output ports
        ------------
        motor_state : 2, ``[theta (rad), omega (rad/s)]``
        motor_torque : 1, electromagnetic torque (N m)
        """

        def _construct(self, params, load_inertia=0.0, initial_state=None, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.params = params
            self.load_inertia = float(load_inertia)
            self.inertia = motor_inertia(params, self.load_inertia)
            self.has_lag = params.current_loop_time_constant > 0.0
            n = 3 if self.has_lag else 2
            x0 = np.zeros(n) if initial_state is None else np.asarray(initial_state, dtype=float)
            if x0.shape != (n,):
                raise ValueError(f"Motor initial_state must have {n} entries, got {x0.shape}")
            self.initial_state = x0
            self.DeclareContinuousState(BasicVector_[T](x0), num_q=1, num_v=1, num_z=n - 2)
            self._u_torque_command = self.DeclareVectorInputPort("torque_command", 1)
            self._u_load_torque = self.DeclareVectorInputPort("load_torque", 1)
            self.DeclareVectorOutputPort(
                "motor_state", 2, self._calc_state, prerequisites_of_calc={self.xc_ticket()}
            )
            torque_deps = {self.xc_ticket()} if self.has_lag else {self.all_input_ports_ticket()}
            self.DeclareVectorOutputPort(
                "motor_torque", 1, self._calc_torque, prerequisites_of_calc=torque_deps
            )

        def _construct_copy(self, other, converter=None):
            Impl._construct(
                self, other.params, load_inertia=other.load_inertia,
                initial_state=other.initial_state, converter=converter,
            )

        def _commanded(self, context):
            u = self._u_torque_command.Eval(context)[0]
            limit = self.params.peak_torque
            return applied_torque(self.params, clip(u, -limit, limit))

        def _torque(self, context, x):
            return x[2] if self.has_lag else self._commanded(context)

        def DoCalcTimeDerivatives(self, context, derivatives):
            x = context.get_continuous_state_vector().CopyToVector()
            omega = x[1]
            tau = self._torque(context, x)
            load = self._u_load_torque.Eval(context)[0]
            domega = (tau - load - self.params.viscous_damping * omega) / self.inertia
            xdot = [omega, domega]
            if self.has_lag:
                xdot.append((self._commanded(context) - tau) / self.params.current_loop_time_constant)
            derivatives.get_mutable_vector().SetFromVector(vector(xdot))

        def _calc_state(self, context, output):
            x = context.get_continuous_state_vector().CopyToVector()
            output.SetFromVector(x[:2])

        def _calc_torque(self, context, output):
            x = context.get_continuous_state_vector().CopyToVector()
            output.SetAtIndex(0, self._torque(context, x))

    return Impl


Motor = Motor_[None]
