"""Nut and table on rolling guides, with friction whose level follows the load case.

Friction levels (Coulomb force) of the guides and of the nut::

    Fc = seal_force + mu_guide (|m g + Fz| + |Fy|)        guides and seals
       + 2 pi T_preload / Ph + mu_nut |Fx|                 ball nut: preload drag + axial load
    Fs = static_ratio * Fc

Where the nut's share acts is ``friction.nut_friction_on``:

* ``"table"`` (default): lumped with the guides on the table, one friction law at the table speed.
  Simple, and the slip speed is nearly the same (the nut contact is stiff: 51.6 N/um against ~8 N/um
  for the whole chain), but the drag then loads the table rather than the screw.
* ``"screw"``: as the drag torque it physically is, against the screw's rotation (on the motor side
  of the screw's elasticity), in :mod:`drakecreep.model.nut_friction`; the table carries only the guides.

The axial load ``Fx`` of the load case opposes the feed (+x) as a constant force, as the paper's air
cylinders do. The vertical load ``Fz`` is positive downwards, pressing the table onto its guides like
its weight (the paper's Table 7 cylinders load the table from above); a lifting load (``Fz < 0``)
unloads the guides, down to zero at ``Fz = -m g`` and lifting the table against the guides' upper
raceways beyond that (rolling guides carry load in both directions, hence the absolute value).
The lateral load ``Fy`` loads the guides' side raceways either way: ``|Fy|``.

Along the travel the table's friction (every term of its law) is ``1 + m(x)`` times the law's, ``m`` the smooth
friction map of ``friction.position_map_*`` (:func:`drakecreep.model.axis.friction_map`, the equation the
replay axis uses): worn or misaligned stretches of the guides, a seal that drags harder near one end. ``x`` is the
table's position (a replay moves the map to where its run starts, :func:`drakecreep.gap.drake_replay.at_origin`).
Where the nut's share acts on the screw (``nut_friction_on: screw``), the map scales the guides' share only.
The lumped drive of the paper's creep theory takes the map's level where its table is
(:func:`drakecreep.model.lumped.lumped`); the linear analyses refuse a map (sliding at a constant force is no steady
state of a level that changes along the travel), as do the plain-Python batch equations and the multibody model.

Over a run the table's friction can drift (``friction.time_drift`` ``r`` [1/s], a warm-up of the guides' grease): its
level is ``max(1 + r t, 0)`` times the law's, ``t`` the time since the run started (the replay axis's
``friction_drift``). The linear analyses refuse it (no steady sliding), as do the plain-Python batch equations and
the multibody model; the lumped drive of the creep theory takes the level at the start.

A structural mode on the table (``table.mode_mass_share`` ``s`` > 0): a share ``s`` of the moving mass (a workpiece
and its fixture, the carriage's upper structure) sits on a spring and damper of its own, ``table.mode_frequency``
``f`` and ``table.mode_damping_ratio`` ``zeta`` (:func:`structural_mode`); the rest, ``(1 - s) M``, carries the nut
and the friction. The table's state gains the mode's deflection ``d = x_mode - x`` and its rate (0 at rest and in
steady sliding, so the linear analyses' operating point has them at 0), and ``d``'s spring and damper push the
table. The guides still carry the whole weight. The lumped drive of the creep theory keeps the whole mass on its
spring (the mode well above the stick-slip frequency moves with the table); the plain-Python batch equations and
the multibody model refuse it.
"""

import math
import sys

from pydrake.systems.framework import BasicVector_, LeafSystem_
from pydrake.systems.scalar_conversion import TemplateSystem

from drakecreep.model._scalar import smax, vector
from drakecreep.model.axis import FRICTION_MAP, friction_map
from drakecreep.model.friction import make_friction_law

__all__ = ["NutTable", "NutTable_", "moving_mass", "friction_levels", "friction_split", "table_friction_levels",
           "friction_map_parameters", "position_level", "structural_mode"]


def moving_mass(params):
    """Translating mass (kg): table plus nut."""
    return params.table.mass + params.nut.mass


def structural_mode(params):
    """The table's structural mode as ``(mass kg, stiffness N/m, damping N s/m)``: ``m = s M`` (``M`` the moving
    mass), ``k = m (2 pi f)^2``, ``c = 2 zeta m 2 pi f``; None without one (``table.mode_mass_share`` 0)."""
    t = params.table
    if t.mode_mass_share == 0.0:
        return None
    m = t.mode_mass_share * moving_mass(params)
    w = 2.0 * math.pi * t.mode_frequency
    return m, m * w * w, 2.0 * t.mode_damping_ratio * m * w


def friction_levels(params, load):
    """Coulomb and breakaway friction forces ``(Fc, Fs)`` in N for a :class:`~drakecreep.params.LoadCase`."""
    fc = sum(friction_split(params, load))
    return fc, params.friction.static_ratio * fc


def friction_split(params, load):
    """Coulomb levels (N) of the guides (seals + rolling guides) and of the nut (preload + axial load).

    Returns
    -------
    guides, nut : float
        Their sum is :func:`friction_levels`' ``Fc``.
    """
    normal = abs(moving_mass(params) * params.loads.gravity + load.fz) + abs(load.fy)
    guides = params.table.seal_force + params.table.guide_friction_coefficient * normal
    nut = 2.0 * math.pi * params.nut.preload_torque / params.screw.lead + params.nut.load_friction_coefficient * abs(load.fx)
    return guides, nut


