"""The flexible ball screw as the spring of a two-mass model.

The motor-side rotation ``theta`` is mapped through the lead to an axial displacement
``theta * Ph / (2 pi)``; the difference to the table position ``x`` stretches the axial stiffness
chain: thrust bearing, screw shaft (its stiffness depends on where the nut is) and screw-nut contact,
in series. The force acts on the table; its reaction, through the lead, loads the motor.

The series damping of the chain uses the light-damping combination of Kelvin-Voigt elements,
``C = K^2 sum(c_i / k_i^2)`` (each element's loss factor weighted by its share of the compliance);
it is exact when every element has the same ``c_i / k_i``.

The chain's elements (:func:`bearing_element`, :func:`nut_element`):

* the thrust bearing, optionally in series with the fixed joints of its seat
  (``screw.seat_joint_stiffness``: base-bearing seat, seat-outer ring, inner ring-shaft; seed paper
  Tables 1-2, see :func:`drakecreep.paper.joints.axial_path_joints`);
* the shaft (undamped);
* the screw-nut contact, optionally in series with the nut seat joints (``nut.seat_joint_stiffness``).

Damping model (``screw.chain_damping``): ``"viscous"`` uses the hammer-test coefficients as identified.
``"loss_factor"`` reads them as hysteretic damping: each test gives a loss factor
``eta_i = c_i omega_i / k_i = c_i / sqrt(k_i m_i)`` at its own test frequency ``omega_i = sqrt(k_i / m_i)``
(half-power bandwidth method: ``eta = 2 zeta``; test masses ``nut.mass``, Table 3's M, and
``screw.bearing_test_mass``), and the equivalent viscous coefficient at the mode the damping acts on,
``c_i = eta_i k_i / (2 pi f)`` with ``f = screw.damping_frequency``, is what the chain uses (a
frequency-independent loss factor cannot be simulated in the time domain; it is exact at ``f``).
The fixed joints' coefficients are used as given.

Lost motion (``nut.backlash`` ``b``, 0 for a preloaded nut): the chain bears no force, and no damping, while its
stretch is within ``+-b / 2``; beyond, the spring acts on the stretch less ``b / 2`` (:func:`chain_force`, a dead
zone: the balls cross the gap between the flanks of their grooves without load). Under a load the chain's stretch
is ``F / K + b / 2`` in the load's direction (:func:`chain_stretch`), so a linearization about steady sliding (the
chain bearing the friction) sees the stiffness ``K``; the lost motion shows where the force through the chain
reverses.
"""

import math
import sys

from pydrake.systems.framework import LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import where

__all__ = [
    "ScrewDrive",
    "ScrewDrive_",
    "shaft_section_area",
    "shaft_axial_stiffness",
    "axial_stiffness",
    "axial_damping",
    "bearing_element",
    "nut_element",
    "screw_inertia",
    "chain_force",
    "chain_stretch",
]


def shaft_section_area(screw):
    """Load-carrying cross-section (m^2) of the shaft, taken at the root diameter."""
    return math.pi / 4.0 * screw.root_diameter**2


def shaft_axial_stiffness(screw, x):
    """Axial stiffness (N/m) of the shaft between its axial support(s) and the nut at table position ``x``.

    ``fixed-free``: one thrust support, ``k = E A / a`` with ``a`` the support-to-nut distance.
    ``fixed-fixed``: supports at both ends, ``k = E A L / (a (L - a))``.
    Works for numpy arrays and any Drake scalar type.
    """
    ea = screw.youngs_modulus * shaft_section_area(screw)
    a = screw.nut_start_distance + x
    if screw.mounting == "fixed-fixed":
        return ea * screw.length / (a * (screw.length - a))
    return ea / a


def _series(k, c, kj, cj):
    """Element ``(k, c)`` in series with a joint ``(kj, cj)`` (``kj = 0``: rigid joint, no change)."""
    if kj <= 0.0:
        return k, c
    ke = 1.0 / (1.0 / k + 1.0 / kj)
    return ke, ke**2 * (c / k**2 + cj / kj**2)


def _hysteretic(k, c, mass, frequency):
    """Equivalent viscous coefficient at ``frequency`` (Hz) of the loss factor a test ``(k, c, mass)`` gives."""
    eta = c / math.sqrt(k * mass)
    return eta * k / (2.0 * math.pi * frequency)


def bearing_element(screw):
    """Thrust bearing (with its seat joints): axial ``(stiffness N/m, damping N s/m)`` of the chain's first element."""
    k, c = screw.bearing_stiffness, screw.bearing_damping
    if screw.chain_damping == "loss_factor":
        c = _hysteretic(k, c, screw.bearing_test_mass, screw.damping_frequency)
    return _series(k, c, screw.seat_joint_stiffness, screw.seat_joint_damping)


