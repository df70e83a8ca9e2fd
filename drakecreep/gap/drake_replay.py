"""Replay of a measured run through a Drake diagram: the measured reference drives the model in closed loop.

Two diagrams, chosen by the run's controller metadata (:class:`drakecreep.gap.measured.ControllerMeta`):

``kind: p_p_cascade`` (EMPS)::

    TrajectorySource(x_ref, first-order hold) --x_ref--> PPCascade --force--> Adder --force--> MeasuredAxis
    TrajectorySource(f_ext, zero-order hold) -------------------------------->  ^                |
                                           PPCascade <--position-- motor_state (or table_state) -+

  :class:`~drakecreep.model.pp_cascade.PPCascade` on the declared sample time and encoder resolution,
  :class:`~drakecreep.model.axis.MeasuredAxis` rigid or two-mass, its coefficients numeric parameters
  (:class:`DrakeReplay` keeps the built diagram; :meth:`DrakeReplay.simulate` takes new parameter
  values without a rebuild).

``kind: drakecreep``: the project's own feed-drive diagram (:func:`drakecreep.model.diagram.build_diagram`,
PI cascade with the gains, sensors and mechanics of ``MeasuredMeta.params``) with its reference replaced by
the measured one and ``f_ext`` added on the table (:func:`replay_drakecreep`).

The simulated signals are sampled at the run's instants (the controller's sample times) and compared
sample by sample: ``u``, ``x_motor``, ``x_table`` and ``force = u_gain u + f_ext``
(:class:`DrakeReplayResult`, :func:`drake_replay_errors`).
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import functools
import math
import os
import time as _time
from dataclasses import dataclass, field

import numpy as np
from scipy import signal
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import ContinuousStateIndex, DiagramBuilder, DiscreteStateIndex
from pydrake.symbolic import Expression, MakeVectorVariable, Variable
from pydrake.systems.primitives import Adder, LogVectorOutput, MatrixGain, SymbolicVectorSystem, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from drakecreep.errors import InputError
from drakecreep.gap.idim import filtered_derivatives, relative_error
from drakecreep.gap.measured import at_controller_rate, controller_ticks
from drakecreep.gap.residuals import classify_regimes, transmission_position
from drakecreep.model.axis import (AXIS_PARAMETERS, FRICTION_MAP, MeasuredAxis, MeasuredAxis_, applied_force,
                                   axis_friction, axis_parameters, axis_ripple, has_bristles, lead_error, nut_load)
from drakecreep.model.delay import split_delay
from drakecreep.model.pp_cascade import PPCascade, pp_initial_state

__all__ = [
    "DrakeReplay",
    "SampledReplay",
    "simulate_each",
    "set_replay_threads",
    "FRACTIONAL_DELAY_TICKS",
    "MAX_SUBSTEPS",
    "diverged_result",
    "make_replay",
    "LoggedReplay",
    "DrakeReplayResult",
    "drake_replay",
    "drake_replay_errors",
    "REGIME_ERRORS",
    "MIN_REGIME_SAMPLES",
    "MODE_BANDS_HZ",
    "RUN_PIECES",
    "piece_keys",
    "mode_band",
    "rms_force_error",
    "axis_from_idim",
    "replay_drakecreep",
    "replay_params",
    "check_replayable",
    "check_travel",
    "at_origin",
    "QUICK_REPLAY_SETTINGS",
    "quick_replay_params",
    "simulated_runs",
]


def check_replayable(run):
    """Raise :class:`InputError` unless the run's metadata names a controller this module can replay."""
    ctrl = run.meta.controller
    if ctrl is None:
        raise InputError("controller", None, "a controller in the run metadata (p_p_cascade or drakecreep)")
    if ctrl.kind == "drakecreep" and run.meta.params is None:
        raise InputError("params", None, "a drakecreep params file in the metadata for controller kind drakecreep")
    if ctrl.kind == "drakecreep":
        from drakecreep.sim.simulation import check_step_budget  # pydrake: not at import

        # a params file's max_step or velocity_period of 1e-9 s replayed for days
        check_step_budget(run.meta.params, float(run.t[-1] - run.t[0]))
    # named by the run: a file holds several, and their sample times may differ; a log taken every few ticks is
    # replayed on the controller's tick (make_replay)
    controller_ticks(run)
    if run.n < 20:
        raise InputError(f"run {run.label}", f"{run.n} samples", "at least 20 samples")


def _check_every_tick(run):
    """Refuse a run logged every few controller ticks: :func:`make_replay` replays it on the controller's tick."""
    m = controller_ticks(run)
    if m != 1:
        raise InputError(f"run {run.label}", f"logged every {m} controller ticks",
                         "a run logged every tick here (make_replay replays one logged every few on the tick)")


def axis_from_idim(params, **extra):
    """Axis parameter values (a dict) from IDIM ``M, Fv, Fc, offset`` (mapping or IdimResult) plus ``extra``."""
    p = params.params if hasattr(params, "params") else params
    values = {"mass": p["M"], "viscous": p["Fv"], "coulomb": p["Fc"], "offset": p.get("offset", 0.0)}
    values.update(extra)
    return values


def _table_position(x_motor, vec):
    """The rigid axis's table position [m] from the motor's: ``x + e(x)`` with the lead error of ``vec``
    (:func:`~drakecreep.model.axis.lead_error`; the compiled replays log the state, not the leaf's table port)."""
    e = lead_error(np.asarray(x_motor, dtype=float), vec)[0]
    return x_motor + e


def _lead_offset(x0, vec):
    """The lead error at ``x0`` [m] for ``vec``: the two-mass axis's table starts there, on its relaxed spring."""
    return float(lead_error(float(x0), vec)[0])


#: The most ticks per sample :class:`SampledReplay` takes. A parameter vector that needs more (a least-squares
#: step to an astronomically stiff friction or bristle) is replayed as diverged, all samples NaN, at once: one
#: asked for more than 1e18 ticks per sample and hung held-out run 18's nominal fit. Physical axes need 1-30
#: (LuGre bristles of 2e7 N/m on a 95 kg axis: 5; an axial mode at 9 kHz, 30 times the search's top: about 230).
MAX_SUBSTEPS = 256


def diverged_result(run, parameters=None, wall_time=0.0):
    """A :class:`DrakeReplayResult` of ``run`` whose samples are all NaN: a replay that diverged, or was not run
    because its parameters could not be (:data:`MAX_SUBSTEPS`, non-finite values)."""
    nan = np.full(run.n, np.nan)
    return DrakeReplayResult(run=run, x_motor=nan, x_table=nan.copy(), u=nan.copy(), force=nan.copy(),
                             parameters=dict(parameters or {}), wall_time=wall_time)


@dataclass(frozen=True)
class DrakeReplayResult:
    """Simulated samples beside the measured run (arrays on ``run.t``).

    ``x_motor``, ``x_table``: positions at the sample instants [m]; ``u``: controller output of each sample
    [unit of u]; ``force``: the force ``u_gain u_applied + f_ext`` [N] at the end of sample interval
    ``[t_k, t_k+1)`` (without a computation delay: held over the whole interval);
    ``wall_time``: seconds the simulation took; ``integrator_steps``: steps the error-controlled integrator took
    (0 where the replay does not count them).
    """

    run: object
    x_motor: np.ndarray
    x_table: np.ndarray
    u: np.ndarray
    force: np.ndarray
    parameters: dict = field(default_factory=dict)
    wall_time: float = 0.0
    integrator_steps: int = 0

    @property
    def x_sim(self):
        """Alias of ``x_motor`` (the fed-back position of the EMPS loop)."""
        return self.x_motor

    @property
    def force_sim(self):
        """Alias of ``force``."""
        return self.force


