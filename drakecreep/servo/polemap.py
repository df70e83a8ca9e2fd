"""How physical parameters move the poles: loci, friction-slope crossings, stiffness x damping maps.

Every point is a Drake linearization (:mod:`drakecreep.servo.linearize`) of the continuous-controller
diagram (``closed_loop``) or of the paper's mechanism with the motor motion prescribed (``mechanism``); the
stiffness x damping map linearizes three points of each stiffness's column and interpolates the rest, the
dynamics being affine in the viscous coefficient (checked on each column, :func:`pole_map`).

The stiffness x damping plane (:func:`pole_map`) holds, at one feed speed ``v``:

* the rightmost closed-loop pole of the linearized drive (colour; its zero contour is the *linear
  stability boundary of the whole loop*),
* the paper mechanism's linear boundary ``C + C1 = 0`` (exact for static friction laws),
* the paper's creep condition ``D^2 = 4 pi zeta`` (eqs. 6, 10), i.e.
  ``C + C1 = (Fs - Fc)^2 / (2 pi v^2 sqrt(K M))``: above it the paper predicts steady sliding,
* optionally, creep found by simulating the nonlinear drive on a coarse grid.

Axes: ``K`` is changed by scaling every stiffness of the screw chain (bearing, shaft modulus, nut)
by the same factor, which leaves the chain damping ``C`` unchanged; ``C + C1`` is changed through the
viscous friction coefficient ``Fv`` (part of ``C1``), so at a speed on the falling Stribeck branch the
plane reaches negative effective damping.
"""

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from drakecreep.errors import InputError
from drakecreep.servo.linearize import linearize_closed_loop, linearize_mechanism, operating_point
from drakecreep.params import with_value
from drakecreep.scenario import Scenario

__all__ = [
    "scale_stiffness",
    "rightmost_pole",
    "parameter_locus",
    "friction_slope_crossings",
    "PoleMap",
    "pole_map",
    "damping_width",
    "paper_creep_damping",
    "LOCUS_PARAMETERS",
]

#: parameters :func:`parameter_locus` can sweep, with their meaning
LOCUS_PARAMETERS = {
    "stiffness": "scale factor on every stiffness of the screw chain",
    "feed": "feed speed (m/s): moves the friction slope C1 along the Stribeck curve",
    "mass": "table mass (kg)",
}


def scale_stiffness(params, factor):
    """``params`` with bearing, shaft (Young's modulus) and nut stiffness multiplied by ``factor``."""
    if not (math.isfinite(factor) and factor > 0):
        raise InputError("stiffness factor", factor, "> 0")
    p = with_value(params, "screw.bearing_stiffness", params.screw.bearing_stiffness * factor)
    p = with_value(p, "screw.youngs_modulus", params.screw.youngs_modulus * factor)
    return with_value(p, "nut.axial_stiffness", params.nut.axial_stiffness * factor)


def rightmost_pole(params, scenario, model="closed_loop"):
    """The pole with the largest real part (rad/s) of the linearized ``closed_loop`` or ``mechanism``."""
    fn = {"closed_loop": linearize_closed_loop, "mechanism": linearize_mechanism}.get(model)
    if fn is None:
        raise InputError("model", model, "closed_loop or mechanism")
    poles = fn(params, scenario).poles()
    return poles[np.argmax(poles.real)]


def _with_parameter(params, scenario, name, value):
    if name == "stiffness":
        return scale_stiffness(params, value), scenario
    if name == "feed":
        return params, Scenario(feed=float(value), load_case=scenario.load_case, duration=scenario.duration)
    if name == "mass":
        return with_value(params, "table.mass", float(value)), scenario
    raise InputError("parameter", name, "one of " + ", ".join(LOCUS_PARAMETERS))


