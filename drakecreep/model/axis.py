"""A feed axis for replaying measured runs: rigid or two-mass, friction with identifiable parameters.

Rigid (``flexible=False``), state ``[x, v]``::

    M dv/dt = F + r(x, t) - f(v, x, t) - offset

Two-mass (``flexible=True``), state ``[x_m, v_m, x_t, v_t]``: the motor side (rotor, coupling and screw
reflected to the table, ``m_m = motor_mass_fraction * M``) and the table (``m_t = M - m_m``) joined by
the axial stiffness ``k`` and damping ``c`` of the screw chain::

    m_m dv_m/dt = F + r(x_m, t) - k (x_m - x_t) - c (v_m - v_t)
    m_t dv_t/dt = k (x_m - x_t) + c (v_m - v_t) - f(v_t) - offset

with the friction (regularized by ``s(v) = tanh(v / v_reg)``, as :mod:`drakecreep.model.friction`)::

    f(v) = L(x, t) [s(v) (Fc + dFc s(v) + (Fs - Fc) exp(-(v/vs)^2)) + (Fv + dFv s(v)) v]
    L(x, t) = 1 + fc cos(2 pi x / Lf) + fs sin(2 pi x / Lf) + m(x) + drift t   (position-dependent, thermal)

with ``m(x)`` a smooth map along the travel (:func:`friction_map`: four ``tanh`` steps). The Coulomb level
``Fc`` rises by ``mu |F_ax|`` with the axial load through the nut (``load_friction_coefficient`` ``mu``,
dimensionless, as in :class:`drakecreep.params.NutParams`; ``F_ax`` the screw's spring force, or on the rigid
axis what the nut passes on to the table, :func:`nut_load`). The drive applies ``F / sqrt(1 + (c F)^2)`` of the
commanded force ``F`` (``inverse_drive_limit`` ``c`` [1/N], 0 by default: a linear drive; :func:`applied_force`);

and a ripple force on the motor side (cogging or a bearing's force at the position period ``Lp``,
plus a fixed time frequency ``f_r``)::

    r(x_m, t) = pc cos(2 pi x_m / Lp) + ps sin(2 pi x_m / Lp) + tc cos(2 pi f_r t) + ts sin(2 pi f_r t)

A lead error moves the nut ``e(x_m)`` ahead of where the screw's angle puts it (:func:`lead_error`: the first
two harmonics of the ``lead``). On the two-mass axis the spring's motor end is at ``x_m + e(x_m)`` (exact
kinematics). On the rigid axis the table is at ``x + e(x)`` and moves at ``g v`` with the gearing
``g = 1 + e'(x)``; the motor side ``m_m = motor_mass_fraction M`` stays at ``x`` (Lagrange's equation of the
constraint, the rigid limit of the two-mass axis)::

    (m_m + m_t g^2) dv/dt = F + r - m_t g e''(x) v^2 - g (f(g v, x + e, t) + offset)

``m_t = M - m_m``. Two pushes at the lead's period: the table's extra inertial force ``m_t e'' v^2``
(:func:`lead_error_force`), which grows with the square of the speed, and the nut's force geared by ``g``, which
at slow speed is mostly friction (``e'`` is 1-3 % for 4-12 um on a 2.5-10 mm lead; 0.4 N at 10 mm/s on the
benchmark's truths, docs/gap_benchmark.md, 3ce).

With bristles (``bristles=True``, ``bristle_stiffness`` ``sigma0 > 0``) the Coulomb-Stribeck part is the LuGre
law instead (Canudas de Wit et al. 1995): a bristle deflection ``z`` is appended to the state, and::

    dz/dt = v - sigma0 |v| z / (b g(v)),     g(v) = Fc + dFc s(v) + (Fs - Fc) exp(-(v/vs)^2)
    f     = L(x, t) [sigma0 z + sigma1 dz/dt + (1 - b) g(v) s(v) + (Fv + dFv s(v)) v],
    sigma1 = 2 zeta sqrt(sigma0 m_t)

so the axis sticks (the bristles hold any force below ``b g(0)`` with a presliding displacement
``|F| / sigma0``) where the regularized law creeps at ``v_reg atanh(F / Fc)``. In steady sliding both laws
give ``g(v) sign(v) + (Fv + dFv s) v``. ``zeta`` is ``bristle_damping_ratio`` (the bristle mode on the
table mass; 1 = critically damped, an assumption: the damping is not identifiable at 1 kHz). ``b`` is
``bristle_share``, the share of the Coulomb-Stribeck level that sticks (default 1): the rest is the regularized
law, which holds nothing at standstill. A drive's friction is several sources (the motor's bearings and seal,
the screw's support bearings, the nut, the guideways) and only some of them hold a presliding deflection the way
a guideway's does: the benchmark's truth puts 20-40 % of it on the motor side as a regularized law.

``dFc``, ``dFv`` make it asymmetric (``Fc + dFc`` forward, ``Fc - dFc`` backward). ``F`` is the drive
force plus any external force (input ``force``, N). The offset is the constant force of the IDIM
model (``tau = M ddq + Fv dq + Fc sign(dq) + offset``, :mod:`drakecreep.gap.idim`).

Every coefficient is a Drake *numeric parameter* (:data:`AXIS_PARAMETERS`): an identification sets
them in the context (:func:`set_axis_parameters`) and simulates the same diagram again, without a
rebuild.
"""