class DrakeReplay:
    """The ``p_p_cascade`` replay diagram of one run, built once.

    Parameters
    ----------
    run : drakecreep.gap.measured.MeasuredRun
        Reference, ``f_ext``, controller and sensor metadata, initial position.
    flexible : bool
        Two-mass axis (``True``) or rigid (``False``).
    delay : float
        Computation delay [samples], >= 0 (fractional allowed).
    quantize : bool
        Count the fed-back position with ``run.meta.sensors.encoder_resolution`` (or
        ``scale_resolution`` for ``feedback: table``).
    accuracy, max_step : float
        Integrator (Runge-Kutta 3, error controlled) settings; ``max_step`` defaults to the sample time.
    compiled : bool
        Simulate the axis as a ``SymbolicVectorSystem`` made from :class:`MeasuredAxis` (no Python in the
        integration loop, its coefficients a symbolic ``parameter`` vector) rather than the leaf system.
    bristles : bool
        Build the axis with the LuGre bristle state. A simulation whose ``bristle_stiffness`` says otherwise
        runs on a twin replay with the other layout (built once, on first use).
    """

    def __init__(self, run, flexible=False, delay=0.0, quantize=True, accuracy=1e-4, max_step=None, compiled=True,
                 bristles=False):
        check_replayable(run)
        ctrl = run.meta.controller
        if ctrl.kind != "p_p_cascade":
            raise InputError("controller.kind", ctrl.kind, "p_p_cascade (use replay_drakecreep for drakecreep)")
        _check_every_tick(run)
        if not (isinstance(delay, (int, float)) and math.isfinite(delay) and delay >= 0):
            raise InputError("delay", delay, "a number of samples >= 0")
        self.run, self.flexible, self.delay = run, bool(flexible), float(delay)
        self.accuracy = float(accuracy)
        self.bristles = bool(bristles)
        self._options = dict(flexible=flexible, delay=delay, quantize=quantize, accuracy=accuracy, max_step=max_step,
                             compiled=compiled)
        self._sibling = None
        h = run.dt
        self.h = h
        self.max_step = h if max_step is None else float(max_step)
        # the controller's clock: sample k at k h (the recorded time stamps may jitter)
        t = np.arange(run.n) * h
        self.t = t
        sensors = run.meta.sensors
        res = (sensors.encoder_resolution if ctrl.feedback == "motor" else sensors.scale_resolution) if quantize else 0.0
        b = DiagramBuilder()
        # the reference a controller sees at t_k is x_ref[k]; a first-order hold is exact at the samples
        ref = b.AddSystem(TrajectorySource(PiecewisePolynomial.FirstOrderHold(t, run.x_ref.reshape(1, -1))))
        ref.set_name("reference")
        f_ext = run.f_ext if run.f_ext is not None else np.zeros(run.n)
        ext = b.AddSystem(TrajectorySource(PiecewisePolynomial.ZeroOrderHold(t, f_ext.reshape(1, -1))))
        ext.set_name("f_ext")
        x0, v0 = float(run.x_motor[0]), float(run.x_motor[1] - run.x_motor[0]) / h
        self.x0, self.v0 = x0, v0
        n_delay = int(math.floor(self.delay))
        history = [float(run.u[0])] * (n_delay + 1)
        ctrl_state = pp_initial_state(ctrl.position_filter, self.delay, x0, v0, h, history)
        # the compiled axis logs its state, and a rigid axis's table is x + e(x), not a state: fed back through it, a
        # scale-fed run (feedback: table) was replayed on the motor position, without the lead error
        self.compiled = bool(compiled) and not (ctrl.feedback == "table" and not self.flexible)
        leaf = PPCascade(ctrl.kp, ctrl.kv, ctrl.saturation, h, ctrl.position_filter, run.u_gain, res, self.delay,
                         ctrl_state)
        if self.compiled and leaf.frac == 0:
            self.controller = _CompiledPP(b, leaf)
        else:
            self.controller = b.AddSystem(leaf)
            self.controller.set_name("controller")
        axis_x0 = ([x0, v0, x0, v0] if self.flexible else [x0, v0]) + ([0.0] if self.bristles else [])
        if self.compiled:
            self.axis = b.AddSystem(compiled_axis(self.flexible, axis_x0, self.bristles))
            states = self.axis.get_output_port(0)
            force_in = self.axis.get_input_port(0)
            sel = {"motor": [0, 1], "table": [2, 3] if self.flexible else [0, 1]}
        else:
            self.axis = b.AddSystem(MeasuredAxis(self.flexible, axis_parameters(), axis_x0, self.bristles))
            force_in = self.axis.GetInputPort("force")
        self.axis.set_name("axis")
        add = b.AddSystem(Adder(2, 1))
        b.Connect(ref.get_output_port(), self.controller.GetInputPort("x_ref"))
        b.Connect(self.controller.GetOutputPort("force"), add.get_input_port(0))
        b.Connect(ext.get_output_port(), add.get_input_port(1))
        b.Connect(add.get_output_port(), force_in)

        def port(which):  # "motor" / "table": [x, v] of that side
            if not self.compiled:
                return self.axis.GetOutputPort(f"{which}_state")
            g = np.zeros((2, len(axis_x0)))
            g[0, sel[which][0]] = g[1, sel[which][1]] = 1.0
            gain = b.AddSystem(MatrixGain(g))
            b.Connect(states, gain.get_input_port())
            return gain.get_output_port()

        motor, table = port("motor"), port("table")
        pick = b.AddSystem(MatrixGain(np.array([[1.0, 0.0]])))
        b.Connect(motor if ctrl.feedback == "motor" else table, pick.get_input_port())
        b.Connect(pick.get_output_port(), self.controller.GetInputPort("position"))
        self._log_motor = LogVectorOutput(motor, b, h)
        self._log_table = LogVectorOutput(table, b, h)
        self._log_u = LogVectorOutput(self.controller.GetOutputPort("u"), b, h)
        self._log_force = LogVectorOutput(self.controller.GetOutputPort("force"), b, h)
        self.diagram = b.Build()
        self.diagram.set_name("measured_replay")
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.axis.GetMyMutableContextFromRoot(self.context).SetContinuousState(axis_x0)
        if isinstance(self.controller, _CompiledPP):
            self.controller.set_initial_state(self.context)
        self._default = self.context.Clone()

    def _fresh_integrator(self):
        # a new integrator for every simulation: one that has run keeps its last step-size guess, and a second
        # simulation of the same parameters differed from the first by 1e-13 m (tests/gap/test_drake_replay.py)
        from pydrake.systems.analysis import ResetIntegratorFromFlags

        ResetIntegratorFromFlags(self.simulator, "runge_kutta3", self.max_step)
        self.simulator.get_mutable_integrator().set_target_accuracy(self.accuracy)

    def simulate(self, parameters):
        """Simulate the run with axis parameters ``parameters`` (a dict by name; see :data:`AXIS_PARAMETERS`).

        Returns
        -------
        DrakeReplayResult
        """
        start = _time.perf_counter()
        vec = axis_parameters(**parameters)
        if has_bristles(vec) != self.bristles:  # the bristle state changes the diagram: its twin has the other layout
            if self._sibling is None:
                self._sibling = DrakeReplay(self.run, bristles=not self.bristles, **self._options)
            return self._sibling.simulate(parameters)
        self.context.SetTimeStateAndParametersFrom(self._default)
        axis_ctx = self.axis.GetMyMutableContextFromRoot(self.context)
        axis_ctx.get_mutable_numeric_parameter(0).SetFromVector(vec)
        offset = _lead_offset(self.x0, vec) if self.flexible else 0.0
        if offset:  # the table on the relaxed spring: x0 + e(x0)
            state = axis_ctx.get_continuous_state_vector().CopyToVector()
            state[2] = self.x0 + offset
            axis_ctx.SetContinuousState(state)
        for log in (self._log_motor, self._log_table, self._log_u, self._log_force):
            log.FindMutableLog(self.context).Clear()
        self._fresh_integrator()
        self.simulator.Initialize()
        self.simulator.AdvanceTo(float(self.run.n * self.h))
        n = self.run.n
        out = {}
        for name, log in (("motor", self._log_motor), ("table", self._log_table), ("u", self._log_u),
                          ("force", self._log_force)):
            lg = log.FindLog(self.context)
            out[name] = _on_samples(lg.sample_times(), lg.data(), np.arange(n + 1) * self.h)
        # a log taken at t_k holds the discrete state from before the update at t_k: the output of sample k
        # (held over [t_k, t_k+1)) is the log at t_k+1
        f_ext = self.run.f_ext if self.run.f_ext is not None else 0.0
        x_table = out["table"][0][:n]
        if self.compiled and not self.flexible:
            x_table = _table_position(out["motor"][0][:n], vec)
        return DrakeReplayResult(
            run=self.run, x_motor=out["motor"][0][:n], x_table=x_table, u=out["u"][0][1:],
            force=out["force"][0][1:] + f_ext, parameters={k: float(v) for k, v in zip(AXIS_PARAMETERS, vec)},
            wall_time=_time.perf_counter() - start)


