"""Friction laws for a sliding contact, written once for float, AutoDiffXd and symbolic Expression.

A law maps the sliding speed ``v`` (m/s) and its internal states ``z`` to the friction force
(N, positive when it opposes positive ``v``). The load-dependent levels -- Coulomb force ``Fc``
and static (breakaway) force ``Fs`` -- are arguments, because they come from the load case
(normal forces on the guides and the axial load on the nut, see :mod:`drakecreep.model.nut_table`);
the law owns only the shape of the curve.

Laws
----
CoulombFriction
    ``Fc tanh(v / v_reg) + Fv v`` -- regularized Coulomb plus viscous friction, no states.
StribeckFriction
    ``g(v) tanh(v / v_reg) + Fv v`` with ``g`` the Stribeck curve, no states.
LuGreFriction
    Canudas de Wit, Olsson, Astrom, Lischinsky, "A new model for control of systems with
    friction", IEEE TAC 40(3), 1995: one bristle state (stored normalized, see the class),
    ``dz/dt = v - sigma0 |v| z / g(v)``, ``F = sigma0 z + sigma1 dz/dt + Fv v``,
    ``g(v) = Fc + (Fs - Fc) exp(-|v/vs|^delta)``. Its steady state is the Stribeck curve.
"""

from dataclasses import dataclass

import numpy as np

from drakecreep.model._scalar import exp, fabs, tanh

__all__ = [
    "FrictionLaw",
    "CoulombFriction",
    "StribeckFriction",
    "LuGreFriction",
    "FRICTION_LAWS",
    "make_friction_law",
    "stribeck_curve",
]


def stribeck_curve(v, Fc, Fs, vs, exponent=2.0):
    """Magnitude of the steady sliding friction ``g(v) = Fc + (Fs - Fc) exp(-|v/vs|^delta)`` (N).

    ``delta = exponent``: 2 is the Gaussian shape of Armstrong-Helouvry (1994) and Canudas de Wit
    (1995); 0.5-1 gives the steeper drop near zero speed reported for rolling contacts.
    Works for numpy arrays and any Drake scalar type.
    """
    if exponent == 2.0:
        return Fc + (Fs - Fc) * exp(-((v / vs) ** 2))
    return Fc + (Fs - Fc) * exp(-(fabs(v / vs) ** exponent))


@dataclass(frozen=True)
class FrictionLaw:
    """Base class: shape parameters shared by every law.

    Parameters
    ----------
    viscous : float
        Viscous coefficient ``Fv`` (N s/m).
    stribeck_velocity : float
        ``vs`` (m/s), the speed over which friction falls from ``Fs`` to ``Fc``.
    stribeck_exponent : float
        ``delta`` of the Stribeck curve (see :func:`stribeck_curve`).
    regularization_velocity : float
        ``v_reg`` (m/s) of the ``tanh`` that replaces ``sign`` in the stateless laws.
    """

    viscous: float
    stribeck_velocity: float
    regularization_velocity: float
    stribeck_exponent: float = 2.0

    #: number of internal states
    num_states = 0
    name = "base"

    def initial_state(self):
        """Internal state of a contact at rest with no presliding displacement."""
        return np.zeros(self.num_states)

    def state_rates(self, v, z, Fc, Fs):
        """Time derivatives of the internal states (empty for stateless laws)."""
        return []

    def force(self, v, z, Fc, Fs):
        """Friction force (N) opposing ``v``; ``z`` the internal states."""
        raise NotImplementedError

    def steady_state_force(self, v, Fc, Fs):
        """Friction force at constant sliding speed ``v`` once internal states have settled.

        Vectorized over numpy arrays; this is the curve whose slope at the operating speed is the
        paper's ``C1`` (:func:`drakecreep.paper.creep.friction_slope`).
        """
        v = np.asarray(v, dtype=float)
        z = [np.zeros_like(v)] * self.num_states
        return self.force(v, z, Fc, Fs)

    def presliding_stiffness(self, Fc, Fs):
        """Tangent stiffness (N/m) of the contact when stuck (``inf`` for stateless laws)."""
        return np.inf