import math
import sys

import numpy as np
from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.errors import InputError
from drakecreep.model._scalar import clip, exp, fabs, tanh, vector
from drakecreep.model.disturbances import cos, sin

__all__ = ["AXIS_PARAMETERS", "AXIS_UNITS", "MeasuredAxis", "MeasuredAxis_", "axis_parameters",
           "set_axis_parameters", "axis_friction", "applied_force", "saturating", "unsaturated", "nut_load",
           "friction_map", "FRICTION_MAP",
           "bristle_rates", "has_bristles", "LEAD_ERROR", "lead_error", "lead_error_force", "lead_error_drive",
           "POSITION_RIPPLE", "axis_ripple"]

#: numeric parameters, in order, with their default values
AXIS_PARAMETERS = {
    "mass": 1.0,
    "viscous": 0.0,
    "viscous_asym": 0.0,
    "coulomb": 0.0,
    "coulomb_asym": 0.0,
    "offset": 0.0,
    "load_friction_coefficient": 0.0,
    "stribeck_extra": 0.0,
    "stribeck_velocity": 1e-3,
    "regularization_velocity": 1e-3,
    "motor_mass_fraction": 0.2,
    "stiffness": 1e8,
    "damping": 0.0,
    "position_ripple_cos": 0.0,
    "position_ripple_sin": 0.0,
    "position_ripple_2_cos": 0.0,
    "position_ripple_2_sin": 0.0,
    "position_period": 2.5e-3,
    "friction_ripple_cos": 0.0,
    "friction_ripple_sin": 0.0,
    "friction_period": 0.1,
    "friction_map_0": 0.0,
    "friction_map_1": 0.0,
    "friction_map_2": 0.0,
    "friction_map_3": 0.0,
    "friction_map_start": 0.0,
    "friction_map_end": 1.0,
    "lead_error_cos": 0.0,
    "lead_error_sin": 0.0,
    "lead_error_2_cos": 0.0,
    "lead_error_2_sin": 0.0,
    "lead": 5e-3,
    "time_ripple_cos": 0.0,
    "time_ripple_sin": 0.0,
    "ripple_frequency": 50.0,
    "friction_drift": 0.0,
    "bristle_stiffness": 0.0,
    "bristle_damping_ratio": 1.0,
    "inverse_drive_limit": 0.0,
    "bristle_share": 1.0,
}
AXIS_UNITS = {
    "mass": "kg", "viscous": "N s/m", "viscous_asym": "N s/m", "coulomb": "N", "coulomb_asym": "N", "offset": "N",
    "load_friction_coefficient": "-",
    "stribeck_extra": "N", "stribeck_velocity": "m/s", "regularization_velocity": "m/s",
    "motor_mass_fraction": "-", "stiffness": "N/m", "damping": "N s/m",
    "position_ripple_cos": "N", "position_ripple_sin": "N", "position_ripple_2_cos": "N", "position_ripple_2_sin": "N",
    "position_period": "m",
    "friction_ripple_cos": "-", "friction_ripple_sin": "-", "friction_period": "m",
    "friction_map_0": "-", "friction_map_1": "-", "friction_map_2": "-", "friction_map_3": "-",
    "friction_map_start": "m", "friction_map_end": "m",
    "lead_error_cos": "m", "lead_error_sin": "m", "lead_error_2_cos": "m", "lead_error_2_sin": "m", "lead": "m",
    "time_ripple_cos": "N", "time_ripple_sin": "N", "ripple_frequency": "Hz", "friction_drift": "1/s",
    "bristle_stiffness": "N/m", "bristle_damping_ratio": "-", "inverse_drive_limit": "1/N", "bristle_share": "-",
}
_POSITIVE = ("mass", "stribeck_velocity", "regularization_velocity", "stiffness", "position_period",
             "friction_period", "ripple_frequency", "lead")