class _CompiledPP:
    """:class:`PPCascade` (integer delay) as a memoryless ``SymbolicVectorSystem`` update sampled by a
    ``ZeroOrderHold`` whose state is the controller's discrete state.

    ``SymbolicVectorSystem`` wants a state (and a discrete one next to continuous states trips a ``DRAKE_DEMAND``
    in Drake 1.51), so the update carries one constant continuous state, and each derivative evaluation evaluates
    its input (the reference, the axis's position and the hold) for that state's zero derivative.
    :mod:`drakecreep.sim.compiled` puts its update in the plant's output instead (session 78, 1.2-1.5x); this
    replay is the error-controlled cross-check of :class:`SampledReplay`, the diagnosis's path, and keeps its
    layout.

    Exposes ``GetInputPort("x_ref" | "position")`` and ``GetOutputPort("force" | "u")`` like the leaf.
    """

    def __init__(self, builder, leaf):
        from pydrake.systems.primitives import Multiplexer, ZeroOrderHold

        sym = leaf.ToSymbolic()
        ctx = sym.CreateDefaultContext()
        n = len(leaf.initial_state)
        xd = MakeVectorVariable(n, "xd")
        inp = MakeVectorVariable(2, "in")
        ctx.SetDiscreteState(0, [Expression(v) for v in xd])
        sym.GetInputPort("x_ref").FixValue(ctx, [Expression(inp[0])])
        sym.GetInputPort("position").FixValue(ctx, [Expression(inp[1])])
        update = sym.EvalUniquePeriodicDiscreteUpdate(ctx).get_vector(0).CopyToVector()
        constant = Variable("unused_constant_state")
        self.update = builder.AddSystem(SymbolicVectorSystem(
            state=[constant], input=np.concatenate([inp, xd]), dynamics=[Expression(0.0)], output=update))
        self.update.set_name("controller_update")
        self.hold = builder.AddSystem(ZeroOrderHold(leaf.period, n))
        self.hold.set_name("controller")
        self.mux = builder.AddSystem(Multiplexer([1, 1, n]))
        builder.Connect(self.mux.get_output_port(0), self.update.get_input_port(0))
        builder.Connect(self.update.get_output_port(0), self.hold.get_input_port())
        builder.Connect(self.hold.get_output_port(), self.mux.get_input_port(2))
        g_force = np.zeros((1, n))
        g_force[0, n - 1] = leaf.gain
        g_u = np.zeros((1, n))
        g_u[0, len(leaf.taps)] = 1.0
        self.force = builder.AddSystem(MatrixGain(g_force))
        self.u = builder.AddSystem(MatrixGain(g_u))
        builder.Connect(self.hold.get_output_port(), self.force.get_input_port())
        builder.Connect(self.hold.get_output_port(), self.u.get_input_port())
        self.initial_state = list(leaf.initial_state)

    def GetInputPort(self, name):
        return self.mux.get_input_port({"x_ref": 0, "position": 1}[name])

    def GetOutputPort(self, name):
        return {"force": self.force, "u": self.u}[name].get_output_port()

    def set_initial_state(self, context):
        self.hold.SetVectorState(self.hold.GetMyMutableContextFromRoot(context), self.initial_state)


#: replays :func:`simulate_each` runs at once (:func:`set_replay_threads`): the cores this process may use
_REPLAY_THREADS = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
#: Least ticks per sample of :class:`SampledReplay` with a fractional delay (its switch is averaged over one tick).
FRACTIONAL_DELAY_TICKS = 4