def nut_element(screw, nut):
    """Screw-nut contact (with its seat joints): axial ``(stiffness N/m, damping N s/m)``."""
    k, c = nut.axial_stiffness, nut.axial_damping
    if screw.chain_damping == "loss_factor":
        c = _hysteretic(k, c, nut.mass, screw.damping_frequency)
    return _series(k, c, nut.seat_joint_stiffness, nut.seat_joint_damping)


def axial_stiffness(screw, nut, x=0.0):
    """Stiffness (N/m) of the whole chain, bearing + shaft + nut in series, with the table at ``x``."""
    kb, _ = bearing_element(screw)
    kn, _ = nut_element(screw, nut)
    return 1.0 / (1.0 / kb + 1.0 / shaft_axial_stiffness(screw, x) + 1.0 / kn)


def axial_damping(screw, nut, x=0.0):
    """Damping (N s/m) of the chain: ``K^2 (c_bearing / k_bearing^2 + c_nut / k_nut^2)`` (shaft undamped)."""
    k = axial_stiffness(screw, nut, x)
    kb, cb = bearing_element(screw)
    kn, cn = nut_element(screw, nut)
    return k**2 * (cb / kb**2 + cn / kn**2)


def screw_inertia(screw):
    """Rotating inertia (kg m^2) of the shaft as a solid cylinder of the nominal diameter."""
    return math.pi / 32.0 * screw.density * screw.length * screw.nominal_diameter**4


def chain_force(stretch, rate, stiffness, damping, backlash=0.0):
    """Axial force [N] of the chain at ``stretch`` [m] and stretch ``rate`` [m/s]: ``K s + C ds/dt``, or with a lost
    motion ``backlash`` [m] (a float) no force within ``+-backlash / 2`` and ``K (s -+ backlash / 2) + C ds/dt``
    beyond. Any Drake scalar type for ``stretch`` and ``rate`` (``if_then_else`` for Expression)."""
    if backlash == 0.0:
        return stiffness * stretch + damping * rate
    h = 0.5 * backlash
    bearing = where(stretch > h, stiffness * (stretch - h) + damping * rate, 0.0 * stretch)
    return where(stretch < -h, stiffness * (stretch + h) + damping * rate, bearing)


def chain_stretch(force, stiffness, backlash=0.0):
    """Stretch [m] at which the chain of ``stiffness`` [N/m] and lost motion ``backlash`` [m] bears a static
    ``force`` [N]: ``F / K``, plus half the lost motion in the force's direction (the middle of the gap at 0)."""
    return force / stiffness + math.copysign(0.5 * backlash, force) * (force != 0.0)


@TemplateSystem.define("ScrewDrive_", scope=sys.modules[__name__])
def ScrewDrive_(T):
    class Impl(LeafSystem_[T]):
        """Spring-damper of the screw between the motor rotation and the table (no state), with the nut's lost
        motion (``nut.backlash``, :func:`chain_force`).

        Input ports
        -----------
        motor_state : 2, ``[theta (rad), omega (rad/s)]``
        table_state : 2, ``[x (m), v (m/s)]``

        Output ports
        ------------
        axial_force : 1, force of the screw on the table (N, +x)
        load_torque : 1, reaction torque on the motor (N m)
        """

        def _construct(self, screw, nut, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.screw = screw
            self.nut = nut
            self.ratio = screw.lead / (2.0 * math.pi)  # m per rad
            self._u_motor_state = self.DeclareVectorInputPort("motor_state", 2)
            self._u_table_state = self.DeclareVectorInputPort("table_state", 2)
            self.DeclareVectorOutputPort("axial_force", 1, self._calc_force)
            self.DeclareVectorOutputPort("load_torque", 1, self._calc_torque)

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.screw, other.nut, converter=converter)

        def force(self, context):
            """Axial force (N) on the table for the current inputs."""
            theta, omega = self._u_motor_state.Eval(context)
            x, v = self._u_table_state.Eval(context)
            stretch = theta * self.ratio - x
            rate = omega * self.ratio - v
            k = axial_stiffness(self.screw, self.nut, x)
            c = axial_damping(self.screw, self.nut, x)
            return chain_force(stretch, rate, k, c, self.nut.backlash)

        def _calc_force(self, context, output):
            output.SetAtIndex(0, self.force(context))

        def _calc_torque(self, context, output):
            output.SetAtIndex(0, self.force(context) * self.ratio)

    return Impl


ScrewDrive = ScrewDrive_[None]