_NAMES = tuple(AXIS_PARAMETERS)


def axis_parameters(**values):
    """Validated parameter vector (defaults of :data:`AXIS_PARAMETERS` for the names not given)."""
    out = dict(AXIS_PARAMETERS)
    for name, value in values.items():
        if name not in out:
            raise InputError(f"axis.{name}", value, "one of " + ", ".join(_NAMES))
        try:
            x = float(value)
        except (TypeError, ValueError):
            raise InputError(f"axis.{name}", value, "a finite number") from None
        if not math.isfinite(x) or (name in _POSITIVE and x <= 0):
            raise InputError(f"axis.{name}", value, "a finite number" + (" > 0" if name in _POSITIVE else ""))
        out[name] = x
    if out["bristle_stiffness"] < 0:
        raise InputError("axis.bristle_stiffness", out["bristle_stiffness"], "a number >= 0 N/m (0: no bristles)")
    if out["bristle_damping_ratio"] < 0:
        raise InputError("axis.bristle_damping_ratio", out["bristle_damping_ratio"], "a number >= 0")
    if not out["friction_map_end"] > out["friction_map_start"]:
        raise InputError("axis.friction_map_end", out["friction_map_end"],
                         f"a position > friction_map_start ({out['friction_map_start']} m)")
    if out["inverse_drive_limit"] < 0:
        raise InputError("axis.inverse_drive_limit", out["inverse_drive_limit"],
                         "a number >= 0 1/N (0: a linear drive)")
    if not 0 < out["bristle_share"] <= 1:
        raise InputError("axis.bristle_share", out["bristle_share"], "a number in (0, 1] (1: all of it sticks)")
    if not 0 < out["motor_mass_fraction"] < 1:
        raise InputError("axis.motor_mass_fraction", out["motor_mass_fraction"], "a number in (0, 1)")
    return np.array([out[n] for n in _NAMES])


def _off(coefficient):
    """True for a plain-number coefficient of 0 (a term switched off): its term is left out rather than
    multiplied by 0, so the float path does no work for it (a symbolic 0 simplifies away by itself)."""
    return isinstance(coefficient, float) and coefficient == 0.0


def axis_friction(v, p, x=0.0, t=0.0, load=0.0):
    """Friction force [N] opposing ``v`` at position ``x`` [m] and time ``t`` [s] under the axial load ``load``
    [N] through the nut for a parameter vector ``p`` (order of :data:`AXIS_PARAMETERS`): the regularized law,
    which is also the steady sliding friction of the LuGre bristles (:func:`bristle_rates`)."""
    P = dict(zip(_NAMES, p))
    g, s = _sliding_level(P, v, load)
    return _level(P, x, t) * (s * g + (P["viscous"] + P["viscous_asym"] * s) * v)


#: smooth steps of the friction map (``friction_map_0`` .. ``_3``)
FRICTION_MAP = tuple(f"friction_map_{k}" for k in range(4))