def parameter_locus(params, scenario, name, values, model="closed_loop"):
    """Poles of the linearized drive as one physical parameter varies.

    Parameters
    ----------
    name : {"stiffness", "feed", "mass"}
        See :data:`LOCUS_PARAMETERS`.
    values : array_like
        Parameter values.

    Returns
    -------
    dict
        ``values``, ``poles`` (list of arrays), ``friction_slope`` and ``zeta`` at each value.
    """
    fn = {"closed_loop": linearize_closed_loop, "mechanism": linearize_mechanism}[model]
    poles, c1, zeta = [], [], []
    for v in values:
        p, sc = _with_parameter(params, scenario, name, v)
        op = operating_point(p, sc)
        poles.append(fn(p, sc, op).poles())
        c1.append(op.friction_slope)
        zeta.append(op.zeta)
    return dict(name=name, values=np.asarray(values, dtype=float), poles=poles,
                friction_slope=np.asarray(c1), zeta=np.asarray(zeta))


def friction_slope_crossings(params, load_case, speeds, model="closed_loop"):
    """Feed speeds where the rightmost linearized pole crosses the imaginary axis, and where ``C + C1 = 0``.

    Parameters
    ----------
    params : drakecreep.params.DriveParams
    load_case : int
    speeds : array_like
        Increasing feed speeds (m/s) bracketing the crossings.
    model : {"closed_loop", "mechanism"}

    Returns
    -------
    dict
        ``pole`` and ``theory``: sorted lists of crossing speeds (m/s), each refined with Brent's method.
    """
    speeds = np.asarray(speeds, dtype=float)

    def sc(v):
        return Scenario(feed=float(v), load_case=load_case)

    def re_pole(v):
        return float(rightmost_pole(params, sc(v), model).real)

    def c_eff(v):
        op = operating_point(params, sc(v))
        return op.damping + op.friction_slope

    out = {}
    for key, f in (("pole", re_pole), ("theory", c_eff)):
        vals = np.array([f(v) for v in speeds])
        roots = []
        for i in np.nonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]:
            roots.append(float(brentq(f, speeds[i], speeds[i + 1], xtol=1e-12, rtol=1e-10)))
        out[key] = roots
    return out


def paper_creep_damping(K, M, dF, v):
    """``C + C1`` on the paper's creep boundary ``D^2 = 4 pi zeta``: ``dF^2 / (2 pi v^2 sqrt(K M))`` (N s/m)."""
    return dF**2 / (2 * math.pi * v**2 * np.sqrt(np.asarray(K, dtype=float) * M))


@dataclass
class PoleMap:
    """Result of :func:`pole_map` (SI units).

    Attributes
    ----------
    stiffness : ndarray
        ``K`` (N/m) of each column.
    damping : ndarray
        ``C + C1`` (N s/m), shape ``(n_damping, n_stiffness)``.
    closed_loop, mechanism : ndarray
        Real part (rad/s) of the rightmost pole of the whole loop / of the paper's mechanism, same shape.
    sim_stiffness, sim_damping, sim_creep, sim_linear_unstable : ndarray
        Coarse grid simulated with the nonlinear model (empty if not asked): creep = the table stuck at
        some time in the metrics window; and whether the linearized whole loop is unstable there.
    """

    feed: float
    mass: float
    friction_drop: float
    stiffness: np.ndarray
    damping: np.ndarray
    closed_loop: np.ndarray
    mechanism: np.ndarray
    nominal: tuple
    sim_stiffness: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sim_damping: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sim_creep: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    sim_linear_unstable: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))

    def agreement(self):
        """At the simulated points: how often simulated creep matches (a) the whole loop being linearly
        unstable and (b) the paper's condition ``D^2 > 4 pi zeta`` (creep below its curve).

        Returns
        -------
        dict
            ``points``, ``linear`` and ``paper`` (counts of agreeing points).
        """
        paper = self.sim_damping < self.paper_boundary(self.sim_stiffness)
        return dict(points=int(len(self.sim_creep)), linear=int(np.sum(self.sim_creep == self.sim_linear_unstable)),
                    paper=int(np.sum(self.sim_creep == paper)))

    def paper_boundary(self, K):
        """``C + C1`` of the paper's creep condition at stiffness ``K``."""
        return paper_creep_damping(K, self.mass, self.friction_drop, self.feed)