@dataclass(frozen=True)
class CoulombFriction(FrictionLaw):
    """Regularized Coulomb + viscous friction: ``Fc tanh(v/v_reg) + Fv v``."""

    name = "coulomb"

    def force(self, v, z, Fc, Fs):
        return Fc * tanh(v / self.regularization_velocity) + self.viscous * v


@dataclass(frozen=True)
class StribeckFriction(FrictionLaw):
    """Static Stribeck curve, regularized at zero speed: ``g(v) tanh(v/v_reg) + Fv v``."""

    name = "stribeck"

    def force(self, v, z, Fc, Fs):
        g = stribeck_curve(v, Fc, Fs, self.stribeck_velocity, self.stribeck_exponent)
        return g * tanh(v / self.regularization_velocity) + self.viscous * v


@dataclass(frozen=True)
class LuGreFriction(FrictionLaw):
    """LuGre dynamic friction (Canudas de Wit et al. 1995) with one bristle state.

    The state is the bristle load as a fraction of the Coulomb level, ``w = sigma0 z / Fc``
    (dimensionless, of order 1), rather than the bristle deflection ``z`` itself (about 0.3 um
    here): an integrator's error control then sees it at the same scale as the other states.
    The equations are the original ones, ``dz/dt = v - sigma0 |v| z / g(v)``,
    ``F = sigma0 z + sigma1 dz/dt + Fv v``, rewritten in ``w``.

    Parameters
    ----------
    bristle_stiffness : float
        ``sigma0`` (N/m): presliding stiffness; presliding range ``Fc / sigma0``.
    bristle_damping : float
        ``sigma1`` (N s/m): micro-damping of the bristles.
    """

    bristle_stiffness: float = 1e7
    bristle_damping: float = 1e3

    num_states = 1
    name = "lugre"

    def _g(self, v, Fc, Fs):
        return stribeck_curve(v, Fc, Fs, self.stribeck_velocity, self.stribeck_exponent)

    def deflection_rate(self, v, w, Fc, Fs):
        """``dz/dt`` (m/s) of the bristles for the normalized state ``w``.

        With no dry friction (``Fc = Fs = 0``, e.g. frictionless guides) the bristles relax
        infinitely fast, ``z = 0``: the rate is 0 and the state stays put.
        """
        if Fc <= 0.0:  # Fs = static_ratio * Fc is then 0 too
            return 0.0 * v
        return v - fabs(v) * w[0] * Fc / self._g(v, Fc, Fs)

    def state_rates(self, v, w, Fc, Fs):
        if Fc <= 0.0:
            return [0.0 * v]
        return [self.bristle_stiffness / Fc * self.deflection_rate(v, w, Fc, Fs)]

    def force(self, v, w, Fc, Fs):
        return Fc * w[0] + self.bristle_damping * self.deflection_rate(v, w, Fc, Fs) + self.viscous * v

    def steady_state_force(self, v, Fc, Fs):
        v = np.asarray(v, dtype=float)
        return self._g(v, Fc, Fs) * np.sign(v) + self.viscous * v

    def deflection(self, w, Fc):
        """Bristle deflection ``z`` (m) for the normalized state ``w``."""
        return np.asarray(w) * Fc / self.bristle_stiffness

    def presliding_stiffness(self, Fc, Fs):
        return self.bristle_stiffness


#: selectable laws by name
FRICTION_LAWS = {cls.name: cls for cls in (CoulombFriction, StribeckFriction, LuGreFriction)}


def make_friction_law(params):
    """Build the law named by ``params.law`` from :class:`drakecreep.params.FrictionParams`."""
    common = dict(
        viscous=params.viscous,
        stribeck_velocity=params.stribeck_velocity,
        regularization_velocity=params.regularization_velocity,
        stribeck_exponent=params.stribeck_exponent,
    )
    if params.law == "lugre":
        return LuGreFriction(
            **common, bristle_stiffness=params.bristle_stiffness, bristle_damping=params.bristle_damping
        )
    return FRICTION_LAWS[params.law](**common)