def _level(P, x, t):
    phase = 2.0 * math.pi * x / P["friction_period"]
    return (1.0 + P["friction_ripple_cos"] * cos(phase) + P["friction_ripple_sin"] * sin(phase)
            + friction_map(P, x) + P["friction_drift"] * t)


def friction_map(P, x):
    """The smooth position-dependent part of the friction level ``L`` (``P``: parameters by name)::

        m(x) = sum_k a_k tanh((x - c_k) / w),   c_k = x0 + (k + 1/2) w,   w = (x1 - x0) / K

    ``K`` = 4 smooth steps spread evenly over ``[x0, x1]`` (``friction_map_start``, ``friction_map_end``: the
    travel the training runs cover, set by the diagnosis), amplitudes ``a_k`` (``friction_map_k``). Any smooth
    level along the travel at that resolution (a ramp, a bump, a worn stretch), linear in the amplitudes; outside
    ``[x0, x1]`` it stays at its edge values (no extrapolated trend). The steps are odd about their centres, so
    a constant level stays the Coulomb and viscous levels' business.
    """
    x0, x1 = P["friction_map_start"], P["friction_map_end"]
    w = (x1 - x0) / len(FRICTION_MAP)
    out = 0.0
    if all(_off(P[name]) for name in FRICTION_MAP):
        return out
    # the edge values outside the travel: the outer steps are only half risen at x0 and x1 (tanh 0.5), and
    # unclipped they would go on rising beyond it by half their amplitude (an extrapolated trend)
    x = clip(x, x0, x1)
    for k, name in enumerate(FRICTION_MAP):
        if _off(P[name]):
            continue  # off (the default): nothing to evaluate
        out = out + P[name] * tanh((x - (x0 + (k + 0.5) * w)) / w)
    return out


def _sliding_level(P, v, load=0.0):
    """``g(v)``: the Coulomb-Stribeck level (with its asymmetry) the bristles relax to; it rises by
    ``load_friction_coefficient`` times the axial load's magnitude (a ball nut's rolling friction grows with
    the load on its balls: the nut's preload is in the Coulomb level, a working load adds to it)."""
    s = tanh(v / P["regularization_velocity"])
    w = v / P["stribeck_velocity"]
    g = P["coulomb"] + P["coulomb_asym"] * s + P["stribeck_extra"] * exp(-w * w)
    mu = P["load_friction_coefficient"]
    if not _off(mu):  # off (the default): no |load| term
        g = g + mu * fabs(load)
    return g, s


def has_bristles(p):
    """True when the parameter vector ``p`` switches the LuGre bristles on (``bristle_stiffness > 0``)."""
    return float(p[_NAMES.index("bristle_stiffness")]) > 0.0


def bristle_rates(v, z, p, table_mass, load=0.0):
    """``(dz/dt, friction)`` of the LuGre bristles at table speed ``v`` [m/s] and deflection ``z`` [m] under the
    axial load ``load`` [N] for the parameter vector ``p``, without the position/time level ``L``
    (:mod:`drakecreep.model.axis` docstring).

    ``dz/dt = v - a(v) z`` is linear in ``z`` with ``a = sigma0 |v| / (b |g0(v)|)``: a sampled replay advances it
    with its exact solution over a step (``drakecreep.gap.drake_replay.SampledReplay``). With a ``bristle_share``
    ``b < 1`` the bristles carry ``b g0`` and the regularized ``(1 - b) g0 s(v)`` the rest. A load-dependent
    friction scales that force, ``(1 + mu |load| / |g0|) (sigma0 z + sigma1 dz/dt + ...)`` with ``g0`` the level without
    the load (normal-load-scaled LuGre), rather than moving the bristles' target ``g``: then ``sigma1 dz/dt``
    would follow every swing of the load, a spurious damping force (on the benchmark's two-mass truth 15 times
    the screw's damper; docs/gap_benchmark.md, 3l). Steady sliding is the same either way: ``g0 + mu |load|``.
    """
    P = dict(zip(_NAMES, p))
    g0, s = _sliding_level(P, v)
    sigma0 = P["bristle_stiffness"]
    sigma1 = 2.0 * P["bristle_damping_ratio"] * (sigma0 * table_mass) ** 0.5
    share = P["bristle_share"]
    zdot = v - sigma0 * fabs(v) * z / (share * fabs(g0) + 1e-9)
    bristle = sigma0 * z + sigma1 * zdot
    if not _off(1.0 - share):  # all of it sticks (the default): no regularized part
        bristle = bristle + (1.0 - share) * s * g0
    mu = P["load_friction_coefficient"]
    if not _off(mu):
        bristle = (1.0 + mu * fabs(load) / (fabs(g0) + 1e-9)) * bristle
    return zdot, bristle + (P["viscous"] + P["viscous_asym"] * s) * v