class SampledReplay:
    """The ``p_p_cascade`` replay as ONE discrete-time ``SymbolicVectorSystem`` on a sub-sample clock (fast path).

    The controller and the axis are the same leaf systems as in :class:`DrakeReplay`
    (:class:`~drakecreep.model.pp_cascade.PPCascade`, :class:`~drakecreep.model.axis.MeasuredAxis`), turned
    into symbolic expressions with ``ToSymbolic`` and fused into one update that ticks ``m`` times per
    sample (period ``h / m``). State ``[controller (discrete), axis (x, v[, x_t, v_t]), j]``, ``j`` the tick
    within the sample::

        j == 0 (t = t_k):  controller update from x_ref[k] and the axis position (counted), as PPCascade
        every tick:        one explicit-midpoint step of the axis over h / m, force = gain applied + f_ext[k]
        j <- (j + 1) mod m

    so no error-controlled integrator runs between the 1 kHz events. With LuGre bristles
    (``bristle_stiffness > 0``) their deflection is advanced by the exact solution of its linear ODE over the tick
    (exponential Euler), the rest of the axis by the midpoint step. ``m`` comes from the stiffest rate of
    the axis at the parameters simulated (friction slope ``Fc / v_reg`` over the mass; twice the axial
    mode's angular frequency): ``h / m`` times that rate stays below ``rate_step`` (a rebuild happens only when new parameter values
    need more ticks than the built system has).

    Only the parameters named in ``free`` stay symbolic (``parameter=`` of the system); every other axis
    parameter is substituted by its value at build time, so the expression carries no term whose
    coefficient is zero (a nominal axis has no ripple, drift or Stribeck term to evaluate). Simulating with
    other values of non-free parameters rebuilds the system (kept in a small cache).

    Same interface as :class:`DrakeReplay` (``run``, ``simulate(parameters) -> DrakeReplayResult``).
    Cross-tested against it on EMPS slices (``tests/gap/test_drake_replay.py``). A fractional delay ``n + f``
    switches the applied output from ``u[k-n-1]`` to ``u[k-n]`` at ``t_k + f h`` as the leaf does: the ticks
    before the switch see the old output, those after it the new one, and the tick it falls in their average
    over the tick (so the impulse is exact), with at least :data:`FRACTIONAL_DELAY_TICKS` ticks per sample.
    """

    def __init__(self, run, flexible=False, delay=0.0, quantize=True, free=None, rate_step=0.5, min_substeps=1):
        check_replayable(run)
        ctrl = run.meta.controller
        if ctrl.kind != "p_p_cascade":
            raise InputError("controller.kind", ctrl.kind, "p_p_cascade (use replay_drakecreep for drakecreep)")
        _check_every_tick(run)
        if isinstance(delay, bool) or not (isinstance(delay, (int, float)) and math.isfinite(delay) and delay >= 0):
            raise InputError("delay", delay, "a number of samples >= 0 (fractions allowed)")
        if not (isinstance(rate_step, (int, float)) and 0 < rate_step <= 1):
            raise InputError("rate_step", rate_step, "a number in (0, 1]")
        self.run, self.flexible, self.delay = run, bool(flexible), float(delay)
        self.quantize, self.rate_step, self.min_substeps = bool(quantize), float(rate_step), int(min_substeps)
        self.free = tuple(free) if free is not None else tuple(AXIS_PARAMETERS)
        for name in self.free:
            if name not in AXIS_PARAMETERS:
                raise InputError("free", name, "names among " + ", ".join(AXIS_PARAMETERS))
        self.h = run.dt
        self.t = np.arange(run.n) * self.h
        self._built = {}
        self.substeps = None

    def substeps_for(self, values):
        """Ticks per sample needed by the parameter vector ``values`` (order of :data:`AXIS_PARAMETERS`)."""
        P = dict(zip(AXIS_PARAMETERS, values))
        m_m = P["motor_mass_fraction"] * P["mass"] if self.flexible else P["mass"]
        m_t = P["mass"] - m_m if self.flexible else P["mass"]
        level = 1.0 + abs(P["friction_ripple_cos"]) + abs(P["friction_ripple_sin"]) + abs(P["friction_drift"]) * \
            self.run.n * self.h + sum(abs(P[n]) for n in FRICTION_MAP)
        viscous = abs(P["viscous"]) + abs(P["viscous_asym"])
        if has_bristles(values):
            # the bristles' own rate is integrated exactly; what remains is their mode on the table mass,
            # omega = sqrt(sigma0 / m_t), and their damping sigma1 / m_t. The sticking bristles cross v = 0 often,
            # where |v| in their rate is not smooth, so the step converges at first order there: 6 omega (about
            # 12 ticks per radian of the mode) keeps the force error within 0.05 points of % of the
            # error-controlled replay at 1e-8 for sigma0 1e6-5e7 N/m on a 95 kg axis (tests/gap/test_drake_replay.py)
            omega = math.sqrt(P["bristle_stiffness"] / m_t)
            rate = level * max(6.0 * omega, 2.0 * P["bristle_damping_ratio"] * omega + viscous / m_t)
        else:
            slope = level * ((abs(P["coulomb"]) + abs(P["coulomb_asym"]) + abs(P["stribeck_extra"])) /
                             P["regularization_velocity"] + viscous)
            rate = slope / m_t
        if self.flexible:
            k, c = abs(P["stiffness"]), abs(P["damping"])
            red = 1.0 / m_m + 1.0 / m_t
            # an oscillation needs finer steps than a decay: the mode's rate counts twice
            rate = max(rate, 2.0 * math.sqrt(k * red), c * red)
        ticks = self.h * rate / self.rate_step
        if not ticks <= 1e18:  # inf or NaN from an overflowing parameter: far beyond MAX_SUBSTEPS either way
            ticks = 1e18
        # a fractional delay's switch is averaged over the tick it falls in (see _build): at 4 ticks or more per
        # sample that costs under 0.02 points of force error against the exact switch (tests/gap/test_drake_replay.py)
        least = max(self.min_substeps, FRACTIONAL_DELAY_TICKS if self.delay % 1 else 1)
        return max(least, int(math.ceil(ticks)))

    def _key(self, vec):
        fixed = tuple(float(v) for n, v in zip(AXIS_PARAMETERS, vec) if n not in self.free)
        return fixed + (has_bristles(vec),)

    def _system(self, vec):
        need = self.substeps_for(vec)
        key = self._key(vec)
        have = self._built.get(key)
        if have is not None and have[0] >= need:
            return have
        m = max(need, 2 * have[0]) if have is not None else need
        if len(self._built) > 8:
            self._built.clear()
        built = (m,) + self._build(vec, m)
        self._built[key] = built
        return built

    def _build(self, vec, m):
        from pydrake.math import exp as exp_, max as max_, min as min_
        from pydrake.symbolic import if_then_else

        run, h = self.run, self.h
        ctrl = run.meta.controller
        sensors = run.meta.sensors
        res = (sensors.encoder_resolution if ctrl.feedback == "motor" else sensors.scale_resolution) \
            if self.quantize else 0.0
        x0, v0 = float(run.x_motor[0]), float(run.x_motor[1] - run.x_motor[0]) / h
        n_delay, frac = split_delay(self.delay, "delay")
        # a fractional delay n + f: the controller's law with a whole delay of n + 1 keeps u[k-n] and u[k-n-1]
        # in its queue; the axis sees u[k-n-1] until t_k + f h and u[k-n] after it (below, per tick)
        whole = n_delay + 1 if frac > 0 else n_delay
        history = [float(run.u[0])] * (whole + 1)
        ctrl_state = pp_initial_state(ctrl.position_filter, whole, x0, v0, h, history)
        leaf = PPCascade(ctrl.kp, ctrl.kv, ctrl.saturation, h, ctrl.position_filter, run.u_gain, res, whole,
                         ctrl_state)
        bristles = has_bristles(vec)
        axis_x0 = ([x0, v0, x0, v0] if self.flexible else [x0, v0]) + ([0.0] if bristles else [])
        na, nc = len(axis_x0), len(ctrl_state)
        time = Variable("t")
        xc = MakeVectorVariable(nc, "xc")
        xa = MakeVectorVariable(na, "xa")
        j = Variable("j")
        inp = MakeVectorVariable(2, "in")  # x_ref, f_ext
        p_free = MakeVectorVariable(len(self.free), "p") if self.free else np.zeros(0, dtype=object)
        p_all = [Expression(p_free[self.free.index(n)]) if n in self.free else Expression(float(v))
                 for n, v in zip(AXIS_PARAMETERS, vec)]
        # the controller's periodic update, from the leaf system
        csym = leaf.ToSymbolic()
        cctx = csym.CreateDefaultContext()
        cctx.SetDiscreteState(0, [Expression(v) for v in xc])
        it = 2 if self.flexible else 0  # the table's position in the axis state
        fb = Expression(xa[0] if ctrl.feedback == "motor" else xa[it])
        if ctrl.feedback != "motor" and not self.flexible:
            # the rigid table at x + e(x) (an Expression already: Expression(fb) of it was a TypeError, so every
            # run of feedback: table ended in 'internal error')
            fb = fb + lead_error(Expression(xa[0]), p_all)[0]
        csym.GetInputPort("x_ref").FixValue(cctx, [Expression(inp[0])])
        csym.GetInputPort("position").FixValue(cctx, [fb])
        c_update = csym.EvalUniquePeriodicDiscreteUpdate(cctx).get_vector(0).CopyToVector()
        first = j < 0.5
        c_next = [if_then_else(first, c_update[i], Expression(xc[i])) for i in range(nc)]
        dt = h / m
        applied = nc - 1  # the state the axis sees at the end of a sample interval
        if frac > 0:
            # the switch at t_k + f h falls in tick floor(f m): that tick takes the time average of the two
            # outputs over it (the impulse is exact), the ticks before it the old one, the ticks after it the new
            N = len(leaf.taps)
            applied = N + n_delay  # u[k-n]
            w_old = min_(max_(frac * m - j, Expression(0.0)), Expression(1.0))
            force = leaf.gain * (w_old * c_next[N + n_delay + 1] + (1.0 - w_old) * c_next[N + n_delay]) + inp[1]
        else:
            force = leaf.gain * c_next[nc - 1] + inp[1]
        # the axis derivatives, from the leaf system, with the fixed parameters substituted
        asym = MeasuredAxis_[Expression](self.flexible, axis_parameters(), axis_x0, bristles)
        actx = asym.CreateDefaultContext()
        za = MakeVectorVariable(na, "za")
        zt = Variable("zt")
        zf = Variable("zF")
        actx.SetTime(Expression(zt))
        actx.SetContinuousState([Expression(v) for v in za])
        actx.get_mutable_numeric_parameter(0).SetFromVector(p_all)
        asym.GetInputPort("force").FixValue(actx, [Expression(zf)])
        f_expr = asym.EvalTimeDerivatives(actx).CopyToVector()

        def f(tt, x, F):
            env = {zt: tt, zf: F}
            env.update({za[i]: x[i] for i in range(na)})
            return [fi.Substitute(env) for fi in f_expr]

        x = [Expression(v) for v in xa]
        k1 = f(Expression(time), x, force)
        mid = [x[i] + 0.5 * dt * k1[i] for i in range(na)]
        if bristles:
            # dz/dt = v - a(v) z is linear in z: the bristles advance by its exact solution with v and a held
            # over the step (exponential Euler), so their stiff rate a = sigma0 |v| / g (up to 1e5-1e6 1/s)
            # needs no tick of its own; the rest of the state takes the explicit midpoint step
            iz = na - 1
            z_rate = f_expr[iz]

            def z_step(state, tau):
                env = {za[i]: state[i] for i in range(na - 1)}
                env[zt], env[zf] = Expression(time), force
                v_free = z_rate.Substitute({**env, za[iz]: Expression(0.0)})  # = v
                a = v_free - z_rate.Substitute({**env, za[iz]: Expression(1.0)})
                y = a * tau
                decay = exp_(-y)
                phi = if_then_else(y > 1e-6, (1.0 - decay) / max_(y, Expression(1e-6)), 1.0 - 0.5 * y)
                return x[iz] * decay + v_free * tau * phi

            mid[iz] = z_step(x, 0.5 * dt)
        k2 = f(time + 0.5 * dt, mid, force)
        a_next = [x[i] + dt * k2[i] for i in range(na)]
        if bristles:
            a_next[iz] = z_step(mid, dt)
        j_next = if_then_else(j < m - 1.5, j + 1.0, Expression(0.0))
        state = np.concatenate([xc, xa, [j]])
        dynamics = list(c_next) + a_next + [j_next]
        system = SymbolicVectorSystem(time=time, state=state, input=inp, parameter=p_free, dynamics=dynamics,
                                      time_period=dt)
        # the logged output is the state itself: a state output port copies it, where symbolic outputs
        # [x_i] would be evaluated through an environment of every variable at each logged sample
        system.DeclareStateOutputPort("state", DiscreteStateIndex(0))
        b = DiagramBuilder()
        sysm = b.AddSystem(system)
        sysm.set_name("sampled_replay")
        t = self.t
        ref = b.AddSystem(TrajectorySource(PiecewisePolynomial.FirstOrderHold(t, run.x_ref.reshape(1, -1))))
        f_ext = run.f_ext if run.f_ext is not None else np.zeros(run.n)
        # breaks half a tick early: every tick of [t_k, t_k+1) reads f_ext[k], whatever the rounding of t
        ext = b.AddSystem(TrajectorySource(PiecewisePolynomial.ZeroOrderHold(t - 0.5 * dt, f_ext.reshape(1, -1))))
        from pydrake.systems.primitives import Multiplexer

        mux = b.AddSystem(Multiplexer([1, 1]))
        b.Connect(ref.get_output_port(), mux.get_input_port(0))
        b.Connect(ext.get_output_port(), mux.get_input_port(1))
        b.Connect(mux.get_output_port(0), sysm.get_input_port(0))
        log = LogVectorOutput(sysm.get_output_port(0), b, h)
        diagram = b.Build()
        simulator = Simulator(diagram)
        context = simulator.get_mutable_context()
        sysm.GetMyMutableContextFromRoot(context).SetDiscreteState(list(ctrl_state) + axis_x0 + [0.0])
        default = context.Clone()
        layout = {"nc": nc, "na": na, "gain": leaf.gain, "u": len(leaf.taps), "table": it, "applied": applied}
        return sysm, simulator, context, default, log, layout

    def simulate(self, parameters):
        """Simulate the run with axis parameters ``parameters`` (a dict by name, see :data:`AXIS_PARAMETERS`).

        Returns
        -------
        DrakeReplayResult
            All samples NaN, at once, when the parameters need more than :data:`MAX_SUBSTEPS` ticks per sample
            (a diverged replay, which the fits step back from).
        """
        start = _time.perf_counter()
        vec = axis_parameters(**parameters)
        if self.substeps_for(vec) > MAX_SUBSTEPS:  # diverged: see MAX_SUBSTEPS
            return diverged_result(self.run, {k: float(v) for k, v in zip(AXIS_PARAMETERS, vec)},
                                   _time.perf_counter() - start)
        m, sysm, simulator, context, default, log, layout = self._system(vec)
        self.substeps = m
        context.SetTimeStateAndParametersFrom(default)
        offset = _lead_offset(self.run.x_motor[0], vec) if self.flexible else 0.0
        if offset:  # the table on the relaxed spring: x0 + e(x0)
            sub = sysm.GetMyMutableContextFromRoot(context)
            state = sub.get_discrete_state_vector().CopyToVector()
            state[layout["nc"] + 2] += offset
            sub.SetDiscreteState(state)
        if self.free:
            sub = sysm.GetMyMutableContextFromRoot(context)
            sub.get_mutable_numeric_parameter(0).SetFromVector(
                [vec[list(AXIS_PARAMETERS).index(n)] for n in self.free])
        log.FindMutableLog(context).Clear()
        simulator.Initialize()
        n = self.run.n
        simulator.AdvanceTo(float(n * self.h))
        lg = log.FindLog(context)
        data = _on_samples(lg.sample_times(), lg.data(), np.arange(n + 1) * self.h)
        nc = layout["nc"]
        f_ext = self.run.f_ext if self.run.f_ext is not None else 0.0
        x_table = data[nc + layout["table"], :n] if self.flexible else _table_position(data[nc, :n], vec)
        return DrakeReplayResult(
            run=self.run, x_motor=data[nc, :n], x_table=x_table, u=data[layout["u"], 1:],
            force=layout["gain"] * data[layout["applied"], 1:] + f_ext,
            parameters={k: float(v) for k, v in zip(AXIS_PARAMETERS, vec)},
            wall_time=_time.perf_counter() - start)


