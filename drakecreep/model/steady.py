"""Steady sliding of the feed drive: the force it takes to hold a feed, and whether the drive has it.

At constant speed ``v`` the table slides against the load case's axial force ``Fx`` and the friction's steady value
``F(v)`` (the guides' and the ball nut's, the nut's lumped on the table: :func:`nut_on_table`), the screw carries
their sum, and the motor adds its own viscous drag. :func:`steady_sliding` gives those forces and the command that
holds them; :func:`sliding_overload` says when that command is beyond the drive's limit
(:func:`drakecreep.model.controller.force_limit`), where no steady sliding exists: the linear analyses cannot
linearize about it, and a simulation of it is a stalled drive, not stick-slip.

Here, in the model layer, so that ``simulate`` refuses such a feed before its run without importing the servo
layer (python-control, 1.3 s); :mod:`drakecreep.servo.linearize` builds its operating point on the same function.
"""

import math

from drakecreep.model.controller import force_limit
from drakecreep.model.friction import make_friction_law
from drakecreep.model.motor import applied_torque, commanded_torque
from drakecreep.model.nut_table import friction_levels
from drakecreep.params import with_value

__all__ = ["nut_on_table", "steady_sliding", "sliding_overload", "drive_limit"]


def nut_on_table(params):
    """``params`` with the ball nut's friction lumped on the table for the linear analysis.

    The linearization (operating point, plant, controller, closed loop) models one friction law on the
    table; the nut's drag on the screw (``friction.nut_friction_on: screw``, the default since issue 15) is
    not linearized yet, so its level is lumped with the guides' here: the same total Coulomb level and
    steady motor torque, but its slope acts at the table's speed instead of the screw's. An approximation,
    stated in ``docs/physics_review.md``.
    """
    if params.friction.nut_friction_on == "table":
        return params
    return with_value(params, "friction.nut_friction_on", "table")


def steady_sliding(params, scenario):
    """Steady sliding at ``scenario``'s feed and load case: ``((law, fc, fs), friction, spring, torque, force)``.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
        Taken as given (lump the nut on the table first with :func:`nut_on_table` for the linear analysis).
    scenario : drakecreep.scenario.Scenario

    Returns
    -------
    tuple
        The friction law (:func:`drakecreep.model.friction.make_friction_law`) and its Coulomb and static levels
        [N], the steady friction ``F(v)`` and the screw's force ``Fx + F(v)`` [N], the motor torque [N m] that
        holds them against the motor's viscous drag, and the force command at the table [N] that makes the drive
        apply it (that torque through the lead, unless the drive saturates: then more, infinite beyond
        ``motor.saturation_torque``, :func:`drakecreep.model.motor.commanded_torque`).
    """
    load = params.load_case(scenario.load_case)
    ratio = params.screw.lead / (2.0 * math.pi)
    law = make_friction_law(params.friction)
    fc, fs = friction_levels(params, load)
    friction = float(law.steady_state_force(scenario.feed, fc, fs))
    spring = load.fx + friction
    torque = spring * ratio + params.motor.viscous_damping * scenario.feed / ratio
    return (law, fc, fs), friction, spring, torque, commanded_torque(params.motor, torque) / ratio


def sliding_overload(params, scenario):
    """``(force, limit)`` [N] when the drive cannot slide steadily at ``scenario``'s feed and load case, else None.

    ``force`` is what would hold it sliding: the load's axial force, the friction at that speed and the motor's
    viscous drag, at the table (the ball nut's friction lumped on the table, :func:`nut_on_table`); ``limit`` is
    the most the drive applies (:func:`drive_limit`). The linear analyses' operating point exists only while
    ``|force| < limit``. None for the GMS law too, which has no steady sliding to linearize (the operating point
    says so).
    """
    if params.friction.law == "gms":
        return None
    torque = steady_sliding(nut_on_table(params), scenario)[3]
    force, limit = torque * 2.0 * math.pi / params.screw.lead, drive_limit(params)[0]
    return (force, limit) if abs(force) >= limit else None


def drive_limit(params):
    """``(force, source)``: the most the drive applies at the table [N], and where that figure comes from in words:
    :func:`drakecreep.model.controller.force_limit` (``motor.peak_torque`` through ``screw.lead``), less for a
    drive that saturates (:func:`drakecreep.model.motor.applied_torque` of the peak torque)."""
    limit = force_limit(params)
    if params.motor.saturation_torque == 0.0:
        return limit, "motor.peak_torque through screw.lead"
    return (applied_torque(params.motor, params.motor.peak_torque) * 2.0 * math.pi / params.screw.lead,
            "motor.peak_torque through motor.saturation_torque and screw.lead")