def applied_force(F, p):
    """Force [N] the drive applies for the commanded ``F`` [N]: :func:`saturating` with
    ``c = inverse_drive_limit`` (a drive-gain nonlinearity: linear for small forces, saturating smoothly at
    ``1 / c``; ``c = 0``, the default, is a linear drive)."""
    return saturating(F, dict(zip(_NAMES, p))["inverse_drive_limit"])


def saturating(F, c):
    """``F / sqrt(1 + (c F)^2)``: what a drive whose gain falls off applies for the command ``F`` (any Drake
    scalar; ``F`` itself for a plain-number ``c`` of 0), a smooth saturation at ``1 / c``; the replay axis's
    :func:`applied_force` and the project's :class:`~drakecreep.model.motor.Motor` (``motor.saturation_torque``)."""
    if _off(c):
        return F
    return F / (1.0 + (c * F) * (c * F)) ** 0.5


def unsaturated(applied, c):
    """The command whose :func:`saturating` is ``applied`` (a float): ``applied / sqrt(1 - (c applied)^2)``, or an
    infinite command of its sign where ``|c applied| >= 1`` (beyond the saturation: no command reaches it)."""
    if c == 0.0:
        return applied
    r = c * applied
    return math.copysign(math.inf, applied) if abs(r) >= 1.0 else applied / math.sqrt(1.0 - r * r)


def nut_load(drive, p, friction=None, acceleration=None):
    """Axial load [N] through the nut of the RIGID axis: the drive force with the ripple, ``drive`` [N], less the
    share that accelerates the motor side (rotor, coupling, screw: ``alpha = motor_mass_fraction`` of the mass)::

        F_ax = drive - alpha M a                          (acceleration given: a measured motion)
             = (1 - alpha) drive + alpha (f + offset)     (friction given: a simulation, M a = drive - f - offset)

    The rigid axis puts all its friction at the table. In the simulation form ``friction`` [N] is the axis's
    friction WITHOUT its load term (``load = 0``), so the load stays explicit: the load term's own share of
    ``F_ax`` (``alpha mu |F_ax|``, a few % of it) is left out there. On the two-mass axis the load is the screw's
    spring force instead (exact; :class:`MeasuredAxis_`).

    ``alpha`` is not identifiable on a rigid axis but through the load term, and then poorly: fitted beside
    ``mu`` on development data, the screen put both at their bounds and the closed-loop replay got 9-55 times
    worse (docs/gap_benchmark.md, 3l). It stays the assumed share (0.2 by default: rotor,
    coupling and screw of a machine-tool axis; 0.4-0.65 on the benchmark's truths). With ``alpha = 0`` the load
    would be the whole drive force, the motor side's inertia force counted as nut load.
    """
    if (friction is None) == (acceleration is None):
        raise ValueError("nut_load: give exactly one of friction and acceleration")
    P = dict(zip(_NAMES, p))
    alpha = P["motor_mass_fraction"]
    if acceleration is not None:
        return drive - alpha * P["mass"] * acceleration
    return (1.0 - alpha) * drive + alpha * (friction + P["offset"])


#: the lead error's harmonic amplitudes [m]: ``(cos, sin)`` of the lead's first and second harmonic
LEAD_ERROR = ("lead_error_cos", "lead_error_sin", "lead_error_2_cos", "lead_error_2_sin")


