"""Position sensors: the motor's rotary encoder and the table's linear scale (grating).

Both count: the reading is ``resolution * floor(true / resolution)``. A resolution of 0 (``0`` counts
per revolution) gives an ideal sensor, which is what linearization needs (a quantizer has no slope).
"""

import math

from pydrake.systems.framework import LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import floor, vector

__all__ = ["MotorEncoder", "MotorEncoder_", "LinearScale", "LinearScale_", "quantize", "encoder_resolution"]


def quantize(value, resolution):
    """``resolution * floor(value / resolution)``; identity for ``resolution == 0``."""
    if resolution == 0:
        return value
    return resolution * floor(value / resolution)


def encoder_resolution(counts_per_rev):
    """Angle of one encoder count (rad); 0 for an ideal encoder."""
    return 0.0 if counts_per_rev == 0 else 2.0 * math.pi / counts_per_rev


@TemplateSystem.define("MotorEncoder_")
def MotorEncoder_(T):
    class Impl(LeafSystem_[T]):
        """Incremental/absolute motor encoder.

        Input ``motor_state`` ``[theta, omega]``; output ``motor_measured`` ``[counted theta (rad),
        omega (rad/s)]``. The speed is passed through unquantized for the continuous controller
        (an ideal tachometer); the sampled controller ignores it and differentiates the counts,
        as a drive does.
        """

        def _construct(self, counts_per_rev, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.counts_per_rev = int(counts_per_rev)
            self.resolution = encoder_resolution(self.counts_per_rev)
            self._u_motor_state = self.DeclareVectorInputPort("motor_state", 2)
            self.DeclareVectorOutputPort("motor_measured", 2, self._calc)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.counts_per_rev, converter=converter)

        def _calc(self, context, output):
            theta, omega = self._u_motor_state.Eval(context)
            output.SetFromVector(vector([quantize(theta, self.resolution), omega]))

    return Impl


@TemplateSystem.define("LinearScale_")
def LinearScale_(T):
    class Impl(LeafSystem_[T]):
        """Linear scale on the table: input ``table_state`` ``[x, v]``, output ``table_position_measured``."""

        def _construct(self, resolution, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.resolution = float(resolution)
            self._u_table_state = self.DeclareVectorInputPort("table_state", 2)
            self.DeclareVectorOutputPort("table_position_measured", 1, self._calc)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.resolution, converter=converter)

        def _calc(self, context, output):
            x = self._u_table_state.Eval(context)[0]
            output.SetAtIndex(0, quantize(x, self.resolution))

    return Impl


MotorEncoder = MotorEncoder_[None]
LinearScale = LinearScale_[None]
