"""Scalar-type-generic helpers so one model source serves float, AutoDiffXd and symbolic Expression.

Python ``if`` on a state value breaks the symbolic path; these helpers branch with
``if_then_else`` when the operands are symbolic and with a plain conditional otherwise.
"""

import numpy as np
import pydrake.math as dmath
from pydrake.symbolic import Expression, Formula, Variable, if_then_else

__all__ = ["is_symbolic", "where", "clip", "smin", "smax", "tanh", "exp", "fabs", "floor", "vector"]


def is_symbolic(*values):
    """True if any value is a Drake symbolic ``Expression``, ``Variable`` or ``Formula``."""
    return any(isinstance(v, (Expression, Variable, Formula)) for v in values)


def _expr(v):
    return v if isinstance(v, Expression) else Expression(v)


def where(condition, a, b):
    """``a`` if ``condition`` else ``b``, for float, AutoDiffXd and Expression operands."""
    if isinstance(condition, Formula):
        return if_then_else(condition, _expr(a), _expr(b))
    return a if bool(condition) else b


def smin(a, b):
    """Minimum of two scalars of any Drake scalar type."""
    if is_symbolic(a, b):
        return dmath.min(_expr(a), _expr(b))
    return a if a <= b else b


def smax(a, b):
    """Maximum of two scalars of any Drake scalar type."""
    if is_symbolic(a, b):
        return dmath.max(_expr(a), _expr(b))
    return a if a >= b else b


def clip(x, lo, hi):
    """Saturate ``x`` to ``[lo, hi]`` for any Drake scalar type (and numpy arrays of floats)."""
    if isinstance(x, np.ndarray) and _numeric(lo) and _numeric(hi):
        return np.clip(x, lo, hi)
    return smin(smax(x, lo), hi)


def _numeric(x):
    return isinstance(x, (float, int, np.ndarray, np.floating))


def tanh(x):
    """Hyperbolic tangent of a float, numpy array, AutoDiffXd or Expression.

    Drake scalars go to ``pydrake.math`` directly rather than through a numpy object-dtype ufunc,
    whose floating-point status check reports harmless intermediate NaNs inside Drake as warnings.
    """
    return np.tanh(x) if _numeric(x) else dmath.tanh(x)


def exp(x):
    """Exponential of a float, numpy array, AutoDiffXd or Expression (see :func:`tanh`)."""
    return np.exp(x) if _numeric(x) else dmath.exp(x)


def fabs(x):
    """Absolute value of a float, numpy array, AutoDiffXd or Expression (see :func:`tanh`)."""
    return np.abs(x) if _numeric(x) else dmath.abs(x)


def floor(x):
    """Floor of a float, numpy array, AutoDiffXd (value only) or Expression (see :func:`tanh`)."""
    return np.floor(x) if _numeric(x) else dmath.floor(x)


def vector(values):
    """A numpy vector of Drake scalars: float dtype for plain numbers, object dtype otherwise."""
    if all(isinstance(v, (float, int, np.floating, np.integer)) for v in values):
        return np.array(values, dtype=float)
    return np.array(values, dtype=object)