def _viscous_for(params, scenario, target, k_scale):
    """Viscous coefficient that puts ``C + C1`` at ``target`` (clipped at 0)."""
    p = scale_stiffness(params, k_scale)
    op = operating_point(p, scenario)
    rest = op.damping + op.friction_slope - p.friction.viscous
    return max(0.0, target - rest)


#: largest relative difference between a column's middle linearization and its interpolation from the ends for
#: :func:`pole_map` to interpolate the column (measured: 1.6e-16 closed loop, 1.5e-16 mechanism on the paper rig)
AFFINE_TOLERANCE = 1e-9


def _along_viscous(column, ops, scenario, linearize):
    """The A matrices of ``linearize`` (a Drake linearization) at each params of ``column`` (one stiffness, the
    viscous coefficient varied), with their operating points ``ops``.

    The viscous coefficient enters the linearized dynamics as one term ``-Fv v`` of the table's force, so A is
    affine in it: the two ends are linearized and the rest interpolated, after a third linearization in the middle
    agrees to :data:`AFFINE_TOLERANCE` (else every point is linearized): 6 linearizations of a 20-row column
    instead of 40, the same poles."""
    def every():  # each point linearized
        return [linearize(p, scenario, op).A for p, op in zip(column, ops)]

    fv = np.array([p.friction.viscous for p in column])
    lo, hi, mid = int(np.argmin(fv)), int(np.argmax(fv)), len(column) // 2
    if len(column) < 3 or fv[hi] == fv[lo] or fv[mid] in (fv[lo], fv[hi]):
        return every()
    a_lo, a_hi, a_mid = (linearize(column[i], scenario, ops[i]).A for i in (lo, hi, mid))

    def at(f):
        return a_lo + (f - fv[lo]) / (fv[hi] - fv[lo]) * (a_hi - a_lo)

    if np.max(np.abs(at(fv[mid]) - a_mid)) > AFFINE_TOLERANCE * max(np.max(np.abs(a_mid)), 1e-300):
        return every()
    return [a_lo if i == lo else a_hi if i == hi else a_mid if i == mid else at(f) for i, f in enumerate(fv)]


def _creeps(point):
    """Whether the nonlinear drive creeps at ``point = (params, scenario)`` (a failed run counts as creep; module
    level, so a process pool can pickle it)."""
    from drakecreep.sim.simulation import simulate

    r = simulate(*point)
    return bool((not r.ok) or r.metrics is None or r.metrics.stick_fraction > 0.0)


def damping_width(damping_range):
    """The linear width [N s/m] of the pole map's damping axis: rows and plot are even in ``asinh(y / width)``, linear
    within about ``width`` of zero and logarithmic beyond it. Half the larger of the range's ends' magnitudes below
    zero and a tenth of its top (at least 1 N s/m): the unstable band, ``C + C1`` below or about 0, had 7 % of a
    linear axis whose top the paper's ``D^2 = 4 pi zeta`` curve sets at 5e6 N s/m (paper rig, 0.1 mm/s), and
    about a quarter of this one."""
    lo, hi = (float(v) for v in damping_range)
    return max(0.5 * max(-lo, 0.0), 0.1 * max(hi, 0.0) if lo >= 0 else 0.0, 1.0)


