"""Feed reference: a position ramp at the feed speed, reached with a constant acceleration."""

import sys

from pydrake.systems.framework import LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import vector, where

__all__ = ["FeedReference", "FeedReference_"]


@TemplateSystem.define("FeedReference_", scope=sys.modules[__name__])
def FeedReference_(T):
    class Impl(LeafSystem_[T]):
        """Output ``reference`` ``[x_ref (m), v_ref (m/s)]`` as a function of time.

        ``x_ref = x0 + feed t^2 / (2 ta)`` for ``t < ta``, then ``x0 + feed (t - ta/2)``.
        """

        def _construct(self, feed, acceleration_time, x0=0.0, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.feed = float(feed)
            self.acceleration_time = float(acceleration_time)
            self.x0 = float(x0)
            self.DeclareVectorOutputPort("reference", 2, self._calc, prerequisites_of_calc={self.time_ticket()})

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.feed, other.acceleration_time, other.x0, converter=converter)

        def _calc(self, context, output):
            t = context.get_time()
            v, ta = self.feed, self.acceleration_time
            if ta == 0.0:
                output.SetFromVector(vector([self.x0 + v * t, v + 0.0 * t]))
                return
            ramping = t < ta
            x = where(ramping, self.x0 + 0.5 * v * t * t / ta, self.x0 + v * (t - 0.5 * ta))
            speed = where(ramping, v * t / ta, v + 0.0 * t)
            output.SetFromVector(vector([x, speed]))

    return Impl


FeedReference = FeedReference_[None]
