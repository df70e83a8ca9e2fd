"""Creep (stick-slip) theory of the seed paper, Section 2, equations 1-11.

The mechanism (paper Fig. 2): a driving part moves at constant speed ``v`` and pushes the driven part
(mass ``M``) through a spring ``K`` and a damper ``C``; friction ``F(v)`` acts on the driven part.
Linearised around steady sliding, the friction slope ``C1 = dF/dv`` adds to the damping (equation 2):

    M x'' + (C + C1) x' + K x = 0

A falling friction characteristic (``C1 < 0``) eats into the damping, and steady sliding is lost when
the friction drop ``Fs - Fd`` is large against the momentum the spring can supply. The paper's boundary is

    D0 = sqrt(4 pi zeta)       (eq. 10),   D = (Fs - Fd) / (v sqrt(K M))     (eq. 6)
    v0 = (Fs - Fd) / sqrt(2 pi (C + C1) sqrt(K M))                             (eq. 11)

and the driven part creeps when ``v < v0`` (equivalently ``D > D0``).

Everything here is SI (N, m, s, kg) and vectorised with numpy broadcasting. Friction laws are *not*
defined here: any callable ``F(v)`` returning the steady-state friction force at sliding speed ``v``
will do (see :func:`friction_slope`), e.g. ``lambda v: law.steady_state_force(v, Fc, Fs)`` with a law
from :mod:`drakecreep.model.friction`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from drakecreep.errors import InputError

__all__ = [
    "natural_frequency",
    "damping_ratio",
    "friction_drop_ratio",
    "critical_D0",
    "critical_speed",
    "creep_predicted",
    "friction_slope",
    "critical_speed_self_consistent",
    "critical_speed_of",
    "CreepCondition",
    "creep_condition",
]

FrictionLaw = Callable[[np.ndarray], np.ndarray]


def natural_frequency(K, M):
    """Undamped natural frequency ``omega_n = sqrt(K / M)`` of the driven part (paper eq. 3).

    Parameters
    ----------
    K : array_like
        Drive stiffness, N/m (> 0).
    M : array_like
        Driven mass, kg (> 0).

    Returns
    -------
    ndarray or float
        Natural frequency in rad/s.
    """
    K = np.asarray(K, dtype=float)
    M = np.asarray(M, dtype=float)
    return np.sqrt(K / M)


def damping_ratio(K, M, C, C1=0.0):
    """Effective damping ratio ``zeta = (C + C1) / (2 sqrt(K M))`` (paper eq. 3).

    Parameters
    ----------
    K : array_like
        Drive stiffness, N/m.
    M : array_like
        Driven mass, kg.
    C : array_like
        Structural (viscous) damping of the drive, N s/m.
    C1 : array_like, optional
        Friction slope ``dF/dv`` at the operating speed, N s/m; negative on the falling
        (Stribeck) branch. Derive it with :func:`friction_slope`.

    Returns
    -------
    ndarray or float
        Damping ratio (dimensionless). Negative when the friction slope outweighs the damping.
    """
    return (np.asarray(C, dtype=float) + np.asarray(C1, dtype=float)) / (
        2.0 * np.sqrt(np.asarray(K, dtype=float) * np.asarray(M, dtype=float))
    )


def friction_drop_ratio(Fs, Fd, v, K, M):
    """Dimensionless friction drop ``D = (Fs - Fd) / (v sqrt(K M))`` (paper eq. 6).

    Parameters
    ----------
    Fs, Fd : array_like
        Static (breakaway) and dynamic friction force, N.
    v : array_like
        Feed speed of the driving part, m/s (> 0).
    K : array_like
        Drive stiffness, N/m.
    M : array_like
        Driven mass, kg.

    Returns
    -------
    ndarray or float
        ``D`` (dimensionless).
    """
    Fs, Fd, v, K, M = (np.asarray(a, dtype=float) for a in (Fs, Fd, v, K, M))
    return (Fs - Fd) / (v * np.sqrt(K * M))


def critical_D0(zeta):
    """Critical friction-drop ratio ``D0 = sqrt(4 pi zeta)`` (paper eq. 10).

    Parameters
    ----------
    zeta : array_like
        Effective damping ratio ``(C + C1) / (2 sqrt(K M))``.

    Returns
    -------
    ndarray or float
        ``D0``. ``nan`` where ``zeta < 0``: with negative effective damping the linearised steady
        sliding is unstable for any friction drop, so no finite boundary exists (creep at any
        speed; :func:`creep_predicted` returns True there).
    """
    zeta = np.asarray(zeta, dtype=float)
    out = np.full(zeta.shape, np.nan)
    ok = zeta >= 0.0
    out[ok] = np.sqrt(4.0 * np.pi * zeta[ok])
    return out[()] if out.ndim == 0 else out


def critical_speed(Fs, Fd, K, M, C, C1=0.0):
    """Critical feed speed ``v0 = (Fs - Fd) / sqrt(2 pi (C + C1) sqrt(K M))`` (paper eq. 11).

    Below ``v0`` the driven part creeps (stick-slip); above it steady sliding is kept. This is the
    same as ``D(v0) = D0`` with :func:`friction_drop_ratio` and :func:`critical_D0`.

    Parameters
    ----------
    Fs, Fd : array_like
        Static and dynamic friction force, N.
    K : array_like
        Drive stiffness, N/m.
    M : array_like
        Driven mass, kg.
    C : array_like
        Structural damping, N s/m.
    C1 : array_like, optional
        Friction slope at the operating speed, N s/m (see :func:`friction_slope`).

    Returns
    -------
    ndarray or float
        ``v0`` in m/s. ``nan`` where ``C + C1 <= 0``: the formula does not apply there because the
        effective damping is zero or negative, i.e. steady sliding is unstable at *every* speed
        (the limit of ``v0`` as ``C + C1 -> 0+`` is infinite). Use :func:`creep_predicted` for a
        yes/no answer that handles this case.
    """
    Fs, Fd, K, M, C, C1 = (np.asarray(a, dtype=float) for a in (Fs, Fd, K, M, C, C1))
    c_eff = np.broadcast_to(C + C1, np.broadcast_shapes(Fs.shape, Fd.shape, K.shape, M.shape,
                                                         C.shape, C1.shape))
    denom_sq = 2.0 * np.pi * c_eff * np.sqrt(K * M)
    out = np.full(c_eff.shape, np.nan)
    ok = c_eff > 0.0
    drop = np.broadcast_to(Fs - Fd, c_eff.shape)
    out[ok] = drop[ok] / np.sqrt(denom_sq[ok])
    return out[()] if out.ndim == 0 else out


def creep_predicted(v, Fs, Fd, K, M, C, C1=0.0):
    """Whether the paper's criterion predicts creep at feed speed ``v``.

    Creep when ``D > D0`` (equivalently ``v < v0``), and always when ``C + C1 <= 0`` (negative
    effective damping: self-excited oscillation grows regardless of the friction drop).

    Parameters
    ----------
    v : array_like
        Feed speed, m/s (> 0).
    Fs, Fd, K, M, C, C1 : array_like
        As in :func:`critical_speed`.

    Returns
    -------
    ndarray of bool or bool
    """
    zeta = damping_ratio(K, M, C, C1)
    D = friction_drop_ratio(Fs, Fd, v, K, M)
    with np.errstate(invalid="ignore"):
        out = np.where(zeta <= 0.0, True, D > critical_D0(np.maximum(zeta, 0.0)))
    return out[()] if np.ndim(out) == 0 else out


def friction_slope(law: FrictionLaw, v, step=None, derivative: FrictionLaw | None = None):
    """Friction slope ``C1 = dF/dv`` of a steady-state friction law at sliding speed ``v``.

    Parameters
    ----------
    law : callable
        ``F(v)``: steady-state friction force (N) at sliding speed ``v`` (m/s); must accept numpy
        arrays. Any law (Coulomb + Stribeck + viscous, a measured table through ``np.interp``, ...).
    v : array_like
        Operating sliding speed(s), m/s, nonzero.
    step : float, optional
        Central-difference half step, m/s. Default ``1e-3 * |v|`` (relative, so the step scales with
        the Stribeck velocity range of interest), never crossing ``v = 0`` where laws with ``sign(v)``
        jump. Truncation error is ``O(step**2)``.
    derivative : callable, optional
        Analytic ``dF/dv``; when given it is used instead of the finite difference.

    Returns
    -------
    ndarray or float
        ``C1`` in N s/m (negative on a falling Stribeck branch).
    """
    v = np.asarray(v, dtype=float)
    if np.any(v == 0.0) or not np.all(np.isfinite(v)):
        raise InputError("v", v.tolist(), "finite and nonzero sliding speed")
    if derivative is not None:
        out = np.asarray(derivative(v), dtype=float)
        return out[()] if out.ndim == 0 else out
    h = 1e-3 * np.abs(v) if step is None else np.minimum(float(step), 0.5 * np.abs(v))
    out = (np.asarray(law(v + h), dtype=float) - np.asarray(law(v - h), dtype=float)) / (2.0 * h)
    return out[()] if out.ndim == 0 else out


def critical_speed_self_consistent(law: FrictionLaw, Fs, Fd, K, M, C, v_bracket=(1e-7, 1.0)):
    """Critical speed with the friction slope ``C1`` taken from the friction law *at* that speed.

    Equation 11 uses ``C1`` "at the operating speed", but the operating speed that matters is
    ``v0`` itself. This solves ``v = v0(Fs, Fd, K, M, C, F'(v))`` for ``v`` with
    :func:`scipy.optimize.brentq`. ``Fs - Fd`` stays the full static-to-dynamic drop, as in the
    paper. Scalars only.

    Parameters
    ----------
    law : callable
        Steady-state friction ``F(v)`` (N) for ``v > 0`` (m/s).
    Fs, Fd : float
        Static (breakaway) and dynamic (Coulomb) friction, N.
    K, M, C : float
        Stiffness (N/m), mass (kg), structural damping (N s/m).
    v_bracket : (float, float)
        Search interval for the speed, m/s.

    Returns
    -------
    float
        Self-consistent critical speed in m/s, or ``nan`` when no root lies in ``v_bracket`` (e.g. the
        drive creeps everywhere in the interval because ``C + C1 <= 0`` there, or nowhere).
    """

    def gap(v):
        v0 = critical_speed(Fs, Fd, K, M, C, friction_slope(law, v))
        # nan means C + C1 <= 0 at v: creep at that speed, as if v0 were infinite.
        return 1.0 if np.isnan(v0) else float(v0 - v)

    lo, hi = v_bracket
    if gap(lo) * gap(hi) > 0.0:
        return float("nan")
    return float(brentq(gap, lo, hi, xtol=1e-12, rtol=1e-10))


def critical_speed_of(drive):
    """Eq. 11's critical speed ``v0`` (m/s) of a lumped drive, ``C1`` taken at ``v0`` itself.

    Parameters
    ----------
    drive : drakecreep.model.lumped.LumpedDrive
        ``lumped(params, load_case)``: K, C, M, Fd = Fc, Fs and the friction law's steady-state curve.

    Returns
    -------
    float
        ``nan`` where no boundary exists (see :func:`critical_speed_self_consistent`).
    """
    return float(critical_speed_self_consistent(drive.steady_friction, drive.breakaway, drive.coulomb,
                                                drive.stiffness, drive.mass, drive.damping))


@dataclass(frozen=True)
class CreepCondition:
    """The paper's creep condition of a lumped drive at one feed (SI units; ``nan`` where undefined).

    Attributes
    ----------
    feed : float
        Sliding speed ``v`` (m/s).
    friction_slope : float
        ``C1 = dF/dv`` of the drive's steady friction curve at ``v`` (N s/m).
    natural_frequency : float
        ``sqrt(K / M)`` (rad/s).
    zeta, D, D0 : float
        Eq. 4's damping ratio with ``C1``, eq. 6's friction-drop ratio and eq. 10's ``sqrt(4 pi zeta)``.
    critical_speed : float
        Eq. 11's ``v0`` with ``C1`` taken at ``v`` (m/s).
    critical_speed_self_consistent : float
        ``v0`` with ``C1`` taken at ``v0`` itself (:func:`critical_speed_of`, m/s).
    creep : bool
        ``v < v0`` (``D > D0``), eq. 11 at ``v``.
    """

    feed: float
    friction_slope: float
    natural_frequency: float
    zeta: float
    D: float
    D0: float
    critical_speed: float
    critical_speed_self_consistent: float
    creep: bool


def creep_condition(drive, v):
    """Eqs. 3-11 for a lumped drive at feed ``v``: what ``drakecreep critical`` prints and the loop report shows.

    Parameters
    ----------
    drive : drakecreep.model.lumped.LumpedDrive
        ``lumped(params, load_case)``: the friction the model applies to the moving mass (with the ball nut's
        drag on the screw, the guides' alone), K, C and M of the chain.
    v : float
        Feed (m/s, > 0).

    Returns
    -------
    CreepCondition
    """
    K, M, C, Fs, Fd = drive.stiffness, drive.mass, drive.damping, drive.breakaway, drive.coulomb
    c1 = float(friction_slope(drive.steady_friction, v))
    zeta = float(damping_ratio(K, M, C, c1))
    return CreepCondition(
        feed=float(v), friction_slope=c1, natural_frequency=float(natural_frequency(K, M)), zeta=zeta,
        D=float(friction_drop_ratio(Fs, Fd, v, K, M)), D0=float(critical_D0(zeta)),
        critical_speed=float(critical_speed(Fs, Fd, K, M, C, c1)),
        critical_speed_self_consistent=critical_speed_of(drive),
        creep=bool(creep_predicted(v, Fs, Fd, K, M, C, c1)))