def set_replay_threads(n):
    """Let :func:`simulate_each` run up to ``n`` replays at once (threads of this process); returns the previous
    number. The default is the cores this process may use; :func:`~drakecreep.gap.drake_diagnosis.diagnose_drake`
    sets its ``workers`` for its run (and in each of its pool's processes)."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError("replay threads", n, "an integer >= 1")
    global _REPLAY_THREADS
    previous, _REPLAY_THREADS = _REPLAY_THREADS, n
    return previous


def simulate_each(replays, parameters):
    """``[rep.simulate(parameters) for rep in replays]``, side by side in up to :func:`set_replay_threads` threads.

    ``Simulator.AdvanceTo`` releases the GIL and each replay has its own diagram and context, so the runs of one
    evaluation (a least-squares residual, a held-out score) simulate in parallel; the results are the serial ones,
    in the same order (``tests/gap/test_drake_replay.py``). On the EMPS half cycles, four runs take 0.11 s in two
    threads instead of 0.165 s serially, and the EMPS diagnosis with two workers 48-50 s instead of 58 s
    (``analysis/bench_diagnose.py``): the process pool keeps both cores busy only while both of its processes have
    work.
    """
    replays = list(replays)
    threads = min(_REPLAY_THREADS, len(replays))
    if threads < 2 or len({id(rep) for rep in replays}) < len(replays):  # one replay twice: not at once
        return [rep.simulate(parameters) for rep in replays]
    with cf.ThreadPoolExecutor(threads) as pool:
        return list(pool.map(lambda rep: rep.simulate(parameters), replays))


def make_replay(run, flexible=False, delay=0.0, quantize=True, free=None, sampled=True):
    """The replay of ``run``: :class:`SampledReplay` (the fast path, whole or fractional delays) when ``sampled``,
    else :class:`DrakeReplay` (error-controlled integration; the cross-check).

    A run logged every few controller ticks (:func:`~drakecreep.gap.measured.controller_ticks`) is replayed on the
    controller's tick (:func:`~drakecreep.gap.measured.at_controller_rate`), ``delay`` in ticks, and its result taken
    at the logged samples (:class:`LoggedReplay`)."""
    check_replayable(run)
    tick = at_controller_rate(run)
    if sampled:
        rep = SampledReplay(tick, flexible=flexible, delay=delay, quantize=quantize, free=free)
    else:
        rep = DrakeReplay(tick, flexible=flexible, delay=delay, quantize=quantize)
    return rep if tick is run else LoggedReplay(run, rep)


class LoggedReplay:
    """A replay of a run logged every ``m`` controller ticks: ``replay`` runs on the controller's tick
    (:func:`~drakecreep.gap.measured.at_controller_rate` of ``run``), and :meth:`simulate` returns its result at
    ``run``'s samples. Every other attribute is the tick replay's."""

    def __init__(self, run, replay):
        self.run, self.replay = run, replay
        self.ticks = controller_ticks(run)

    def __getattr__(self, name):
        if name == "replay":  # not set yet (copy, unpickling): no recursion through __getattr__
            raise AttributeError(name)
        return getattr(self.replay, name)

    def simulate(self, parameters):
        """:meth:`SampledReplay.simulate` (or :meth:`DrakeReplay.simulate`) at the run's logged samples."""
        res = self.replay.simulate(parameters)
        m = self.ticks
        return dataclasses.replace(res, run=self.run, x_motor=res.x_motor[::m], x_table=res.x_table[::m],
                                   u=res.u[::m], force=res.force[::m])


def compiled_axis(flexible, initial_state, bristles=False):
    """:class:`MeasuredAxis` as a ``SymbolicVectorSystem``: input ``[F]``, parameters in
    :data:`AXIS_PARAMETERS` order, output the full state ``[x_m, v_m(, x_t, v_t)(, z)]``.

    The equations are the leaf system's, evaluated once on symbolic variables (``ToSymbolic``).
    """
    sym = MeasuredAxis_[Expression](flexible, axis_parameters(), initial_state, bristles)
    ctx = sym.CreateDefaultContext()
    x = MakeVectorVariable(len(initial_state), "x")
    u = MakeVectorVariable(1, "F")
    p = MakeVectorVariable(len(AXIS_PARAMETERS), "p")
    time = Variable("t")
    ctx.SetTime(Expression(time))
    ctx.SetContinuousState([Expression(v) for v in x])
    ctx.get_mutable_numeric_parameter(0).SetFromVector([Expression(v) for v in p])
    sym.GetInputPort("force").FixValue(ctx, [Expression(u[0])])
    xdot = sym.EvalTimeDerivatives(ctx).CopyToVector()
    system = SymbolicVectorSystem(time=time, state=x, input=u, parameter=p, dynamics=xdot)
    # the output is the state itself: a state output port copies it (symbolic outputs [x_i] were evaluated
    # through an environment of every variable)
    system.DeclareStateOutputPort("state", ContinuousStateIndex(0))
    return system


def _on_samples(times, data, t):
    """Columns of a log at the instants ``t`` (the last logged value at or before each instant)."""
    idx = np.searchsorted(times, t + 1e-9 * max(1.0, float(t[-1])), side="right") - 1
    if idx[0] < 0:
        raise RuntimeError("the replay log starts after the first sample")
    return data[:, idx]


def drake_replay(run, parameters, flexible=False, delay=0.0, quantize=True):
    """Build the replay diagram of ``run`` and simulate it once (see :class:`DrakeReplay`)."""
    return make_replay(run, flexible=flexible, delay=delay, quantize=quantize, sampled=False).simulate(parameters)


#: time regimes (:func:`drakecreep.gap.residuals.classify_regimes`) whose force error
#: :func:`drake_replay_errors` adds as ``force_<regime>`` (a candidate's ``regime``:
#: :class:`drakecreep.gap.drake_effects.DrakeEffect`)
REGIME_ERRORS = ("constant_speed",)
#: fewest samples of a regime for its force error (fewer: the key is left out)
MIN_REGIME_SAMPLES = 20
#: Pieces of equal length a run's force error is also given over (``force_piece_<i>``): the claim test's pieces for
#: an effect that one or two fast held-out runs carry (:attr:`drakecreep.gap.drake_effects.DrakeEffect.piece_test`).
RUN_PIECES = 4


def piece_keys(pieces=RUN_PIECES):
    """The error keys of a run's pieces (:func:`drake_replay_errors`), in time order."""
    return tuple(f"force_piece_{i}" for i in range(pieces))


