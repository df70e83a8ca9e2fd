"""The ball nut's friction as a drag torque on the screw (``friction.nut_friction_on: screw``).

A ball nut resists the screw's rotation: preload drag plus a share of the axial load
(:func:`drakecreep.model.nut_table.friction_split`). Its sliding speed is the screw's, ``omega Ph / 2 pi``
at the table's scale, and it loads the motor side of the screw's elasticity, where the velocity loop
and a friction compensator act. The law and its shape are the drive's (``params.friction``); only the
level is the nut's. The viscous term is not: ``friction.viscous`` is the axis's one viscous coefficient
``Fv``, and it acts with the guides on the table wherever the nut's Coulomb level acts
(:func:`nut_friction_params`), as in the linearization (``model.steady.nut_on_table``).
"""

import dataclasses
import math
import sys

from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import vector
from drakecreep.model.disturbances import add_load_torque
from drakecreep.model.friction import make_friction_law
from drakecreep.model.nut_table import friction_split

__all__ = ["NutFriction", "NutFriction_", "nut_friction_levels", "nut_friction_params", "add_nut_friction"]


def nut_friction_levels(params, load):
    """``(Fc, Fs)`` (N, at the table's scale) of the nut when it acts on the screw, else ``(0, 0)``."""
    if params.friction.nut_friction_on != "screw":
        return 0.0, 0.0
    fc = friction_split(params, load)[1]
    return fc, params.friction.static_ratio * fc


def nut_friction_params(friction):
    """The friction parameters of the nut's drag on the screw: ``friction`` (law, shape, bristles) with no viscous
    term. ``friction.viscous`` is counted once, on the table: moving the nut's Coulomb level between the table
    and the screw (``friction.nut_friction_on``) must not add a second ``Fv`` (before this, the ``screw`` side
    had ``2 Fv`` in total, against ``Fv`` in the linearization and on the ``table`` side)."""
    return dataclasses.replace(friction, viscous=0.0)


@TemplateSystem.define("NutFriction_", scope=sys.modules[__name__])
def NutFriction_(T):
    class Impl(LeafSystem_[T]):
        """Drag torque of the nut on the screw.

        Input ``motor_state`` ``[theta, omega]``; outputs ``friction_torque`` (N m, opposing ``omega``)
        and ``friction_force`` (N, the same at the table's scale). State: the law's internal states.
        """

        def _construct(self, friction, fc, fs, lead, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.friction, self.fc, self.fs, self.lead = friction, float(fc), float(fs), float(lead)
            self.law = make_friction_law(friction)
            self.ratio = self.lead / (2.0 * math.pi)
            if self.law.num_states:
                self.DeclareContinuousState(BasicVector_[T]([0.0] * self.law.num_states))
            self._u_motor_state = self.DeclareVectorInputPort("motor_state", 2)
            self.DeclareVectorOutputPort("friction_torque", 1, self._calc_torque)
            self.DeclareVectorOutputPort("friction_force", 1, self._calc_force)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.friction, other.fc, other.fs, other.lead, converter=converter)

        def _speed_and_state(self, context):
            omega = self._u_motor_state.Eval(context)[1]
            z = context.get_continuous_state_vector().CopyToVector() if self.law.num_states else []
            return omega * self.ratio, z

        def force(self, context):
            """Nut friction (N) at the table's scale."""
            v, z = self._speed_and_state(context)
            return self.law.force(v, z, self.fc, self.fs)

        def DoCalcTimeDerivatives(self, context, derivatives):
            if self.law.num_states:
                v, z = self._speed_and_state(context)
                derivatives.get_mutable_vector().SetFromVector(vector(list(self.law.state_rates(v, z, self.fc, self.fs))))

        def _calc_force(self, context, output):
            output.SetAtIndex(0, self.force(context))

        def _calc_torque(self, context, output):
            output.SetAtIndex(0, self.force(context) * self.ratio)

    return Impl


NutFriction = NutFriction_[None]


def add_nut_friction(builder, systems, params, scenario, ports):
    """Add the nut's drag torque when ``friction.nut_friction_on == "screw"``; return the updated ports.

    ``ports["load_torque"]`` (where the screw's reaction goes for the motor) becomes one input of an
    adder whose other input is the nut's drag torque.
    """
    fc, fs = nut_friction_levels(params, params.load_case(scenario.load_case))
    if fc <= 0.0:
        return ports
    return add_load_torque(builder, systems, ports, NutFriction(nut_friction_params(params.friction), fc, fs,
                                                                 params.screw.lead),
                           "nut_friction", "friction_torque", "motor_load_sum")
