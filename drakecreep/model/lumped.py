"""The drive reduced to one mass on one spring: what the paper's creep theory (section 2) reads off the model.

One place computes the lumped values every analytic result uses (eq. 11's critical speed, the sweep map's
``v0`` curve, the paper reproduction, ``drakecreep critical``), from the same functions the Drake systems use.

The friction of the lumped mass is the friction the model applies to the table
(:func:`~drakecreep.model.nut_table.table_friction_levels`): with the ball nut's drag on the screw's rotation
(``friction.nut_friction_on: screw``, the default since issue 15) that is the guides' share only; the nut's
drag then acts on the motor side of the spring, where the paper's Fig. 2 mechanism (motor side at a constant
speed) absorbs it. With ``nut_friction_on: table`` it is everything, as the paper lumps it. A friction map
(``friction.position_map_*``) scales it by its level where the table is. A lost motion of the nut
(``nut.backlash``) is not in it: feeding one way, the chain bears the friction in one direction throughout a
stick-slip cycle (its force swings between the kinetic and the breakaway level, never through zero), so the gap
stays closed and the spring the creep theory reads is the chain's stiffness. A structural mode on the table
(``table.mode_mass_share``) is not in it either: its mass is in the lumped mass, moving with the table (right where
the mode is well above the stick-slip frequency; where it is not, simulate the diagram). A friction drift over
time (``friction.time_drift``) is taken at its start (level 1).
"""

from __future__ import annotations

from dataclasses import dataclass

from drakecreep.model.friction import FrictionLaw, make_friction_law
from drakecreep.model.nut_table import moving_mass, position_level, table_friction_levels
from drakecreep.model.screw import axial_damping, axial_stiffness, screw_inertia

__all__ = ["LumpedDrive", "lumped", "axial_mode_frequency"]


@dataclass(frozen=True)
class LumpedDrive:
    """A one-mass, one-spring drive with friction (SI units).

    Attributes
    ----------
    stiffness : float
        K, N/m: the whole axial chain (bearing, shaft, nut in series) with the table at ``x``.
    damping : float
        C, N s/m: the chain's structural damping.
    mass : float
        M, kg: table plus nut.
    coulomb, breakaway : float
        Fc (the paper's Fd) and Fs, N, for the load case: the friction acting on the table (the guides'
        share when the nut's drag is on the screw). ``breakaway`` is the law's
        (:meth:`~drakecreep.model.friction.FrictionLaw.breakaway`): ``Fc`` for the Coulomb law, which has no drop.
    law : FrictionLaw
        The friction law of ``params.friction`` (its steady-state curve gives the slope C1).
    load_case : int
        The load case these levels belong to (0 = unloaded).
    """

    stiffness: float
    damping: float
    mass: float
    coulomb: float
    breakaway: float
    law: FrictionLaw
    load_case: int = 0

    def steady_friction(self, v):
        """Steady-sliding friction force (N) at speed ``v`` (m/s)."""
        return self.law.steady_state_force(v, self.coulomb, self.breakaway)


def lumped(params, load_case=0, x=0.0):
    """The lumped drive of ``params`` under ``load_case`` with the table at ``x`` (m).

    Parameters
    ----------
    params : DriveParams
    load_case : int
        0 = no external load, 1.. = ``params.loads.cases``.
    x : float
        Table position (m); the shaft's stiffness depends on it.
    """
    from drakecreep.params import check_params

    check_params(params)
    fc, fs = table_friction_levels(params, params.load_case(load_case))
    level = float(position_level(params.friction, x))  # the friction map's level where the table is
    fc, fs = level * fc, level * fs
    law = make_friction_law(params.friction)
    return LumpedDrive(
        stiffness=float(axial_stiffness(params.screw, params.nut, x)),
        damping=float(axial_damping(params.screw, params.nut, x)),
        mass=float(moving_mass(params)),
        coulomb=float(fc),
        breakaway=float(law.breakaway(fc, fs)),
        law=law,
        load_case=int(load_case),
    )


def axial_mode_frequency(params, x=0.0):
    """Undamped axial mode (Hz) of the two-mass drive: motor side against the table on the chain.

    ``omega^2 = K (1 / M + r^2 / J)`` with ``K`` the chain at table position ``x``, ``M`` the moving
    mass, ``J`` the rotor, coupling and shaft inertia and ``r = Ph / 2 pi`` (the motor side reflected
    as the mass ``J / r^2``). The frequency ``screw.damping_frequency`` should match for the
    ``loss_factor`` damping model.
    """
    import math

    r = params.screw.lead / (2.0 * math.pi)
    inertia = params.motor.rotor_inertia + params.motor.coupling_inertia + screw_inertia(params.screw)
    k = float(axial_stiffness(params.screw, params.nut, x))
    return math.sqrt(k * (1.0 / moving_mass(params) + r * r / inertia)) / (2.0 * math.pi)