#: octave bands [Hz] centred half an octave apart, 5 * 2^(k/2) from 5 to 320 Hz (the axial mode's search range
#: with a quarter octave to spare): :func:`drake_replay_errors` adds the force error in each as
#: ``force_band_<lo>-<hi>_Hz``, the signature band of a fitted mode (:func:`mode_band`)
MODE_BANDS_HZ = tuple((5.0 * 2.0 ** ((k - 1) / 2.0), 5.0 * 2.0 ** ((k + 1) / 2.0)) for k in range(13))
#: highest band edge, as a share of the sample rate (the Butterworth band-pass below Nyquist)
BAND_EDGE_SHARE = 0.45


def _band_name(lo, hi):
    return f"band_{lo:.3g}-{hi:.3g}_Hz"


def mode_band(frequency):
    """The band of :data:`MODE_BANDS_HZ` a mode at ``frequency`` [Hz] is the signature of: the one whose centre is
    nearest on a log scale (the mode at least a quarter octave inside it), as the regime name
    ``band_<lo>-<hi>_Hz`` whose force error is ``force_band_<lo>-<hi>_Hz``."""
    k = int(np.clip(round(2.0 * math.log2(max(float(frequency), 1e-9) / 5.0)), 0, len(MODE_BANDS_HZ) - 1))
    return _band_name(*MODE_BANDS_HZ[k])


@functools.lru_cache(maxsize=8)
def _band_filters(fs):
    """``(name, sos)`` of each band of :data:`MODE_BANDS_HZ` below :data:`BAND_EDGE_SHARE` of the sample rate
    ``fs`` (designed once per rate: every replay's errors use them)."""
    return tuple((_band_name(lo, hi), signal.butter(4, [lo, min(hi, BAND_EDGE_SHARE * fs)], btype="bandpass", fs=fs,
                                                    output="sos"))
                 for lo, hi in MODE_BANDS_HZ if lo < BAND_EDGE_SHARE * fs)


def _band_errors(measured, simulated, dt):
    """Force error [%] in each band of :data:`MODE_BANDS_HZ` below :data:`BAND_EDGE_SHARE` of the sample rate:
    measured and simulated force band-passed alike (4th-order Butterworth, forward-backward), so a simulated
    oscillation out of phase with the measured one counts against the model."""
    out = {}
    if measured.size < 64:  # shorter than the filters' padding
        return out
    for name, sos in _band_filters(1.0 / dt):
        y = signal.sosfiltfilt(sos, measured)
        if np.any(y != 0):
            out["force_" + name] = relative_error(y, signal.sosfiltfilt(sos, simulated))
    return out


def drake_replay_errors(result, cutoff=None, order=4, bands=True):
    """Relative errors [%] of position, velocity, acceleration and force (as :func:`drakecreep.gap.replay.replay_errors`).

    Velocity and acceleration of the measured and simulated motor positions go through the same IDIM
    processing (Butterworth ``cutoff`` forward-backward, central differences); ``table_position`` is added when the
    run has a linear scale, and with it ``transmission``, the error of the position the screw adds between the
    motor and the table (:func:`transmission_position`: its windup and any kinematic error) unless the measured
    one is constant; ``force_level`` (the run's own friction level) when the result carries its
    parameters; ``force_constant_speed`` (for each regime of :data:`REGIME_ERRORS`) the force error over the
    samples of that regime (:func:`drakecreep.gap.residuals.classify_regimes` of the reference and the measured
    speed) when the run has at least :data:`MIN_REGIME_SAMPLES` of them; ``force_band_<lo>-<hi>_Hz`` the force
    error in each band of :data:`MODE_BANDS_HZ` (:func:`mode_band`) unless ``bands`` is false (a fit's training
    errors and the ``drakecreep`` kind's, which no band test reads: the bands are most of this function's cost);
    ``force_piece_<i>`` (:func:`piece_keys`) the force error over each of :data:`RUN_PIECES` windows of equal
    length, in time order, when the run has at least ``RUN_PIECES * MIN_REGIME_SAMPLES`` samples and a force in
    every piece; ``force_lowpass`` the part of the force error below ``cutoff`` (the force residual through the
    same zero-phase Butterworth low-pass, over the norm of the whole measured force, so that ``force^2`` is about
    ``force_lowpass^2`` plus the part above). Under a speed loop that differences encoder counts, the force carries
    a ripple whose sample pattern no replay reproduces, and any change of the model draws it anew (docs
    gap_benchmark.md 3ce): ``force_lowpass`` leaves most of it out.
    """
    run = result.run
    _, dq, ddq = filtered_derivatives(run.x_motor, run.dt, cutoff, order)
    _, dq_s, ddq_s = filtered_derivatives(result.x_motor, run.dt, cutoff, order)
    out = {
        "position": relative_error(run.x_motor, result.x_motor),
        "velocity": relative_error(dq, dq_s),
        "acceleration": relative_error(ddq, ddq_s),
        "force": relative_error(run.force, result.force),
    }
    if run.x_table is not None:
        out["table_position"] = relative_error(run.x_table, result.x_table)
        deflection = transmission_position(run.x_motor, run.x_table)
        if np.any(deflection != 0):
            out["transmission"] = relative_error(deflection, transmission_position(result.x_motor, result.x_table))
    if result.parameters:
        out["force_level"] = _force_level_error(result, cutoff, order)
    regimes = classify_regimes(np.arange(run.n) * run.dt, run.x_ref, dq)
    force, force_sim = np.asarray(run.force), np.asarray(result.force)
    below = filtered_derivatives(force - force_sim, run.dt, cutoff, order)[0]
    out["force_lowpass"] = float(100.0 * np.linalg.norm(below) / np.linalg.norm(force))
    for regime in REGIME_ERRORS:
        sel = regimes == regime
        if np.count_nonzero(sel) >= MIN_REGIME_SAMPLES and np.any(force[sel] != 0):
            out[f"force_{regime}"] = relative_error(force[sel], force_sim[sel])
    if run.n >= RUN_PIECES * MIN_REGIME_SAMPLES:
        edges = np.linspace(0, run.n, RUN_PIECES + 1).astype(int)
        if all(np.any(force[a:b] != 0) for a, b in zip(edges[:-1], edges[1:])):
            for key, a, b in zip(piece_keys(), edges[:-1], edges[1:]):
                out[key] = relative_error(force[a:b], force_sim[a:b])
    if bands:
        out.update(_band_errors(force, force_sim, run.dt))
    return out


def _force_level_error(result, cutoff, order):
    """Force error [%] with the run's own friction level: the simulated friction force scaled by the
    least-squares factor that best explains the force residual (the closed-loop counterpart of
    :func:`drakecreep.gap.screen.screen_effect`'s ``run_level``).

    In the position loop, a friction level ``s`` times the model's is supplied by the controller at the
    frequencies the loop follows: the measured force is, to first order, the simulated one plus ``(s - 1) f``
    with ``f`` the model's friction on the simulated motion (the table's, behind the screw). Friction drifts
    between runs, so a held-out run's level is a nuisance, not something a candidate may be credited with.
    """
    run = result.run
    p = axis_parameters(**result.parameters)
    _, dv, _ = filtered_derivatives(result.x_table, run.dt, cutoff, order)
    t = np.arange(run.n) * run.dt
    # the nut's load as the rigid axis has it (nut_load)
    load = nut_load(applied_force(result.force, p) + axis_ripple(result.x_motor, t, p), p,
                    friction=axis_friction(dv, p, result.x_table, t, 0.0))
    fr = np.asarray(axis_friction(dv, p, result.x_table, t, load), dtype=float)
    e = np.asarray(run.force, dtype=float) - result.force
    scale = float(fr @ e) / max(float(fr @ fr), 1e-300)
    return relative_error(run.force, result.force + scale * fr)


def rms_force_error(errors, key="force"):
    """RMS over runs of the force error [%] of ``{label: errors}`` (:func:`drake_replay_errors`; ``key``
    ``"force_lowpass"`` for its part below the cut-off); NaN if empty."""
    values = [e[key] for e in errors.values()]
    return float(math.sqrt(sum(v * v for v in values) / len(values))) if values else float("nan")


