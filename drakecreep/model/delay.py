"""A computation (output) delay of a sampled controller: the one implementation of its queue and events.

A sampled drive reads its sensors at ``t_k = k h``, computes ``u[k]`` and applies it after a
computation delay of ``delay = n + f`` samples (``n`` integer, ``0 <= f < 1``): ``u[k - n]`` from
``t_k + f h`` on. ``f = 0`` needs only the periodic update at the sample instants; ``f > 0`` adds a
second periodic update at offset ``f h`` that switches the applied value (exact, no interpolation).

State layout this helper keeps, after the owner's own discrete state, which holds the newest output
``u[k]`` somewhere: ``[u[k-1] .. u[k-n]]`` (the queue) and, when ``f > 0``, ``applied``. With
``delay = 0`` there is no extra state at all, so a system without delay is unchanged.

Used by :class:`drakecreep.model.controller.CascadeController` (``controller.computation_delay``),
the sampled compensators (:mod:`drakecreep.model.compensators`) and, for the validation and event
declaration, the EMPS law :class:`drakecreep.model.pp_cascade.PPCascade`.
"""

import math

from drakecreep.errors import InputError

__all__ = ["OutputDelay", "split_delay"]


def split_delay(delay, field="controller.computation_delay"):
    """``(n, f)`` of a delay in samples; ``InputError(field, ...)`` unless finite and >= 0."""
    if isinstance(delay, bool) or not isinstance(delay, (int, float)) or not (math.isfinite(delay) and delay >= 0):
        raise InputError(field, delay, "a number of samples >= 0 (fractions allowed)")
    n = int(math.floor(float(delay)))
    return n, float(delay) - n


class OutputDelay:
    """Queue of past outputs and the applied value for a delay of ``delay`` samples.

    Parameters
    ----------
    delay : float
        Samples, >= 0.
    field : str
        Parameter name reported by :class:`~drakecreep.errors.InputError` for a bad value.
    """

    def __init__(self, delay, field="controller.computation_delay"):
        self.n, self.frac = split_delay(delay, field)
        self.delay = float(delay)
        self.field = field

    @property
    def size(self):
        """Number of extra discrete states: ``n`` queued outputs plus ``applied`` when ``f > 0``."""
        return self.n + (1 if self.frac > 0 else 0)

    def initial(self, u0):
        """Extra states of a drive that has output ``u0`` for ever."""
        return [float(u0)] * self.size

    def advance(self, newest_before, extra):
        """Extra states after a sample: the queue shifts by one, ``applied`` stays (it switches at ``f h``).

        Parameters
        ----------
        newest_before : scalar
            The owner's newest output before this sample, ``u[k-1]``.
        extra : sequence
            The extra states before this sample.
        """
        extra = list(extra)
        queue = ([newest_before] + extra[:self.n])[:self.n]
        return queue + extra[self.n:]

    def applied(self, newest, extra):
        """The output the plant sees now: ``u[k-n]`` (``f = 0``) or the switched value (``f > 0``)."""
        if self.frac > 0:
            return extra[-1]
        return extra[self.n - 1] if self.n else newest

    def switched(self, newest, extra):
        """Extra states at the switch instant ``t_k + f h``: ``applied = u[k-n]``."""
        extra = list(extra)
        extra[-1] = extra[self.n - 1] if self.n else newest
        return extra

    def declare(self, system, period, update, switch):
        """Declare ``update`` at offset 0 and, for ``f > 0``, ``switch`` at offset ``f h`` on ``system``."""
        system.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, update)
        if self.frac > 0:
            system.DeclarePeriodicDiscreteUpdateEvent(period, self.frac * period, switch)