def table_friction_levels(params, load):
    """``(Fc, Fs)`` acting on the table: everything, or only the guides' share when
    ``friction.nut_friction_on == "screw"`` (the nut's share then acts on the screw, see
    :mod:`drakecreep.model.nut_friction`)."""
    if params.friction.nut_friction_on == "screw":
        fc = friction_split(params, load)[0]
        return fc, params.friction.static_ratio * fc
    return friction_levels(params, load)


def friction_map_parameters(friction):
    """``friction.position_map_*`` (:class:`~drakecreep.params.FrictionParams`) by the names of
    :func:`drakecreep.model.axis.friction_map`."""
    P = dict(zip(FRICTION_MAP, friction.position_map))
    P["friction_map_start"] = friction.position_map_start
    P["friction_map_end"] = friction.position_map_end
    return P


def position_level(friction, x):
    """The table friction's level factor ``1 + m(x)`` at map position ``x`` [m] (any Drake scalar; exactly 1.0
    without a map)."""
    return 1.0 + friction_map(friction_map_parameters(friction), x)


@TemplateSystem.define("NutTable_", scope=sys.modules[__name__])
def NutTable_(T):
    class Impl(LeafSystem_[T]):
        """Table mass with friction; state ``[x, v, z..., d, dd]`` (``z``: the friction law's internal states;
        ``d``, ``dd``: the deflection of the structural mode's mass from the table and its rate, with one).

        Input ports
        -----------
        axial_force : 1, force of the screw on the table (N)

        Output ports
        ------------
        table_state : 2, ``[x (m), v (m/s)]``
        friction_force : 1, friction on the table (N, opposing +v)
        friction_state : internal friction states (LuGre: bristle load / Fc), size 0 for stateless laws
        """

        def _construct(self, params, load, initial_state=None, converter=None):
            LeafSystem_[T].__init__(self, converter=converter)
            self.params = params
            self.load = load
            # the map's parameters by friction_map's names, built once (None: no map)
            self._map = friction_map_parameters(params.friction) if params.friction.has_position_map else None
            self.drift = params.friction.time_drift
            self.law = make_friction_law(params.friction)
            self.mode = structural_mode(params)
            self.mass = moving_mass(params) - (self.mode[0] if self.mode else 0.0)
            self.fc, self.fs = table_friction_levels(params, load)
            self._nz = self.law.num_states
            n = 2 + self._nz + (2 if self.mode else 0)
            self.initial_state = [0.0] * n if initial_state is None else list(initial_state)
            if len(self.initial_state) != n:
                raise ValueError(f"NutTable initial_state must have {n} entries")
            self.DeclareContinuousState(BasicVector_[T](self.initial_state), num_q=1, num_v=1, num_z=n - 2)
            self._u_axial_force = self.DeclareVectorInputPort("axial_force", 1)
            state_only = {self.xc_ticket()}
            self.DeclareVectorOutputPort("table_state", 2, self._calc_state, prerequisites_of_calc=state_only)
            timed = state_only | ({self.time_ticket()} if self.drift != 0.0 else set())  # a drift reads the time
            self.DeclareVectorOutputPort("friction_force", 1, self._calc_friction, prerequisites_of_calc=timed)
            self.DeclareVectorOutputPort(
                "friction_state", self.law.num_states, self._calc_z, prerequisites_of_calc=state_only
            )

        def _construct_copy(self, other, converter=None):
            Impl._construct(self, other.params, other.load, initial_state=other.initial_state, converter=converter)

        def _split(self, context, state=None):
            x = context.get_continuous_state_vector().CopyToVector() if state is None else state
            return x[0], x[1], x[2:2 + self._nz]

        def _force(self, x, v, z, t):
            # the law's internal states are normalized by its level, so the map and the drift scale its force, not
            # its rates
            f = self.law.force(v, z, self.fc, self.fs)
            if self._map is not None:
                f = (1.0 + friction_map(self._map, x)) * f
            if self.drift != 0.0:
                f = smax(1.0 + self.drift * t, 0.0) * f
            return f

        def friction(self, context):
            """Friction force (N) on the table in this context."""
            return self._force(*self._split(context), context.get_time())

        def DoCalcTimeDerivatives(self, context, derivatives):
            state = context.get_continuous_state_vector().CopyToVector()  # read once: the leaf backend's hot path
            x, v, z = self._split(context, state)
            push = self._u_axial_force.Eval(context)[0] - self.load.fx - self._force(x, v, z, context.get_time())
            if self.mode is None:
                accel, mode_rates = push / self.mass, []
            else:  # the mode's mass pulls the table by its deflection d = x_mode - x; d'' = its acceleration - the table's
                m, k, c = self.mode
                d, dd = state[2 + self._nz:]
                pull = k * d + c * dd
                accel = (push + pull) / self.mass
                mode_rates = [dd, -pull / m - accel]
            rates = [v, accel] + list(self.law.state_rates(v, z, self.fc, self.fs)) + mode_rates
            derivatives.get_mutable_vector().SetFromVector(vector(rates))

        def _calc_state(self, context, output):
            x, v, _ = self._split(context)
            output.SetFromVector(vector([x, v]))

        def _calc_friction(self, context, output):
            output.SetAtIndex(0, self.friction(context))

        def _calc_z(self, context, output):
            _, _, z = self._split(context)
            if len(z):
                output.SetFromVector(z)

    return Impl


NutTable = NutTable_[None]