def replay_params(run, params=None, quantize=True):
    """The :class:`~drakecreep.params.DriveParams` a ``kind: drakecreep`` run is replayed with.

    ``params`` (default ``run.meta.params``) with the run's declared sensor resolutions
    (``run.meta.sensors``: an encoder count at the load becomes ``encoder_counts_per_rev = lead / count``, the
    scale resolution is taken as is; a resolution of 0 means "not declared" and keeps the params file's);
    with ``quantize`` false both sensors are ideal.

    Raises
    ------
    InputError
        No params, or an encoder count that does not divide the lead into a whole number of counts.
    """
    from drakecreep.params import MAX_INT, MIN_ENCODER_COUNTS, DriveParams

    if params is None:
        check_replayable(run)
        params = run.meta.params
    if not isinstance(params, DriveParams):
        raise InputError("params", type(params).__name__, "drakecreep DriveParams (a params file)")
    sensors = params.sensors
    declared = run.meta.sensors
    if declared.encoder_resolution > 0:
        counts = params.screw.lead / declared.encoder_resolution
        if counts > MAX_INT:  # 1e-30 m was 'encoder_counts_per_rev: got 4999999999999999791559868416', unwritten
            raise InputError("sensors.encoder_resolution", declared.encoder_resolution,
                             f"at least the lead / {MAX_INT} counts per revolution, {params.screw.lead / MAX_INT:.3g} m "
                             "(or 0 for none)")
        if abs(counts - round(counts)) > 1e-6 * counts or round(counts) < 1:
            raise InputError("sensors.encoder_resolution", declared.encoder_resolution,
                             f"a whole fraction of the lead {params.screw.lead:g} m (lead / counts per revolution)")
        if round(counts) < MIN_ENCODER_COUNTS:  # (the params' own bound, named by the metadata's field)
            raise InputError("sensors.encoder_resolution", declared.encoder_resolution,
                             f"at most the lead / {MIN_ENCODER_COUNTS}, {params.screw.lead / MIN_ENCODER_COUNTS:.3g} m "
                             f"(an encoder of at least {MIN_ENCODER_COUNTS} counts per revolution), or 0 for none")
        sensors = dataclasses.replace(sensors, encoder_counts_per_rev=int(round(counts)))
    if declared.scale_resolution > 0:
        try:
            sensors = dataclasses.replace(sensors, scale_resolution=declared.scale_resolution)
        except InputError as err:  # the metadata's key, not the params file's field the value goes to
            raise err.renamed("sensors.scale_resolution") from None
    if not quantize:
        sensors = dataclasses.replace(sensors, encoder_counts_per_rev=0, scale_resolution=0.0)
    return dataclasses.replace(params, sensors=sensors)


def check_travel(run, params, x_origin=None):
    """Raise :class:`InputError` unless ``run``'s positions keep the nut on ``params``' screw.

    A run's positions are the params file's table coordinates (at table position 0 the nut is
    ``screw.nut_start_distance`` from the thrust bearing): the replay puts the nut where the run was
    (:func:`at_origin`), so that the shaft's stiffness is the one at the run's position. Every position of
    ``x_motor`` and ``x_ref`` (and ``x_origin``, the diagram's table position 0, when given) must lie between
    ``-nut_start_distance`` and ``length - nut_start_distance``.
    """
    screw = params.screw
    lo, hi = -screw.nut_start_distance, screw.length - screw.nut_start_distance
    x = np.concatenate([run.x_motor, run.x_ref] + ([[x_origin]] if x_origin is not None else []))
    first, last = float(np.min(x)), float(np.max(x))
    if not (lo < first and last < hi):
        raise InputError(f"x_motor (run {run.label})", f"positions from {first:.6g} to {last:.6g} m",
                         f"table positions in the params file's coordinates that keep the nut on the screw, between "
                         f"{lo:.6g} and {hi:.6g} m (at 0 the nut is screw.nut_start_distance = "
                         f"{screw.nut_start_distance:g} m from the thrust bearing, the shaft {screw.length:g} m long)")


def at_origin(params, x_origin):
    """``params`` with what is fixed to the machine moved from its table position 0 to ``x_origin`` [m] (the
    motor's travel at the replayed diagram's angle 0; the run's first position, where the diagram starts): the
    phases of what is fixed to the screw and the motor (the lead error, the cogging), the friction map's travel
    (``friction.position_map_start`` and ``_end`` less ``x_origin``: fixed to the guides) and the nut's distance
    from the thrust bearing (``screw.nut_start_distance + x_origin``), so that the shaft's stiffness is the one
    where the run was. They belong to the machine, not to the run.

    Replaying a run at 0.094 m of a flexible axis with the nut at ``nut_start_distance`` instead, as before
    session 73, made the chain 14 % stiffer and 31 % more damped than where the run was (development dataset
    9014, docs/gap_benchmark.md 3cb): the truth's delay of 8 speed-loop ticks, which drives its 207 Hz axial mode
    unstable, left that replay stable, and at the run's position it oscillates at 203 Hz like the truth.
    """
    from drakecreep.params import with_value

    if x_origin == 0.0:
        return params
    d = params.disturbance
    for on, period, phases in ((d.has_lead_error, d.lead_error_period, ("lead_error_phase", "lead_error_2_phase")),
                               (d.has_cogging, d.cogging_period, ("cogging_phase", "cogging_2_phase"))):
        if not on:
            continue
        turn = 2.0 * math.pi * x_origin / period
        for harmonic, name in enumerate(phases, start=1):
            value = getattr(d, name) + harmonic * turn
            params = with_value(params, f"disturbance.{name}", math.remainder(value, 2.0 * math.pi))
    f = params.friction
    if f.has_position_map:
        # moved down, the start goes first, moved up the end: end > start holds between the two steps
        order = ("position_map_start", "position_map_end")[::1 if x_origin > 0 else -1]
        for name in order:
            params = with_value(params, f"friction.{name}", getattr(f, name) - x_origin)
    return with_value(params, "screw.nut_start_distance", params.screw.nut_start_distance + x_origin)