def lead_error(x, p):
    """``(e, de/dx, d2e/dx2)`` of the lead error at the motor position ``x`` [m] for the parameter vector ``p``::

        e(x) = sum_k=1,2 c_k cos(k theta) + s_k sin(k theta),   theta = 2 pi x / lead

    (``lead_error_cos/sin``, ``lead_error_2_cos/sin`` [m], ``lead`` [m]). Plain zeros when every amplitude is a
    plain 0 (the default): nothing to evaluate.
    """
    P = dict(zip(_NAMES, p))
    e = d1 = d2 = 0.0
    for k, (c, s) in enumerate(((P[LEAD_ERROR[0]], P[LEAD_ERROR[1]]), (P[LEAD_ERROR[2]], P[LEAD_ERROR[3]])), 1):
        if _off(c) and _off(s):
            continue
        w = 2.0 * math.pi * k / P["lead"]
        cs, sn = cos(w * x), sin(w * x)
        e = e + c * cs + s * sn
        d1 = d1 + w * (s * cs - c * sn)
        d2 = d2 - w * w * (c * cs + s * sn)
    return e, d1, d2


def lead_error_force(x, v, p, lead=None):
    """Force [N] along +x on the RIGID axis from the table's extra inertia under a lead error (:func:`lead_error`):
    ``-m_t g e''(x) v^2`` with the gearing ``g = 1 + e'(x)`` and ``m_t = (1 - motor_mass_fraction) mass``. The rest
    of the lead error's push (the nut's force geared by ``g``, the table's inertia ``m_t g^2``) is in the rigid
    equation of :class:`MeasuredAxis_`; :func:`lead_error_drive` is the whole push to first order in ``e``.
    ``lead``: :func:`lead_error` at ``x`` if already evaluated."""
    _, e1, e2 = lead if lead is not None else lead_error(x, p)
    if _off(e2):
        return 0.0
    P = dict(zip(_NAMES, p))
    return -(1.0 - P["motor_mass_fraction"]) * P["mass"] * (1.0 + e1) * e2 * v * v


def lead_error_drive(x, v, a, drive, p):
    """Drive force [N] a lead error takes on the RIGID axis for a measured motion ``x, v, a`` [m, m/s, m/s^2] and
    the applied force ``drive`` [N] (ripple included), to first order in the error ``e`` (arrays or floats)::

        m_t e''(x) v^2 + e'(x) (drive - (m_m - m_t) a)

    The rigid equation of :class:`MeasuredAxis_` expanded in ``e``, with the nut's force ``f + offset`` taken as
    ``drive - M a`` (its zeroth order): for a measured drive the force is affine in the lead error's amplitudes,
    as an inverse-dynamics fit wants them (:func:`drakecreep.gap.screen.inverse_dynamics_force`). Left out: the
    friction's change with the table's speed ``g v``, ``e' v df/dv`` (``Fv e' v`` of the viscous part, a few
    tenths of a newton on the benchmark's truths), which would tie the amplitudes to the friction's
    coefficients; and the terms in ``e'^2``. Where a ripple's amplitudes are solved beside the error's, the
    product ``e' r`` (a few hundredths of the ripple) is not in the screen's regressor columns, each taken with
    the other linear coefficients at 0.
    """
    _, e1, e2 = lead_error(x, p)
    if _off(e1) and _off(e2):
        return 0.0
    P = dict(zip(_NAMES, p))
    m_m = P["motor_mass_fraction"] * P["mass"]
    m_t = P["mass"] - m_m
    return m_t * e2 * v * v + e1 * (drive - (m_m - m_t) * a)


#: the position ripple's harmonic amplitudes [N]: ``(cos, sin)`` of its first and second harmonic (a cogging's
#: force has harmonics of its fundamental; so has a bearing's)
POSITION_RIPPLE = ("position_ripple_cos", "position_ripple_sin", "position_ripple_2_cos", "position_ripple_2_sin")


