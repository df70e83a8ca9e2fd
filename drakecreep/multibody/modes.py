"""Modal analysis of the multibody feed drive: static equilibrium, M, K, C, natural modes, labels.

* :func:`static_equilibrium` -- Newton iterations on the generalized forces of the force elements and
  gravity at rest (``MultibodyPlant.CalcGeneralizedForces``); the feed direction is a free (rigid-body)
  motion, handled by a least-squares step.
* :func:`linearize_mechanics` -- ``M`` from ``CalcMassMatrix``; ``K`` and ``C`` from Drake's
  ``Linearize`` (AutoDiff, exact): with ``v = 0``, ``dv/dt = M^-1 f(q, v)`` so ``K = -M A_vq N`` and
  ``C = -M A_vv`` (``N`` the velocity-to-qdot map; at an equilibrium ``f = 0`` and the ``dM/dq`` term vanishes).
* :func:`modal_analysis` -- ``K phi = w^2 M phi`` (``scipy.linalg.eigh``), each mode labelled by the
  kinetic energy of its motion per body group and direction (see :data:`LABELS`), its modal damping
  ratio ``phi^T C phi / (2 w)`` (mass-normalised ``phi``; the proportional-damping approximation), and
  whether the two-mass model represents it (its axial mode only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from pydrake.multibody.tree import JacobianWrtVariable, MultibodyForces
from pydrake.systems.framework import InputPortSelection, OutputPortSelection
from pydrake.systems.primitives import FirstOrderTaylorApproximation

from drakecreep.errors import InputError
from drakecreep.model.lumped import lumped
from drakecreep.model.motor import motor_inertia
from drakecreep.model.screw import screw_inertia
from drakecreep.multibody.plant import BodyGroup

__all__ = ["Mode", "ModalResult", "LABELS", "RIGID_BODY_HZ", "STEP_ROUNDOFF", "static_equilibrium",
           "linearize_mechanics", "modal_analysis", "two_mass_axial_frequency", "not_in_multibody"]

#: (body group, motion) -> label; motion is "tx".."tz" (translation) or "rx".."rz" (rotation about an axis)
LABELS = {
    **{(BodyGroup.TABLE, m): lab for m, lab in (("tx", "axial"), ("ty", "table lateral"), ("tz", "table vertical"),
                                                ("rx", "table roll"), ("ry", "table pitch"), ("rz", "table yaw"))},
    **{(BodyGroup.NUT, m): lab for m, lab in (("tx", "axial"), ("ty", "screw bending"), ("tz", "screw bending"),
                                              ("rx", "torsion"), ("ry", "screw bending"), ("rz", "screw bending"))},
    **{(BodyGroup.SCREW, m): lab for m, lab in (("tx", "screw axial"), ("ty", "screw bending"),
                                                ("tz", "screw bending"), ("rx", "torsion"),
                                                ("ry", "screw bending"), ("rz", "screw bending"))},
    **{(BodyGroup.BEARING_SEAT, m): "bearing seat" for m in ("tx", "ty", "tz", "rx", "ry", "rz")},
}
#: modes below this frequency are rigid-body motions (the feed: screw rotation with the table's travel)
RIGID_BODY_HZ = 1.0


@dataclass(frozen=True)
class Mode:
    """One natural mode.

    Attributes
    ----------
    frequency : float
        Undamped natural frequency, Hz.
    damping_ratio : float
        ``phi^T C phi / (2 w)`` (proportional-damping approximation).
    label : str
        Motion with the largest share of the mode's kinetic energy (a :data:`LABELS` value).
    shares : dict
        Label -> share of the kinetic energy (sums to 1).
    shape : numpy.ndarray
        Mass-normalised mode shape in generalized velocities ``v`` (largest entry positive).
    two_mass : bool
        True for the mode the two-mass model represents (the lowest axial mode).
    """

    frequency: float
    damping_ratio: float
    label: str
    shares: dict
    shape: np.ndarray
    two_mass: bool = False


@dataclass(frozen=True)
class ModalResult:
    """Modes of a :class:`~drakecreep.multibody.plant.MultibodyDrive` about its static equilibrium.

    Attributes
    ----------
    modes : tuple of Mode
        The first flexible modes, by frequency.
    rigid_body_modes : int
        Modes below :data:`RIGID_BODY_HZ` (1 expected: the feed).
    mass, stiffness, damping : numpy.ndarray
        ``M``, ``K`` (symmetrised), ``C`` in generalized velocities.
    stiffness_asymmetry : float
        ``|K - K^T| / |K|`` before symmetrising (small at an equilibrium).
    equilibrium_residual : float
        Largest generalized force (N or N m) left at the equilibrium.
    n_segments : int
    rigid_joints : bool
    """

    modes: tuple
    rigid_body_modes: int
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    stiffness_asymmetry: float
    equilibrium_residual: float
    n_segments: int
    rigid_joints: bool

    def axial_mode(self):
        """The mode the two-mass model represents (lowest mode labelled ``"axial"``)."""
        for mode in self.modes:
            if mode.two_mass:
                return mode
        raise LookupError("no axial mode among the computed modes")

    def to_dict(self):
        """JSON-ready summary (frequencies in Hz, shares in %)."""
        return {
            "n_segments": self.n_segments,
            "rigid_joints": self.rigid_joints,
            "rigid_body_modes": self.rigid_body_modes,
            "equilibrium_residual_N": self.equilibrium_residual,
            "stiffness_asymmetry": self.stiffness_asymmetry,
            "modes": [
                {"mode": i + 1, "frequency_Hz": m.frequency, "damping_ratio": m.damping_ratio, "label": m.label,
                 "in_two_mass_model": m.two_mass,
                 "energy_share_percent": {k: 100.0 * v for k, v in sorted(m.shares.items(), key=lambda kv: -kv[1])
                                          if v >= 0.01}}
                for i, m in enumerate(self.modes)
            ],
        }


def _plant_context(drive, context):
    if context is None:
        context = drive.diagram.CreateDefaultContext()
    if drive.diagram is None:  # a plant still being wired into a larger diagram: its own context
        return context
    try:
        drive.diagram.ValidateContext(context)
    except RuntimeError:
        return context  # the plant's own context
    return drive.plant.GetMyMutableContextFromRoot(context)


def _generalized_forces(plant, context):
    forces = MultibodyForces(plant)
    plant.CalcForceElementsContribution(context, forces)
    return plant.CalcGeneralizedForces(context, forces)


def linearize_mechanics(drive, context=None):
    """Mass, stiffness and damping matrices ``(M, K, C)`` at the state of ``context`` (velocities zeroed).

    Parameters
    ----------
    drive : MultibodyDrive
    context : Context, optional
        The diagram's or the plant's context; default: the undeformed rig at rest.

    Returns
    -------
    M, K, C : numpy.ndarray
        ``nv x nv``; ``K`` is returned as computed (not symmetrised).
    """
    plant = drive.plant
    pc = _plant_context(drive, context)
    plant.SetVelocities(pc, np.zeros(plant.num_velocities()))
    lin = FirstOrderTaylorApproximation(plant, pc, input_port_index=InputPortSelection.kNoInput,
                    output_port_index=OutputPortSelection.kNoOutput)
    nq = plant.num_positions()
    a = lin.A()
    mass = plant.CalcMassMatrix(pc)
    n_map = plant.MakeVelocityToQDotMap(pc)
    n_map = n_map.toarray() if hasattr(n_map, "toarray") else np.asarray(n_map)
    stiffness = -mass @ a[nq:, :nq] @ n_map
    damping = -mass @ a[nq:, nq:]
    return mass, stiffness, damping


#: A Newton step of the static equilibrium at most this many machine epsilons of the coordinates (at least 1 m or
#: rad) moves nothing: the residual is then the round-off of the stiff joints, 0.1-0.7e-6 N with 12 screw segments,
#: 1-4e-6 N with 60-150, rigid joints or not, however many steps follow. An absolute 1e-6 N alone ended 'modes
#: --segments 60' (allowed: 2-400) in 'internal error: RuntimeError: static equilibrium not reached'.
STEP_ROUNDOFF = 64


def static_equilibrium(drive, context=None, tolerance=1e-6, max_iterations=10):
    """Move ``context`` to the static equilibrium under gravity (at rest, no external load).

    Newton steps ``dv = lstsq(K, f)`` with ``K`` from :func:`linearize_mechanics` at the start (the
    joints are linear springs: the chord method converges in a few steps); the free feed motion is
    left where it is (least-squares, minimum-norm step).

    Returns
    -------
    float
        Largest remaining generalized force (N or N m): below ``tolerance``, or where the next step is at the
        coordinates' round-off (:data:`STEP_ROUNDOFF`); raises RuntimeError if neither within ``max_iterations``.
    """
    plant = drive.plant
    pc = _plant_context(drive, context)
    plant.SetVelocities(pc, np.zeros(plant.num_velocities()))
    _, stiffness, _ = linearize_mechanics(drive, pc)
    residual = math.inf
    for _ in range(max_iterations):
        f = _generalized_forces(plant, pc)
        residual = float(np.max(np.abs(f)))
        if residual <= tolerance:
            return residual
        step = np.linalg.lstsq(stiffness, f, rcond=1e-12)[0]
        q = plant.GetPositions(pc)
        if np.max(np.abs(step)) <= STEP_ROUNDOFF * np.finfo(float).eps * max(1.0, float(np.max(np.abs(q)))):
            return residual  # as exact as the floats allow
        plant.SetPositions(pc, q + plant.MapVelocityToQDot(pc, step))
    raise RuntimeError(f"static equilibrium not reached: residual {residual:.3g} after {max_iterations} steps")


def _energy_shares(drive, pc, shape):
    plant = drive.plant
    world = plant.world_frame()
    energy = {}
    for name, group in drive.groups.items():
        body = plant.GetBodyByName(name)
        jac = plant.CalcJacobianSpatialVelocity(pc, JacobianWrtVariable.kV, body.body_frame(), np.zeros(3),
                                                world, world)
        spatial = jac @ shape
        w, v = spatial[:3], spatial[3:]
        rot = plant.EvalBodyPoseInWorld(pc, body).rotation().matrix()
        inertia_w = rot @ body.default_rotational_inertia().CopyToFullMatrix3() @ rot.T
        rot_energy = w * (inertia_w @ w)  # per axis; sums to w^T I w
        trans_energy = body.default_mass() * v**2
        for k, axis in enumerate("xyz"):
            for motion, value in ((f"t{axis}", trans_energy[k]), (f"r{axis}", rot_energy[k])):
                label = LABELS[(group, motion)]
                energy[label] = energy.get(label, 0.0) + float(value)
    total = sum(energy.values())
    return {k: v / total for k, v in energy.items()}


def modal_analysis(drive, num_modes=10, context=None, equilibrium=True):
    """Natural frequencies and mode shapes of ``drive`` about its static equilibrium.

    Parameters
    ----------
    drive : MultibodyDrive
    num_modes : int
        Flexible modes returned (rigid-body modes are counted, not returned).
    context : Context, optional
        Start state (default: the undeformed rig); it is moved to the equilibrium when ``equilibrium``.
    equilibrium : bool
        Solve for the static equilibrium under gravity first.

    Returns
    -------
    ModalResult
    """
    if isinstance(num_modes, bool) or not isinstance(num_modes, int) or num_modes < 1:
        raise InputError("num_modes", num_modes, "an integer >= 1")
    plant = drive.plant
    context = drive.diagram.CreateDefaultContext() if context is None else context
    pc = _plant_context(drive, context)
    residual = static_equilibrium(drive, pc) if equilibrium else float(np.max(np.abs(_generalized_forces(plant, pc))))
    mass, stiffness, damping = linearize_mechanics(drive, pc)
    asym = float(np.linalg.norm(stiffness - stiffness.T) / np.linalg.norm(stiffness))
    k_sym = 0.5 * (stiffness + stiffness.T)
    m_sym = 0.5 * (mass + mass.T)
    eigval, eigvec = scipy.linalg.eigh(k_sym, m_sym)
    freqs = np.sqrt(np.clip(eigval, 0.0, None)) / (2.0 * math.pi)
    rigid = int(np.sum(freqs < RIGID_BODY_HZ))
    modes, axial_found = [], False
    for idx in np.flatnonzero(freqs >= RIGID_BODY_HZ)[:num_modes]:
        phi = eigvec[:, idx]
        phi = phi * (1.0 if phi[np.argmax(np.abs(phi))] > 0 else -1.0)
        omega = 2.0 * math.pi * freqs[idx]
        shares = _energy_shares(drive, pc, phi)
        label = max(shares, key=shares.get)
        two_mass = label == "axial" and not axial_found
        axial_found |= two_mass
        modes.append(Mode(frequency=float(freqs[idx]), damping_ratio=float(phi @ damping @ phi / (2.0 * omega)),
                          label=label, shares=shares, shape=phi, two_mass=two_mass))
    return ModalResult(modes=tuple(modes), rigid_body_modes=rigid, mass=mass, stiffness=k_sym, damping=damping,
                       stiffness_asymmetry=asym, equilibrium_residual=residual, n_segments=drive.n_segments,
                       rigid_joints=drive.rigid_joints)


def two_mass_axial_frequency(params, table_position=0.0):
    """Natural frequency (Hz) of the two-mass model's axial mode (motor side free, no friction).

    ``f = sqrt(K (1/M + r^2/J)) / 2 pi`` with ``K, M`` of :func:`drakecreep.model.lumped.lumped`,
    ``J`` the rotor, coupling and screw inertia and ``r = Ph / 2 pi``: the free-free two-mass mode.
    """
    drive = lumped(params, x=table_position)
    ratio = params.screw.lead / (2.0 * math.pi)
    inertia = motor_inertia(params.motor, screw_inertia(params.screw))
    return math.sqrt(drive.stiffness * (1.0 / drive.mass + ratio**2 / inertia)) / (2.0 * math.pi)


def not_in_multibody(params):
    """The two-mass model's fields of ``params`` the multibody modes leave out, as ``(field, value SI, what: in words,
    the value in its edge unit)``: a
    structural mode on the table (``table.mode_mass_share``) and the nut's lost motion (``nut.backlash``; the
    modes are those of the closed gap)."""
    out = []
    if params.table.mode_mass_share > 0.0:
        out.append(("table.mode_mass_share", params.table.mode_mass_share,
                    f"{params.table.mode_mass_share:g} of the moving mass on a structural mode of the table at "
                    f"{params.table.mode_frequency:g} Hz (the two-mass model's; margins shows it in the loop)"))
    if params.nut.backlash > 0.0:
        out.append(("nut.backlash", params.nut.backlash,
                    f"the nut's lost motion, {1e6 * params.nut.backlash:.3g} um (these are the closed gap's modes)"))
    return out
