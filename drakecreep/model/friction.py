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
GMSFriction
    Generalized Maxwell-slip: Al-Bender, Lampaert, Swevers, "The generalized Maxwell-slip model: a
    novel model for friction simulation and compensation", IEEE TAC 50(11), 2005. N elasto-slip
    elements in parallel, each sticking (``dF_i/dt = k_i v``) until its force reaches its share
    ``alpha_i g(v)`` of the Stribeck curve, then sliding with ``dF_i/dt = C (alpha_i sgn(v) - F_i/g(v))``;
    presliding hysteresis with non-local memory, and the Stribeck curve in steady sliding.
"""

from dataclasses import dataclass

import numpy as np

from drakecreep.model._scalar import clip, exp, fabs, tanh, where

__all__ = [
    "FrictionLaw",
    "CoulombFriction",
    "StribeckFriction",
    "LuGreFriction",
    "GMSFriction",
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
        ``v_reg`` (m/s) of the ``tanh`` that replaces ``sign`` in the stateless laws (and gives the direction
        of the asymmetries).
    coulomb_asymmetry : float
        ``a_c`` (-): the dry-friction curve ``g(v)`` (Coulomb and breakaway levels) is ``(1 + a_c)`` times its
        mean moving in +x and ``(1 - a_c)`` times it moving in -x, blended by ``tanh(v / v_reg)``; 0 symmetric.
    viscous_asymmetry : float
        ``a_v`` (-): the viscous term is ``Fv (1 + a_v tanh(v / v_reg)) v``; 0 symmetric.

    A law's internal states stay normalized by the mean level ``Fc``, so a stuck contact's force does not jump
    when its tiny presliding speed changes sign; only the sliding level ``g(v)`` that the states approach
    depends on the direction.
    """

    viscous: float
    stribeck_velocity: float
    regularization_velocity: float
    stribeck_exponent: float = 2.0
    coulomb_asymmetry: float = 0.0
    viscous_asymmetry: float = 0.0

    #: number of internal states
    num_states = 0
    name = "base"

    def _direction_factor(self, v, asymmetry):
        """``1 + asymmetry tanh(v / v_reg)``; exactly 1 when symmetric, so no ``tanh`` enters the expression (a
        product with 1.0 leaves floats, AutoDiffXd and Drake's Expression unchanged)."""
        if asymmetry == 0.0:
            return 1.0
        return 1.0 + asymmetry * tanh(v / self.regularization_velocity)

    def viscous_force(self, v):
        """Viscous friction ``Fv (1 + a_v tanh(v / v_reg)) v`` (N)."""
        return self.viscous * self._direction_factor(v, self.viscous_asymmetry) * v

    def sliding_level(self, v, Fc, Fs):
        """The dry-friction level in steady sliding at ``v``: the Stribeck curve :func:`stribeck_curve` times
        ``1 + a_c tanh(v / v_reg)`` (N, >= 0)."""
        g = stribeck_curve(v, Fc, Fs, self.stribeck_velocity, self.stribeck_exponent)
        return g * self._direction_factor(v, self.coulomb_asymmetry)

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

    def breakaway(self, Fc, Fs):
        """Largest friction force (N) the law holds at rest: ``Fs`` (the static level) for laws with one."""
        return Fs


@dataclass(frozen=True)
class CoulombFriction(FrictionLaw):
    """Regularized Coulomb + viscous friction: ``Fc tanh(v/v_reg) + Fv v``."""

    name = "coulomb"

    def force(self, v, z, Fc, Fs):
        level = Fc * self._direction_factor(v, self.coulomb_asymmetry)
        return level * tanh(v / self.regularization_velocity) + self.viscous_force(v)

    def breakaway(self, Fc, Fs):
        """``Fc``: the law has no static level above the sliding one (no friction drop, no creep)."""
        return Fc