def axis_ripple(x, t, p):
    """Position-periodic (cogging, a bearing: first and second harmonic of ``position_period``) plus time-periodic
    ripple force [N] along +x (a lead error's force is :func:`lead_error_force`)."""
    P = dict(zip(_NAMES, p))
    a = 2.0 * math.pi * x / P["position_period"]
    b = 2.0 * math.pi * P["ripple_frequency"] * t
    force = (P["position_ripple_cos"] * cos(a) + P["position_ripple_sin"] * sin(a)
             + P["time_ripple_cos"] * cos(b) + P["time_ripple_sin"] * sin(b))
    if not (_off(P["position_ripple_2_cos"]) and _off(P["position_ripple_2_sin"])):
        force = force + P["position_ripple_2_cos"] * cos(2.0 * a) + P["position_ripple_2_sin"] * sin(2.0 * a)
    return force


def set_axis_parameters(axis, context, **values):
    """Write parameters (by name) into ``axis``'s context (``context``: the root context of its diagram
    or its own); the others keep their value."""
    vec = axis.GetMyMutableContextFromRoot(context).get_mutable_numeric_parameter(0)
    for name, value in values.items():
        if name not in AXIS_PARAMETERS:
            raise InputError(f"axis.{name}", value, "one of " + ", ".join(_NAMES))
        vec.SetAtIndex(_NAMES.index(name), float(value))


