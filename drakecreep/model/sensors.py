"""Position sensors: the motor's rotary encoder and the table's linear scale (grating).

Both count: the reading is ``resolution * floor(true / resolution)``. A resolution of 0 (``0`` counts
per revolution) gives an ideal sensor, which is what linearization needs (a quantizer has no slope).

The linear scale may also carry an **interpolation error**: an incremental grating of signal period
``p`` (20 um for the common glass scales) is read by interpolating its sine/cosine signals, and
imperfect signals (amplitude, offset, phase errors) leave an error periodic in the position with the
signal period ([assumed] from manufacturers' data, "interpolation error" / "sub-divisional error": tens of
nm up to about 1 % of ``p`` on 20 um scales). The
reading is ``quantize(x + a sin(2 pi x / p), resolution)`` (:func:`scale_reading`), one formula for the
Drake system and for evaluating the sensor on a recorded position.

A speed measured from a counting sensor differentiates the counts over a sample period ``T``
(:func:`differenced_speed`): its quantum is ``resolution / T``, and an interpolation error of
amplitude ``a`` puts a ripple ``2 pi a v / p`` on it, proportional to the feed ``v``.
"""

import math
import sys

import numpy as np

from pydrake.systems.framework import LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import floor, vector
from drakecreep.model.disturbances import sin

__all__ = ["MotorEncoder", "MotorEncoder_", "LinearScale", "LinearScale_", "quantize", "encoder_resolution",
           "scale_reading", "differenced_speed"]


def quantize(value, resolution):
    """``resolution * floor(value / resolution)``; identity for ``resolution == 0``."""
    if resolution == 0:
        return value
    return resolution * floor(value / resolution)


def scale_reading(x, resolution, interpolation_error=0.0, signal_period=20e-6):
    """Reading of a linear scale at true position ``x`` (m): ``quantize(x + a sin(2 pi x / p), resolution)``.

    Works on floats, numpy arrays, AutoDiffXd and symbolic Expressions (the Drake system calls it).

    Parameters
    ----------
    x : float or array
        True position (m).
    resolution : float
        Counting step (m); 0 = unquantized.
    interpolation_error : float
        Amplitude ``a`` of the interpolation error (m); 0 = none.
    signal_period : float
        Signal period ``p`` of the grating (m).
    """
    if interpolation_error:
        x = x + interpolation_error * sin(2.0 * math.pi * x / signal_period)
    return quantize(x, resolution)


def differenced_speed(time, reading, period):
    """Speed a counter sampled every ``period`` seconds reports: ``(r[k] - r[k-1]) / period``.

    Parameters
    ----------
    time : array
        Uniform sample times of ``reading`` (s); ``period`` must be a whole multiple of their spacing.
    reading : array
        Sensor reading (m), e.g. :func:`scale_reading` of a recorded position or the diagram's
        ``scale_position`` signal.
    period : float
        Sample period of the speed measurement (s).

    Returns
    -------
    t : ndarray
        Times of the speed samples (the end of each difference), s.
    speed : ndarray
        m/s.
    """
    from drakecreep.errors import InputError

    time = np.asarray(time, dtype=float)
    if len(time) < 2:
        raise InputError("time", len(time), "at least two samples")
    step = (time[-1] - time[0]) / (len(time) - 1)
    ratio = period / step
    k = int(round(ratio))
    if k < 1 or abs(ratio - k) > 1e-6 * ratio:
        raise InputError("speed_meter_period", period, f"a whole multiple of the sample spacing {step:.6g} s")
    r = np.asarray(reading, dtype=float)[::k]
    return time[::k][1:], np.diff(r) / period


def encoder_resolution(counts_per_rev):
    """Angle of one encoder count (rad); 0 for an ideal encoder."""
    return 0.0 if counts_per_rev == 0 else 2.0 * math.pi / counts_per_rev


@TemplateSystem.define("MotorEncoder_", scope=sys.modules[__name__])
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


@TemplateSystem.define("LinearScale_", scope=sys.modules[__name__])
def LinearScale_(T):
    class Impl(LeafSystem_[T]):
        """Linear scale on the table: input ``table_state`` ``[x, v]``, output ``table_position_measured``.

        The reading is :func:`scale_reading`: counted at ``resolution``, with an interpolation error
        of amplitude ``interpolation_error`` periodic in the position with the grating's ``signal_period``.
        """

        def _construct(self, resolution, interpolation_error=0.0, signal_period=20e-6, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.resolution = float(resolution)
            self.interpolation_error = float(interpolation_error)
            self.signal_period = float(signal_period)
            self._u_table_state = self.DeclareVectorInputPort("table_state", 2)
            self.DeclareVectorOutputPort("table_position_measured", 1, self._calc)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.resolution, other.interpolation_error, other.signal_period,
                            converter=converter)

        def read(self, x):
            """The reading at true position(s) ``x`` (m): :func:`scale_reading` with this scale's settings."""
            return scale_reading(x, self.resolution, self.interpolation_error, self.signal_period)

        def _calc(self, context, output):
            x = self._u_table_state.Eval(context)[0]
            output.SetAtIndex(0, self.read(x))

    return Impl


MotorEncoder = MotorEncoder_[None]
LinearScale = LinearScale_[None]