@dataclass(frozen=True)
class StribeckFriction(FrictionLaw):
    """Static Stribeck curve, regularized at zero speed: ``g(v) tanh(v/v_reg) + Fv v``."""

    name = "stribeck"

    def force(self, v, z, Fc, Fs):
        return self.sliding_level(v, Fc, Fs) * tanh(v / self.regularization_velocity) + self.viscous_force(v)


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

    def deflection_rate(self, v, w, Fc, Fs):
        """``dz/dt`` (m/s) of the bristles for the normalized state ``w``.

        With no dry friction (``Fc = Fs = 0``, e.g. frictionless guides) the bristles relax
        infinitely fast, ``z = 0``: the rate is 0 and the state stays put.
        """
        if Fc <= 0.0:  # Fs = static_ratio * Fc is then 0 too
            return 0.0 * v
        return v - fabs(v) * w[0] * Fc / self.sliding_level(v, Fc, Fs)

    def state_rates(self, v, w, Fc, Fs):
        if Fc <= 0.0:
            return [0.0 * v]
        return [self.bristle_stiffness / Fc * self.deflection_rate(v, w, Fc, Fs)]

    def force(self, v, w, Fc, Fs):
        return Fc * w[0] + self.bristle_damping * self.deflection_rate(v, w, Fc, Fs) + self.viscous_force(v)

    def steady_state_force(self, v, Fc, Fs):
        v = np.asarray(v, dtype=float)
        return self.sliding_level(v, Fc, Fs) * np.sign(v) + self.viscous_force(v)

    def deflection(self, w, Fc):
        """Bristle deflection ``z`` (m) for the normalized state ``w``."""
        return np.asarray(w) * Fc / self.bristle_stiffness

    def presliding_stiffness(self, Fc, Fs):
        return self.bristle_stiffness