def replay_drakecreep(run, params=None, quantize=True, load_case=0, backend="compiled"):
    """Replay ``run`` through the project's feed-drive diagram (``controller: {kind: drakecreep}``).

    The diagram is :func:`drakecreep.model.diagram.build_diagram` of ``params`` (default
    ``run.meta.params``, with the run's declared sensor resolutions, :func:`replay_params`): PI cascade with
    ``params.controller``'s gains and periods, encoder and scale (ideal when ``quantize`` is false), motor,
    elastic screw and table with their friction law and disturbances; the ramp reference is replaced by the
    measured one (``TrajectorySource`` of a first-order hold, the speed its slope) and ``f_ext`` (a
    zero-order hold) is added to the push on the table. Positions are relative to the first sample (the
    diagram starts at rest, in equilibrium under ``load_case``, its position feedback reading the first sample:
    under an axial load the screw is wound up, ``initial_conditions``' ``x_ref0``); the lead error, fixed to the screw, keeps
    its phase at the run's absolute start position ``x_motor[0]`` (``disturbance.lead_error_phase`` is its
    phase at the screw's position 0), and so does the cogging, fixed to the motor (``disturbance.cogging_phase``).

    ``backend="compiled"`` (default) simulates the diagram compiled into ``SymbolicVectorSystem`` systems
    (:func:`drakecreep.sim.compiled.compile_diagram`, the reference and ``f_ext`` its ``inputs`` port, fed
    by C++ ``TrajectorySource`` systems: no Python in the loop); ``"leaf"`` the Python leaf systems (same
    equations, same integrator; kept as the cross-check, ``tests/gap/test_drake_replay.py``). A fractional
    ``controller.computation_delay`` is replayed on the leaf systems whatever ``backend`` says (the compiled path
    takes one sampling offset; about 10 times slower).

    Parameters
    ----------
    run : drakecreep.gap.measured.MeasuredRun
    params : drakecreep.params.DriveParams, optional
    quantize : bool
    load_case : int
        Load case of ``params`` the run was taken under (0 = unloaded).
    backend : {"compiled", "leaf"}

    Returns
    -------
    DrakeReplayResult
        ``u`` is the force command [N] of the cascade; ``force = u_gain u + f_ext``.
    """
    from pydrake.systems.primitives import ConstantVectorSource, Multiplexer

    from drakecreep.model.diagram import build_diagram, initial_conditions
    from drakecreep.scenario import MIN_FEED, Scenario
    from drakecreep.sim.compiled import compile_diagram
    from drakecreep.sim.simulation import make_simulator, target_accuracy

    if backend not in ("compiled", "leaf"):
        raise InputError("backend", backend, "compiled or leaf")
    params = replay_params(run, params, quantize)
    ctrl = params.controller
    if backend == "compiled" and ctrl.sampled and not float(ctrl.computation_delay).is_integer():
        backend = "leaf"  # a fractional delay is a second sampling offset, which the compiled path refuses
    start = _time.perf_counter()
    t = run.t - run.t[0]
    # the diagram starts at rest with its table at 0 and the screw wound up by the axial load (the load case's fx,
    # with loads.constant_force): the motor at theta0, the position feedback reading x_ref0. The run's first
    # readings are that state: the origin is where the run's feedback sensor puts the diagram's
    def origin(p):
        if ctrl.position_feedback == "table" and run.x_table is not None:
            return float(run.x_table[0])
        rest = initial_conditions(p, Scenario(load_case=int(load_case)))
        return float(run.x_motor[0]) - (rest["x_ref0"] if ctrl.position_feedback == "motor"
                                        else rest["theta0"] * p.screw.lead / (2 * math.pi))

    x_origin = origin(params)
    check_travel(run, params, x_origin)
    x_origin = origin(at_origin(params, x_origin))  # the windup of the shaft where the run was (a load case's)
    check_travel(run, params, x_origin)
    params = at_origin(params, x_origin)
    xr = run.x_ref - x_origin
    vr = np.gradient(xr, t)
    f_ext = run.f_ext if run.f_ext is not None else np.zeros(run.n)

    def sources():  # the reference [x_ref, v_ref] and f_ext, built only where they are wired
        return (TrajectorySource(PiecewisePolynomial.FirstOrderHold(t, np.vstack([xr, vr]))),
                TrajectorySource(PiecewisePolynomial.ZeroOrderHold(t, f_ext.reshape(1, -1))))
    feed = float(np.max(np.abs(vr))) or 1e-6
    scenario = Scenario(feed=min(max(feed, MIN_FEED), 1.0), load_case=int(load_case), duration=max(float(t[-1]), 1e-3))
    # u[k] is the force command the controller computes at t_k from the measurement at t_k (what the truth and a
    # drive's own trace record). A log published at t_k holds the command before the speed loop's update at t_k
    # (the last tick of the previous sample): with the position loop at 1 kHz and the speed loop at 4 kHz that
    # tick's force lags the sample's by an acceleration-dependent step (+-7 kg of apparent mass on a 72 kg
    # axis, docs/gap_benchmark.md, 3d). So the log runs at the speed loop's period and u is read one tick later.
    tick = min(ctrl.velocity_period, run.dt) if ctrl.sampled else run.dt
    b = DiagramBuilder()
    if backend == "compiled":
        fd = build_diagram(params, scenario, reference=ConstantVectorSource(np.zeros(2)),
                           external_force=ConstantVectorSource(np.zeros(1)))
        # only the three signals read below: the plant's output is evaluated at every tick and log
        compiled = compile_diagram(fd, inputs=("reference", "external_force"),
                                   signals=("motor_angle", "table_position", "force_command"))
        system = b.AddSystem(compiled.diagram)
        if not np.any(f_ext):
            # no external force (most runs): one source of [x_ref, v_ref, 0], the same inputs as the multiplexer's
            # (a first-order hold of zeros is 0.0) without a multiplexer and a second source to evaluate at every
            # stage of every step
            inputs = b.AddSystem(TrajectorySource(PiecewisePolynomial.FirstOrderHold(
                t, np.vstack([xr, vr, np.zeros_like(t)]))))
        else:
            reference, ext = (b.AddSystem(source) for source in sources())
            inputs = b.AddSystem(Multiplexer([2, 1]))
            b.Connect(reference.get_output_port(), inputs.get_input_port(0))
            b.Connect(ext.get_output_port(), inputs.get_input_port(1))
        b.Connect(inputs.get_output_port(0), system.GetInputPort("inputs"))
        logs = {"signals": LogVectorOutput(system.GetOutputPort("signals"), b, tick)}
        names = compiled.signal_names
        rows = [names.index(k) for k in ("motor_angle", "table_position", "force_command")]
    else:
        reference, ext = sources()
        fd = build_diagram(params, scenario, reference=reference, external_force=ext)
        system = b.AddSystem(fd.diagram)
        logs = {key: LogVectorOutput(system.GetOutputPort(key), b, tick)
                for key in ("motor.motor_state", "table.table_state", "controller.controller_signals")}
        rows = None
    root = b.Build()
    context = root.CreateDefaultContext()
    if backend == "compiled":
        compiled.set_initial_state(root.GetMutableSubsystemContext(system, context))
    simulator = make_simulator(root, context, params.simulation, target_accuracy(params))
    after = tick if ctrl.sampled else 0.0
    simulator.AdvanceTo(float(t[-1]) + after)

    def sampled(key, at):
        log = logs[key].FindLog(context)
        return _on_samples(log.sample_times(), log.data(), at)

    if rows is not None:
        signals = sampled("signals", t)
        angle, x_table = signals[rows[0]], signals[rows[1]]
        u = sampled("signals", t + after)[rows[2]]
    else:
        angle, x_table = sampled("motor.motor_state", t)[0], sampled("table.table_state", t)[0]
        u = sampled("controller.controller_signals", t + after)[1]
    x_motor = angle * params.screw.lead / (2 * math.pi) + x_origin
    x_table = x_table + x_origin
    # the controller's force command is in N; the run's u is in its u_units (u_gain N per unit): a run in A
    # compares its u with the command over the gain, and the force is the command itself
    force = u + f_ext
    u = u / run.u_gain
    return DrakeReplayResult(run=run, x_motor=x_motor, x_table=x_table, u=u, force=force,
                             wall_time=_time.perf_counter() - start,
                             integrator_steps=int(simulator.get_integrator().get_num_steps_taken()))


#: ``(path, value)`` settings that make a params file quick to replay, for studies and tests that generate
#: many runs of the project's controller: a Stribeck law regularised at 0.1 mm/s (no LuGre bristle state),
#: accuracy 1e-4, the nut's friction on the table (no second friction state on the screw) and an ideal
#: current loop (no 0.1 ms lag to resolve). The rig is then no longer the paper's; use it for the gap
#: machinery, not for creep verdicts.
QUICK_REPLAY_SETTINGS = (("friction.law", "stribeck"), ("friction.regularization_velocity", 1e-4),
                         ("simulation.accuracy", 1e-4), ("friction.nut_friction_on", "table"),
                         ("motor.current_loop_time_constant", 0.0))


def quick_replay_params(params):
    """``params`` with :data:`QUICK_REPLAY_SETTINGS` applied (a new :class:`~drakecreep.params.DriveParams`)."""
    from drakecreep.params import with_value

    for path, value in QUICK_REPLAY_SETTINGS:
        params = with_value(params, path, value)
    return params


def simulated_runs(truth, speeds, *, declared=None, n=500, dt=1e-3, noise=0.0, seed=0, leg=0.2,
                   starts=(0.03, 0.26), f_ext=None, label="r", origins=None):
    """Runs of the project's controller as a measurement of the rig ``truth`` would record them.

    Each run is an out-and-back reference (:func:`drakecreep.gap.truth.out_and_back`) at one of ``speeds``,
    replayed through ``truth``'s diagram (:func:`replay_drakecreep`), with white noise of standard deviation
    ``noise`` [N] added to ``u``; the metadata declare ``kind: drakecreep`` and the params file ``declared``
    (default ``truth``): what the user's model says the rig is.

    Parameters
    ----------
    truth, declared : drakecreep.params.DriveParams
    speeds : sequence of float
        Reference speed of each run [m/s].
    n : int
        Samples per run.
    dt : float
        Sample time [s].
    noise : float
        Standard deviation of the noise on ``u`` [N].
    seed : int
        Seeds the noise: run ``i``'s generator is ``numpy.random.default_rng(seed + i)``.
    leg, starts : float, tuple of float
        Duration of each leg and its start times [s] (:func:`~drakecreep.gap.truth.out_and_back`).
    f_ext : array_like, optional
        Known external force on the table, the same for every run [N].
    label : str
        Run labels are ``label + index``.
    origins : sequence of float, optional
        Position where each run starts [m] (default 0 for all): where a lead error fixed to the screw is in
        its period.

    Returns
    -------
    list of drakecreep.gap.measured.MeasuredRun
    """
    from drakecreep.gap.measured import ControllerMeta, MeasuredMeta, MeasuredRun
    from drakecreep.gap.truth import out_and_back

    meta = MeasuredMeta(u_units="N", u_gain=1.0, params=truth if declared is None else declared,
                        controller=ControllerMeta(kind="drakecreep"))
    t = np.arange(n) * dt
    force = None if f_ext is None else np.asarray(f_ext, dtype=float)
    runs = []
    origins = [0.0] * len(speeds) if origins is None else [float(o) for o in origins]
    if len(origins) != len(speeds):
        raise InputError("origins", len(origins), f"one start position per speed ({len(speeds)})")
    for i, v in enumerate(speeds):
        x_ref = out_and_back(v, origins[i], n=n, dt=dt, leg=leg, starts=starts)
        blank = MeasuredRun(t=t, x_ref=x_ref, x_motor=x_ref, u=np.zeros(n), meta=meta, f_ext=force,
                            label=f"{label}{i}")
        sim = replay_drakecreep(blank, truth)
        u = sim.u + (np.random.default_rng(seed + i).normal(0.0, noise, n) if noise > 0 else 0.0)
        runs.append(dataclasses.replace(blank, x_motor=sim.x_motor, u=u, x_table=sim.x_table))
    return runs
