"""The paper's Fig. 2 drive: the motor side moves at exactly constant speed, no controller, no motor dynamics.

:class:`ConstantSpeedDrive` stands in for the motor of the feed-drive diagram
(``build_diagram(..., drive="constant_speed")``): its ``motor_state`` is ``[theta0 + omega t, omega]`` with
``omega = feed 2 pi / lead``, so the screw's spring (stiffness K, damping C of the axial chain) is wound up
at the feed speed and pushes the table (mass M) against friction, which is the mechanism of the paper's
equations 1-11. Its ``motor_torque`` is the torque the ideal drive has to supply (the screw's reaction).

:class:`DriveScenario` is a :class:`~drakecreep.scenario.Scenario` that also says which drive to build, so
``simulate()`` and sweeps can run the spring-driven system unchanged.
"""

import math
import sys
from dataclasses import dataclass

from pydrake.systems.framework import LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import vector
from drakecreep.errors import InputError
from drakecreep.scenario import Scenario

__all__ = ["DRIVES", "ConstantSpeedDrive", "ConstantSpeedDrive_", "DriveScenario", "scenario_with_drive", "motor_speed_for"]

#: drives :func:`drakecreep.model.diagram.build_diagram` can wire
DRIVES = ("cascade", "constant_speed")


@TemplateSystem.define("ConstantSpeedDrive_", scope=sys.modules[__name__])
def ConstantSpeedDrive_(T):
    class Impl(LeafSystem_[T]):
        """Ideal speed source on the motor shaft (no state).

        Input ports
        -----------
        load_torque : 1, N m (reaction of the screw; passed to ``motor_torque``)

        Output ports
        ------------
        motor_state : 2, ``[theta0 + omega t (rad), omega (rad/s)]``
        motor_torque : 1, torque the drive supplies (N m) = the load torque
        """

        def _construct(self, omega, theta0=0.0, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.omega = float(omega)
            self.theta0 = float(theta0)
            self._u_load_torque = self.DeclareVectorInputPort("load_torque", 1)
            self.DeclareVectorOutputPort("motor_state", 2, self._calc_state, prerequisites_of_calc={self.time_ticket()})
            self.DeclareVectorOutputPort("motor_torque", 1, self._calc_torque,
                                         prerequisites_of_calc={self.all_input_ports_ticket()})

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.omega, other.theta0, converter=converter)

        def _calc_state(self, context, output):
            t = context.get_time()
            output.SetFromVector(vector([self.theta0 + self.omega * t, self.omega + 0.0 * t]))

        def _calc_torque(self, context, output):
            output.SetAtIndex(0, self._u_load_torque.Eval(context)[0])

    return Impl


ConstantSpeedDrive = ConstantSpeedDrive_[None]


@dataclass(frozen=True)
class DriveScenario(Scenario):
    """A :class:`~drakecreep.scenario.Scenario` plus the drive: ``"cascade"`` (servo loop, the default
    machine) or ``"constant_speed"`` (the paper's Fig. 2: motor side at exactly the feed speed)."""

    drive: str = "cascade"

    def __post_init__(self):
        super().__post_init__()
        if self.drive not in DRIVES:
            raise InputError("drive", self.drive, "one of " + ", ".join(DRIVES))


def scenario_with_drive(drive=None, **fields):
    """A plain :class:`Scenario` for the cascade (so existing cache keys stay), else a :class:`DriveScenario`."""
    if drive is None or drive == "cascade":
        return Scenario(**fields)
    return DriveScenario(drive=drive, **fields)


def motor_speed_for(feed, lead):
    """Motor speed (rad/s) that moves the nut at ``feed`` (m/s) for a screw ``lead`` (m)."""
    return feed * 2.0 * math.pi / lead