@dataclass(frozen=True)
class GMSFriction(FrictionLaw):
    """Generalized Maxwell-slip friction (Al-Bender, Lampaert, Swevers, IEEE TAC 50(11), 2005), N elements.

    Element ``i`` is a spring ``k_i`` ending in a slip block. Its force ``F_i`` (state, stored as
    ``w_i = F_i / Fc``)

    * *sticks* -- ``dF_i/dt = k_i v`` -- while ``|F_i| < alpha_i g(v)`` or while the motion unloads it;
    * *slides* once it reaches ``alpha_i g(v)`` and is pushed further:
      ``dF_i/dt = C (alpha_i sgn(v) - F_i / g(v))`` (the paper's slip law, the sign taken with ``v``
      as in its stated intent: ``F_i`` is attracted to ``alpha_i g(v) sgn(v)`` at the rate ``C``).

    ``F = sum F_i + sigma1 sum(dF_i/dt) / sigma0 + Fv v``. In steady sliding every element sits at its
    limit: ``F = g(v) sgn(v) + Fv v``, the Stribeck curve, as LuGre. Unlike LuGre, a stuck element
    does not creep (LuGre's ``dz/dt = v - sigma0 |v| z / g`` lets the bristles slide at any load),
    and the presliding force-displacement curve is a hysteresis loop with non-local memory
    (Masing's rules: after a reversal the curve follows twice the virgin curve).

    Element parameters: equal shares ``alpha_i = 1/N``, stiffnesses ``k_i = sigma0 / (i H_N)``
    (``H_N`` the N-th harmonic number): their sum is LuGre's presliding stiffness ``sigma0`` and the
    elements let go one after another at displacements ``i x1`` with ``x1 = Fs H_N / (N sigma0)``, the
    last at ``H_N Fs / sigma0`` (about 2x LuGre's presliding range for N = 4). The switch from stick to
    slip is blended over the last ``blend`` share of each element's limit (0.02: a continuous
    right-hand side for the variable-step integrators; the steady state is exact).

    Parameters
    ----------
    bristle_stiffness : float
        ``sigma0 = sum k_i`` (N/m): initial presliding stiffness.
    bristle_damping : float
        ``sigma1`` (N s/m): micro-damping on the presliding rate ``sum(dF_i/dt) / sigma0``.
    elements : int
        N, the number of Maxwell-slip elements (>= 1).
    attraction : float
        ``C`` (N/s): how fast a sliding element's force follows ``alpha_i g(v)``; ``g / C`` is the
        frictional memory time.
    blend : float
        Share of an element's limit over which stick turns into slip (numerical, 0 < blend < 1).
    """

    bristle_stiffness: float = 1e7
    bristle_damping: float = 1e3
    elements: int = 4
    attraction: float = 1e4
    blend: float = 0.02

    name = "gms"

    def __post_init__(self):
        if isinstance(self.elements, bool) or not isinstance(self.elements, int) or self.elements < 1:
            raise ValueError(f"GMSFriction.elements must be an integer >= 1, got {self.elements!r}")
        if not 0.0 < self.blend < 1.0:
            raise ValueError(f"GMSFriction.blend must be in (0, 1), got {self.blend!r}")

    @property
    def num_states(self):
        """One state per element."""
        return self.elements

    @property
    def shares(self):
        """``alpha_i`` (sum 1)."""
        return np.full(self.elements, 1.0 / self.elements)

    @property
    def stiffnesses(self):
        """``k_i`` (N/m), summing to ``sigma0``."""
        i = np.arange(1, self.elements + 1)
        return self.bristle_stiffness / (i * np.sum(1.0 / i))

    def force_rates(self, v, w, Fc, Fs):
        """``dF_i/dt`` (N/s) of the elements for the normalized states ``w``."""
        if Fc <= 0.0:
            return [0.0 * v for _ in range(self.elements)]
        g = self.sliding_level(v, Fc, Fs)
        rates = []
        for alpha, k, wi in zip(self.shares, self.stiffnesses, w):
            F = Fc * wi
            limit = alpha * g
            loaded = where(F * v > 0.0, 1.0, 0.0)  # the motion pushes the element further
            phi = loaded * clip((fabs(F) / limit - (1.0 - self.blend)) / self.blend, 0.0, 1.0)
            sign = where(F > 0.0, 1.0, -1.0)
            slip = self.attraction * (alpha * sign - F / g)
            rates.append((1.0 - phi) * (float(k) * v) + phi * slip)
        return rates

    def state_rates(self, v, w, Fc, Fs):
        if Fc <= 0.0:
            return [0.0 * v for _ in range(self.elements)]
        return [r / Fc for r in self.force_rates(v, w, Fc, Fs)]

    def force(self, v, w, Fc, Fs):
        rates = self.force_rates(v, w, Fc, Fs)
        total, rate = 0.0, 0.0
        for wi, r in zip(w, rates):
            total = total + Fc * wi
            rate = rate + r
        return total + self.bristle_damping * rate / self.bristle_stiffness + self.viscous_force(v)

    def steady_state_force(self, v, Fc, Fs):
        v = np.asarray(v, dtype=float)
        return self.sliding_level(v, Fc, Fs) * np.sign(v) + self.viscous_force(v)

    def presliding_stiffness(self, Fc, Fs):
        return self.bristle_stiffness


#: selectable laws by name
FRICTION_LAWS = {cls.name: cls for cls in (CoulombFriction, StribeckFriction, LuGreFriction, GMSFriction)}


def make_friction_law(params):
    """Build the law named by ``params.law`` from :class:`drakecreep.params.FrictionParams`."""
    common = dict(
        viscous=params.viscous,
        stribeck_velocity=params.stribeck_velocity,
        regularization_velocity=params.regularization_velocity,
        stribeck_exponent=params.stribeck_exponent,
        coulomb_asymmetry=params.coulomb_asymmetry,
        viscous_asymmetry=params.viscous_asymmetry,
    )
    if params.law == "lugre":
        return LuGreFriction(
            **common, bristle_stiffness=params.bristle_stiffness, bristle_damping=params.bristle_damping
        )
    if params.law == "gms":
        return GMSFriction(
            **common, bristle_stiffness=params.bristle_stiffness, bristle_damping=params.bristle_damping,
            elements=params.gms_elements, attraction=params.gms_attraction,
        )
    return FRICTION_LAWS[params.law](**common)
