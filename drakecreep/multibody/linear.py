"""The multibody mechanics linearized at steady sliding: the plant of the velocity loop, from Drake.

As :func:`drakecreep.servo.linearize.linearize_plant` does for the two-mass model: a point of the
steady sliding trajectory at the scenario's feed, the drift (the ramp) dropped, the Jacobians from
Drake's ``FirstOrderTaylorApproximation`` (AutoDiff) of the very diagram the simulation runs
(:func:`~drakecreep.multibody.diagram.build_multibody_diagram` with ``open_loop=True``: torque limit,
current loop, MultibodyPlant, the friction TemplateSystems and the load case).

Operating point: the static equilibrium under gravity, the load case and the friction forces at the
feed (the guides' and the nut's steady-state friction as constant loads), the motor torque holding
it (:func:`~drakecreep.multibody.diagram.loaded_equilibrium`); every body moving with the rigid-body
feed motion (the null vector of the stiffness, scaled to the feed at the table); LuGre's bristle states
at their steady value. Unlike the two-mass linearization (which lumps the nut on the table,
:func:`drakecreep.model.steady.nut_on_table`), the nut's friction acts on the screw here.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
from pydrake.systems.primitives import FirstOrderTaylorApproximation

from drakecreep.model.friction import make_friction_law
from drakecreep.model.nut_friction import nut_friction_levels, nut_friction_params
from drakecreep.model.nut_table import table_friction_levels
from drakecreep.multibody.diagram import (
    MultibodyOptions,
    _applied_map,
    _indices,
    _load_forces,
    build_multibody_diagram,
    loaded_equilibrium,
)

__all__ = ["linearize_multibody_plant", "residualize", "PLANT_OUTPUTS"]

#: outputs of the linearized plant (the names :mod:`drakecreep.servo.loops` reads)
PLANT_OUTPUTS = ("motor_angle", "motor_speed", "table_position", "table_speed")


def linearize_multibody_plant(params, scenario, options=None):
    """``(A, B, C, D)`` of the multibody mechanics at steady sliding at ``scenario.feed``.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    scenario : drakecreep.scenario.Scenario
        Feed (the operating speed) and load case.
    options : MultibodyOptions, optional

    Returns
    -------
    dict
        ``A, B, C, D`` (numpy), ``inputs`` (``["torque_command"]``), ``outputs`` (:data:`PLANT_OUTPUTS`),
        ``torque`` (N m, at the operating point), ``acceleration_residual`` (largest generalized
        acceleration left at the operating point, 1/s^2 or m/s^2: ~0 at a steady state).
    """
    options = MultibodyOptions() if options is None else options
    fd = build_multibody_diagram(params, scenario, options, continuous=True, ideal_sensors=True, open_loop=True)
    drive, diagram = fd.drive, fd.diagram
    plant = drive.plant
    idx = _indices(drive)
    load = params.load_case(scenario.load_case)
    v = scenario.feed
    ratio = params.screw.lead / (2.0 * math.pi)
    law = make_friction_law(params.friction)
    amap = _applied_map(drive, idx)

    fc, fs = table_friction_levels(params, load) if options.friction else (0.0, 0.0)
    fc_n, fs_n = nut_friction_levels(params, load) if options.friction else (0.0, 0.0)
    f_guide = float(law.steady_state_force(v, fc, fs)) if fc > 0 else 0.0
    f_nut = float(make_friction_law(nut_friction_params(params.friction)).steady_state_force(v, fc_n, fs_n)) \
        if fc_n > 0 else 0.0
    applied = _load_forces(drive, idx, load) + amap @ np.array([0.0, f_guide, f_nut * ratio, 0.0])

    context = diagram.CreateDefaultContext()
    pc = plant.GetMyMutableContextFromRoot(context)
    _, torque, _ = loaded_equilibrium(drive, applied, amap[:, 0], idx["table"]["vx"],
                                      torque=fd.initial_torque, context=pc)

    # the rigid-body feed motion: the stiffness's null vector, scaled to the feed at the table
    from drakecreep.multibody.modes import linearize_mechanics

    _, stiffness, _ = linearize_mechanics(drive, pc)
    k_sym = 0.5 * (stiffness + stiffness.T)
    mass = plant.CalcMassMatrix(pc)
    _, vecs = scipy.linalg.eigh(k_sym, 0.5 * (mass + mass.T), subset_by_index=[0, 0])
    feed_mode = vecs[:, 0] / vecs[idx["table"]["vx"], 0] * v
    plant.SetVelocities(pc, feed_mode)

    for name, level in (("guide_friction", fc), ("nut_friction", fc_n)):
        if name in fd.systems and law.num_states:
            system = fd.systems[name]
            z = float(law.sliding_level(v, level, params.friction.static_ratio * level)) * math.copysign(1.0, v) / level
            system.GetMyMutableContextFromRoot(context).SetContinuousState([z])
    if "current_loop" in fd.systems:
        lag = fd.systems["current_loop"]
        lag.set_initial_output_value(lag.GetMyMutableContextFromRoot(context), [torque])
    diagram.get_input_port(0).FixValue(context, [torque])
    lin = FirstOrderTaylorApproximation(diagram, context)
    accel = plant.get_generalized_acceleration_output_port().Eval(pc)
    return dict(A=lin.A(), B=lin.B(), C=lin.C(), D=lin.D(), inputs=["torque_command"], outputs=list(PLANT_OUTPUTS),
                torque=torque, acceleration_residual=float(np.max(np.abs(accel))))


def residualize(A, B, C, D, cutoff):
    """Drop the modes faster than ``cutoff`` (rad/s) by singular perturbation (their static response kept).

    The real Schur form of ``A`` is ordered slow-first and block-diagonalised (Sylvester equation); the
    fast block's states are set to their quasi-static values, ``D += -C_f A_f^-1 B_f``. The DC gain is
    exact and the response below ``cutoff`` is that of the full model up to the fast modes' dynamics.

    Returns
    -------
    A, B, C, D : numpy.ndarray
        The reduced model; its state count is that of the modes with ``|lambda| <= cutoff``.
    """
    T, Z, slow = scipy.linalg.schur(A, output="real", sort=lambda re, im: math.hypot(re, im) <= cutoff)
    if slow == A.shape[0]:
        return A, B, C, D
    a11, a12, a22 = T[:slow, :slow], T[:slow, slow:], T[slow:, slow:]
    # x = [I X; 0 I] y block-diagonalises [a11 a12; 0 a22] when a11 X - X a22 = -a12
    X = scipy.linalg.solve_sylvester(a11, -a22, -a12)
    Bz, Cz = Z.T @ B, C @ Z
    b1 = Bz[:slow] - X @ Bz[slow:]
    b2 = Bz[slow:]
    c1 = Cz[:, :slow]
    c2 = Cz[:, :slow] @ X + Cz[:, slow:]
    return a11, b1, c1, D - c2 @ np.linalg.solve(a22, b2)