@TemplateSystem.define("MeasuredAxis_", scope=sys.modules[__name__])
def MeasuredAxis_(T):
    class Impl(LeafSystem_[T]):
        """Rigid or two-mass axis with parameterised friction, optionally with LuGre bristles.

        State ``[x_m, v_m(, x_t, v_t)(, z)]``: the table's pair with ``flexible``, the bristle deflection ``z``
        [m] with ``bristles`` (then ``bristle_stiffness`` must be > 0).

        Input ports
        -----------
        force : 1, drive plus external force (N)

        Output ports
        ------------
        motor_state : 2, ``[x_m (m), v_m (m/s)]`` (the motor encoder's view)
        table_state : 2, ``[x_t (m), v_t (m/s)]`` (the linear scale's view; when rigid, motor_state moved by the
            lead error: ``[x + e(x), v (1 + e'(x))]``)
        friction_force : 1, friction on the table (N)
        """

        def _construct(self, flexible=False, parameters=None, initial_state=None, bristles=False, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.flexible = bool(flexible)
            self.bristles = bool(bristles)
            self.parameters = axis_parameters() if parameters is None else np.asarray(parameters, dtype=float)
            if self.parameters.shape != (len(_NAMES),):
                raise InputError("axis.parameters", self.parameters.shape, f"{len(_NAMES)} values")
            n = 4 if self.flexible else 2
            size = n + (1 if self.bristles else 0)
            self.initial_state = [0.0] * size if initial_state is None else [float(v) for v in initial_state]
            if len(self.initial_state) != size:
                raise InputError("axis.initial_state", len(self.initial_state), f"{size} entries")
            self.DeclareContinuousState(BasicVector_[T](self.initial_state), num_q=n // 2, num_v=n // 2,
                                        num_z=size - n)
            self.DeclareNumericParameter(BasicVector_[T](self.parameters))
            self._force = self.DeclareVectorInputPort("force", 1)
            deps = {self.xc_ticket(), self.all_parameters_ticket()}
            self.DeclareVectorOutputPort("motor_state", 2, self._calc_motor, prerequisites_of_calc=deps)
            self.DeclareVectorOutputPort("table_state", 2, self._calc_table, prerequisites_of_calc=deps)
            self.DeclareVectorOutputPort("friction_force", 1, self._calc_friction,
                                         prerequisites_of_calc=deps | {self.time_ticket(),
                                                                       self.all_input_ports_ticket()})

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.flexible, other.parameters, other.initial_state, other.bristles,
                            converter=converter)

        def _p(self, context):
            return context.get_numeric_parameter(0).CopyToVector()

        def _masses(self, P):
            """``(m_m, m_t)``: motor side and table (both the whole mass when rigid)."""
            if not self.flexible:
                return P["mass"], P["mass"]
            m_m = P["motor_mass_fraction"] * P["mass"]
            return m_m, P["mass"] - m_m

        def _table_motion(self, x, p, lead=None):
            """``(position, speed)`` of the table: the two-mass axis's own; on the rigid axis the nut's,
            ``(x + e(x), (1 + e'(x)) v)`` (``lead`` = :func:`lead_error` at ``x`` if already evaluated)."""
            if self.flexible:
                return x[2], x[3]
            e, e1, _ = lead if lead is not None else lead_error(x[0], p)
            if _off(e) and _off(e1):
                return x[0], x[1]
            return x[0] + e, x[1] * (1.0 + e1)

        def _friction(self, x, p, t, load, lead=None):
            """``(friction on the table, [dz/dt] or [])`` under the axial load ``load`` (:meth:`_load`), at the
            table's position and speed (:meth:`_table_motion`)."""
            P = dict(zip(_NAMES, p))
            pos, speed = self._table_motion(x, p, lead)
            if not self.bristles:
                return axis_friction(speed, p, pos, t, load), []
            zdot, f = bristle_rates(speed, x[-1], p, self._masses(P)[1], load)
            return _level(P, pos, t) * f, [zdot]

        def _load(self, x, P, F, t, p, lead=None):
            """Axial load through the nut [N]: the screw's spring force (two-mass; its motor end at
            ``x_m + e(x_m)`` with a lead error, ``lead`` = :func:`lead_error` at ``x_m`` if already evaluated), or
            :func:`nut_load` (rigid; 0 when the load term is off: nothing reads it then)."""
            if self.flexible:
                e, e1, _ = lead if lead is not None else lead_error(x[0], p)
                return P["stiffness"] * (x[0] + e - x[2]) + P["damping"] * (x[1] * (1.0 + e1) - x[3])
            if _off(P["load_friction_coefficient"]):
                return 0.0
            return nut_load(F + axis_ripple(x[0], t, p), p, friction=self._friction(x, p, t, 0.0, lead)[0])

        def DoCalcTimeDerivatives(self, context, derivatives):
            x = context.get_continuous_state_vector().CopyToVector()
            p = self._p(context)
            P = dict(zip(_NAMES, p))
            F = applied_force(self._force.Eval(context)[0], p)
            t = context.get_time()
            lead = lead_error(x[0], p)
            load = self._load(x, P, F, t, p, lead)
            friction, zdot = self._friction(x, p, t, load, lead)
            if self.flexible:
                m_m, m_t = self._masses(P)
                # the spring pulls the motor side back through the lead error's gearing, (1 + e'): the work
                # balance of the kinematic constraint
                e1 = lead[1]
                a_m = (F + axis_ripple(x[0], t, p) - load * (1.0 + e1)) / m_m
                a_t = (load - friction - P["offset"]) / m_t
                rates = [x[1], a_m, x[3], a_t]
            elif _off(lead[1]) and _off(lead[2]):
                rates = [x[1], (F + axis_ripple(x[0], t, p) - friction - P["offset"]) / P["mass"]]
            else:
                # the table at x + e(x) moves at g v: Lagrange's equation of the constraint (module docstring)
                g = 1.0 + lead[1]
                m_m = P["motor_mass_fraction"] * P["mass"]
                m_t = P["mass"] - m_m
                push = (F + axis_ripple(x[0], t, p) + lead_error_force(x[0], x[1], p, lead)
                        - g * (friction + P["offset"]))
                rates = [x[1], push / (m_m + m_t * g * g)]
            derivatives.get_mutable_vector().SetFromVector(vector(rates + zdot))

        def _calc_motor(self, context, output):
            x = context.get_continuous_state_vector().CopyToVector()
            output.SetFromVector(vector([x[0], x[1]]))

        def _calc_table(self, context, output):
            x = context.get_continuous_state_vector().CopyToVector()
            output.SetFromVector(vector(list(self._table_motion(x, self._p(context)))))

        def _calc_friction(self, context, output):
            x = context.get_continuous_state_vector().CopyToVector()
            p, t = self._p(context), context.get_time()
            lead = lead_error(x[0], p)
            load = self._load(x, dict(zip(_NAMES, p)), applied_force(self._force.Eval(context)[0], p), t, p, lead)
            output.SetAtIndex(0, self._friction(x, p, t, load, lead)[0])

    return Impl


MeasuredAxis = MeasuredAxis_[None]