def pole_map(params, scenario, k_scales=None, n_damping=20, damping_range=None, sim_grid=None, sim_duration=1.0,
             workers=1):
    """Rightmost poles over stiffness x effective damping at the scenario's feed.

    Parameters
    ----------
    params, scenario
        Drive and the feed speed / load case of the plane.
    k_scales : array_like, optional
        Stiffness factors (default 16 values, 0.25-4, log spaced).
    n_damping : int
        Rows of the damping axis.
    damping_range : (float, float), optional
        ``C + C1`` range (N s/m); default from the lowest value reachable (``Fv = 0``) to 1.3 x the
        paper's boundary at the smallest stiffness.
    sim_grid : (int, int), optional
        Simulate the nonlinear drive on this many stiffness x damping points (e.g. ``(6, 6)``).
    sim_duration : float
        Simulated time per point (s); the metrics window is its second half.
    workers : int
        Processes for the ``sim_grid`` simulations (1: in this process; a pool never has more than the usable
        CPUs, :func:`drakecreep.processes.pool_size`).

    Returns
    -------
    PoleMap
    """
    # the simulations check the linear model, which lumps the nut's friction on the table: simulate that one
    from drakecreep.model.steady import nut_on_table

    params = nut_on_table(params)
    k_scales = np.geomspace(0.25, 4.0, 16) if k_scales is None else np.asarray(k_scales, dtype=float)
    op0 = operating_point(params, scenario)
    M = op0.mass
    dF = op0.Fs - op0.Fc
    v = abs(scenario.feed)
    if damping_range is None:
        lo = op0.damping + op0.friction_slope - params.friction.viscous
        hi = 1.3 * float(paper_creep_damping(op0.stiffness * k_scales.min(), M, dF, v))
        hi = max(hi, op0.damping + op0.friction_slope + 100.0, lo + 100.0)
        damping_range = (lo, hi)
    width = damping_width(damping_range)
    targets = width * np.sinh(np.linspace(np.arcsinh(damping_range[0] / width), np.arcsinh(damping_range[1] / width),
                                          n_damping))
    K = np.zeros(len(k_scales))
    Y = np.zeros((n_damping, len(k_scales)))
    cl = np.zeros_like(Y)
    mech = np.zeros_like(Y)
    for j, s in enumerate(k_scales):
        ps = scale_stiffness(params, s)
        opj = operating_point(ps, scenario)
        K[j] = opj.stiffness
        rest = opj.damping + opj.friction_slope - ps.friction.viscous
        column = [with_value(ps, "friction.viscous", max(0.0, y - rest)) for y in targets]
        ops = [operating_point(p, scenario) for p in column]
        Y[:, j] = [op.damping + op.friction_slope for op in ops]
        for out, linearize in ((cl, linearize_closed_loop), (mech, linearize_mechanism)):
            out[:, j] = [np.linalg.eigvals(a).real.max() for a in _along_viscous(column, ops, scenario, linearize)]
    result = PoleMap(feed=v, mass=M, friction_drop=dF, stiffness=K, damping=Y, closed_loop=cl, mechanism=mech,
                     nominal=(op0.stiffness, op0.damping + op0.friction_slope))
    if sim_grid:
        nk, ny = sim_grid
        ks = np.geomspace(k_scales.min(), k_scales.max(), nk)
        # rows from the lowest reachable damping (slightly inside, to stay visible on the plot) upwards
        u0, u1 = np.arcsinh(damping_range[0] / width), np.arcsinh(damping_range[1] / width)
        ys = width * np.sinh(np.linspace(u0, u1, ny + 1)[:-1] + 0.03 * (u1 - u0))  # even on the plot's axis
        psim = with_value(params, "simulation.steady_start", 0.5 * sim_duration)
        sk, sy, unstable, points = [], [], [], []
        sc = Scenario(feed=scenario.feed, load_case=scenario.load_case, duration=sim_duration)
        for s in ks:
            ps = scale_stiffness(psim, s)
            for y in ys:
                fv = _viscous_for(ps, sc, y, 1.0)
                p = with_value(ps, "friction.viscous", fv)
                op = operating_point(p, sc)
                sk.append(op.stiffness)
                sy.append(op.damping + op.friction_slope)
                unstable.append(bool(linearize_closed_loop(p, sc, op).poles().real.max() > 0))
                points.append((p, sc))
        if workers > 1 and len(points) > 1:
            from drakecreep.processes import process_pool

            with process_pool(workers) as pool:  # a Ctrl-C or an error ends the workers at once
                creep = list(pool.map(_creeps, points))
        else:
            creep = [_creeps(point) for point in points]
        result.sim_stiffness = np.asarray(sk)
        result.sim_damping = np.asarray(sy)
        result.sim_creep = np.asarray(creep, dtype=bool)
        result.sim_linear_unstable = np.asarray(unstable, dtype=bool)
    return result
