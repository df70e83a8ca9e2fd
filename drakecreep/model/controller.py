"""PI cascade controller: position P with velocity feedforward, velocity PI with anti-windup.

Both loops work on table-side linear quantities (m, m/s, N); the output is the motor torque command
``F * Ph / (2 pi)``. Anti-windup is back-calculation (Astrom & Hagglund, *Advanced PID Control*,
ISA 2006, sec. 3.5) with tracking time ``Tt = kv / ki``: smooth, so the same source also serves
linearization and the symbolic fast path.

Two variants from one class:

* ``sampled`` (``ControllerParams.sampled``): periodic discrete update at the velocity-loop period;
  the position loop runs every ``position_period / velocity_period`` velocity samples; the speed is
  the backward difference of the encoder counts; the force command is held (zero-order hold) and
  applied after ``computation_delay = n + f`` samples (:class:`drakecreep.model.delay.OutputDelay`:
  ``force[k-n]`` from ``t_k + f h`` on; 1 in the presets).
  Discrete state ``[v_cmd, integrator, theta_prev, force, tick]`` followed, for a delay > 0, by the
  queue ``force[k-1] .. force[k-n]`` and (``f > 0``) the applied force; ``force`` is the newest command.
* continuous: the integrator is the only (continuous) state; the speed comes from the motor state.
  This is the variant to linearize.

Position feedback: ``motor`` (semi-closed loop, encoder angle times lead over 2 pi) or ``table``
(closed loop on the linear scale).
"""

import math
import sys

from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import clip, vector, where
from drakecreep.model.delay import OutputDelay

__all__ = ["CascadeController", "CascadeController_", "force_limit"]


def force_limit(params):
    """Largest axial force (N) the drive can command: peak torque through the lead."""
    return params.motor.peak_torque * 2.0 * math.pi / params.screw.lead


@TemplateSystem.define("CascadeController_", scope=sys.modules[__name__])
def CascadeController_(T):
    class Impl(LeafSystem_[T]):
        """PI cascade controller.

        Input ports
        -----------
        reference : 2, ``[x_ref (m), v_ref (m/s)]``
        motor_measured : 2, ``[encoder angle (rad), motor speed (rad/s)]``
        table_position_measured : 1, linear scale reading (m)

        Output ports
        ------------
        torque_command : 1, N m, the applied (delayed) command
        controller_signals : 3, ``[v_cmd (m/s), newest force command (N), integrator (N)]``
        """

        def _construct(self, gains, lead, limit, initial_force=0.0, initial_angle=0.0, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.gains = gains
            self.lead = float(lead)
            self.limit = float(limit)
            self.initial_force = float(initial_force)
            self.initial_angle = float(initial_angle)
            self.ratio = self.lead / (2.0 * math.pi)
            g = gains
            # back-calculation with tracking time Tt = kv / ki: the rate 1 / Tt
            self.tracking = g.velocity_integral_gain / g.velocity_gain if g.anti_windup else 0.0
            self._u_reference = self.DeclareVectorInputPort("reference", 2)
            self._u_motor_measured = self.DeclareVectorInputPort("motor_measured", 2)
            self._u_table_position_measured = self.DeclareVectorInputPort("table_position_measured", 1)
            if g.sampled:
                f0 = self.initial_force
                self.delay = OutputDelay(g.computation_delay)
                self.initial_state = [0.0, f0, self.initial_angle, f0, 0.0] + self.delay.initial(f0)
                self.DeclareDiscreteState(BasicVector_[T](self.initial_state))
                self.delay.declare(self, g.velocity_period, self._update, self._switch)
                deps = {self.xd_ticket()}
                self.DeclareVectorOutputPort("torque_command", 1, self._torque_sampled, prerequisites_of_calc=deps)
                self.DeclareVectorOutputPort("controller_signals", 3, self._signals_sampled, prerequisites_of_calc=deps)
            else:
                self.initial_state = [self.initial_force]
                self.DeclareContinuousState(BasicVector_[T](self.initial_state))
                self.DeclareVectorOutputPort("torque_command", 1, self._torque_continuous)
                self.DeclareVectorOutputPort("controller_signals", 3, self._signals_continuous)

        def _construct_copy(self, other, converter=None):
            Impl._construct(
                self, other.gains, other.lead, other.limit, initial_force=other.initial_force,
                initial_angle=other.initial_angle, converter=converter,
            )

        # -- shared pieces ------------------------------------------------------------------
        def _position(self, context, theta):
            if self.gains.position_feedback == "table":
                return self._u_table_position_measured.Eval(context)[0]
            return theta * self.ratio

        def _velocity_command(self, context, theta):
            x_ref, v_ref = self._u_reference.Eval(context)
            g = self.gains
            return g.position_gain * (x_ref - self._position(context, theta)) + g.velocity_feedforward * v_ref

        def _pi(self, error, integrator):
            """Force command and integrator rate for a speed error (back-calculation anti-windup)."""
            unsaturated = self.gains.velocity_gain * error + integrator
            force = clip(unsaturated, -self.limit, self.limit)
            rate = self.gains.velocity_integral_gain * error + self.tracking * (force - unsaturated)
            return force, rate

        # -- sampled ------------------------------------------------------------------------
        def _update(self, context, discrete_state):
            x = context.get_discrete_state_vector().CopyToVector()
            v_held, integ, theta_prev, force_before, tick = x[:5]
            g = self.gains
            theta = self._u_motor_measured.Eval(context)[0]
            speed = (theta - theta_prev) / g.velocity_period * self.ratio
            v_cmd = where(tick < 0.5, self._velocity_command(context, theta), v_held)
            force, rate = self._pi(v_cmd - speed, integ)
            n = g.position_divider
            next_tick = where(tick > n - 1.5, 0.0 * tick, tick + 1.0)
            discrete_state.get_mutable_vector().SetFromVector(
                vector([v_cmd, integ + g.velocity_period * rate, theta, force, next_tick]
                       + self.delay.advance(force_before, x[5:]))
            )

        def _switch(self, context, discrete_state):
            x = context.get_discrete_state_vector().CopyToVector()
            discrete_state.get_mutable_vector().SetFromVector(
                vector(list(x[:5]) + self.delay.switched(x[3], x[5:])))

        def _torque_sampled(self, context, output):
            x = context.get_discrete_state_vector().CopyToVector()
            output.SetAtIndex(0, self.delay.applied(x[3], x[5:]) * self.ratio)

        def _signals_sampled(self, context, output):
            x = context.get_discrete_state_vector().CopyToVector()
            output.SetFromVector(x[[0, 3, 1]])

        # -- continuous ---------------------------------------------------------------------
        def _continuous(self, context):
            theta, omega = self._u_motor_measured.Eval(context)
            integ = context.get_continuous_state_vector().GetAtIndex(0)
            v_cmd = self._velocity_command(context, theta)
            force, rate = self._pi(v_cmd - omega * self.ratio, integ)
            return v_cmd, force, rate, integ

        def DoCalcTimeDerivatives(self, context, derivatives):
            if not self.gains.sampled:
                derivatives.get_mutable_vector().SetAtIndex(0, self._continuous(context)[2])

        def _torque_continuous(self, context, output):
            output.SetAtIndex(0, self._continuous(context)[1] * self.ratio)

        def _signals_continuous(self, context, output):
            v_cmd, force, _, integ = self._continuous(context)
            output.SetFromVector(vector([v_cmd, force, integ]))

    return Impl


CascadeController = CascadeController_[None]
