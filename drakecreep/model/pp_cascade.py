"""The P-P cascade of the EMPS benchmark as a sampled Drake system, with an optional computation delay.

At each sample ``t_k = k h`` (offset 0, period ``h``)::

    q[k]  = res * floor(x[k] / res)                  (encoder counts; res = 0: ideal)
    qf[k] = sum_i taps[i] * q[k-i]                   (EMPS: 0.5 q[k] + 0.5 q[k-1])
    dq[k] = (qf[k] - qf[k-1]) / h
    u[k]  = clip(kp * kv * (x_ref[k] - q[k]) - kv * dq[k], -saturation, saturation)

and the drive force ``gain * u`` is held (zero-order hold). A computation delay of ``delay = n + f``
samples (``n`` integer, ``0 <= f < 1``) applies ``u[k-n]`` from ``t_k + f h`` on: ``f = 0`` is one
periodic update; ``f > 0`` adds a second periodic update at offset ``f h`` that switches the
applied value (validation and events: :mod:`drakecreep.model.delay`, shared with the PI cascade).
The documented EMPS law is ``delay = 0``.

Discrete state: ``[q[k-1] .. q[k-N] (N = len(taps)), u[k] .. u[k-n], applied]``.
"""

import math
import sys

from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.errors import InputError
from drakecreep.model._scalar import clip, vector
from drakecreep.model.delay import OutputDelay, split_delay
from drakecreep.model.sensors import quantize

__all__ = ["PPCascade", "PPCascade_", "pp_initial_state"]


def pp_initial_state(taps, delay, q0, v0, h, u_history=()):
    """Discrete state of a loop that has tracked ``q0 - v0 (t0 - t)`` before ``t0``.

    Parameters
    ----------
    taps : sequence of float
    delay : float
        Computation delay [samples].
    q0, v0 : float
        Position [m] and speed [m/s] at the first sample.
    h : float
        Sample time [s].
    u_history : sequence of float
        Outputs before the first sample, newest first (fills the delay queue; missing = 0).
    """
    n = int(math.floor(delay))
    hist = [q0 - (i + 1) * v0 * h for i in range(len(taps))]
    queue = [float(u_history[i]) if i < len(u_history) else 0.0 for i in range(n + 1)]
    applied = queue[n] if n < len(queue) else 0.0
    return hist + queue + [applied]


@TemplateSystem.define("PPCascade_", scope=sys.modules[__name__])
def PPCascade_(T):
    class Impl(LeafSystem_[T]):
        """Sampled position-P / velocity-P cascade (EMPS).

        Input ports
        -----------
        x_ref : 1, reference position (m)
        position : 1, fed-back position (m), before the encoder counts

        Output ports
        ------------
        force : 1, applied drive force ``gain * u`` (N)
        u : 1, controller output of the latest sample (unit of u)
        """

        def _construct(self, kp, kv, saturation, period, taps=(1.0,), gain=1.0, resolution=0.0, delay=0.0,
                       initial_state=None, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.kp, self.kv, self.saturation = float(kp), float(kv), float(saturation)
            self.period, self.gain, self.resolution = float(period), float(gain), float(resolution)
            self.taps = tuple(float(c) for c in taps)
            self.n_delay, self.frac = split_delay(delay, "controller.delay")
            self.delay = float(delay)
            n = len(self.taps) + self.n_delay + 2
            self.initial_state = [0.0] * n if initial_state is None else [float(v) for v in initial_state]
            if len(self.initial_state) != n:
                raise InputError("initial_state", len(self.initial_state), f"{n} entries")
            self._x_ref = self.DeclareVectorInputPort("x_ref", 1)
            self._position = self.DeclareVectorInputPort("position", 1)
            self.DeclareDiscreteState(BasicVector_[T](self.initial_state))
            OutputDelay(self.delay, "controller.delay").declare(self, self.period, self._update, self._switch)
            deps = {self.xd_ticket()}
            self.DeclareVectorOutputPort("force", 1, self._calc_force, prerequisites_of_calc=deps)
            self.DeclareVectorOutputPort("u", 1, self._calc_u, prerequisites_of_calc=deps)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.kp, other.kv, other.saturation, other.period, other.taps, other.gain,
                            other.resolution, other.delay, other.initial_state, converter=converter)

        def _update(self, context, discrete_state):
            s = context.get_discrete_state_vector().CopyToVector()
            N = len(self.taps)
            past = list(s[:N])                       # q[k-1] .. q[k-N]
            queue = list(s[N:N + self.n_delay + 1])  # u[k-1] .. u[k-1-n]
            applied = s[-1]
            q = quantize(self._position.Eval(context)[0], self.resolution)
            qf = sum(c * v for c, v in zip(self.taps, [q] + past[:N - 1]))
            qf_prev = sum(c * v for c, v in zip(self.taps, past))
            dq = (qf - qf_prev) / self.period
            u = clip(self.kp * self.kv * (self._x_ref.Eval(context)[0] - q) - self.kv * dq,
                     -self.saturation, self.saturation)
            queue = [u] + queue[:-1]
            if self.frac == 0:
                applied = queue[self.n_delay]
            discrete_state.get_mutable_vector().SetFromVector(vector([q] + past[:-1] + queue + [applied]))

        def _switch(self, context, discrete_state):
            s = context.get_discrete_state_vector().CopyToVector()
            s = list(s)
            s[-1] = s[len(self.taps) + self.n_delay]
            discrete_state.get_mutable_vector().SetFromVector(vector(s))

        def _calc_force(self, context, output):
            output.SetAtIndex(0, self.gain * context.get_discrete_state_vector().GetAtIndex(self.num_states() - 1))

        def _calc_u(self, context, output):
            output.SetAtIndex(0, context.get_discrete_state_vector().GetAtIndex(len(self.taps)))

        def num_states(self):
            return len(self.initial_state)

    return Impl


PPCascade = PPCascade_[None]
