"""The symbolic fast path: one feed-drive diagram turned into one ``SymbolicVectorSystem`` (and a hold).

The leaf systems are written once as ``TemplateSystem``s; here the whole diagram is converted with
``ToSymbolic()``, its time derivatives, its periodic discrete update and every recorded signal are
evaluated once as symbolic expressions of ``(t, x_continuous, x_discrete)``, and those expressions
become a Drake C++ ``SymbolicVectorSystem`` and a hold:

* ``plant``: continuous state, input = the discrete state (and the inputs), output = recorded signals +
  continuous state + the periodic update ``g(t, x_c, x_d)``;
* ``sampler``: a ``ZeroOrderHold`` with the diagram's period whose state is the discrete state, sampling ``g``
  from the plant's output (no feedthrough, so no algebraic loop); the exported output ``signals`` leaves ``g``
  out. Several sampled leaves (controller, compensator on the encoder speed) are fine when they share one period
  and offset 0: their groups are concatenated. A second timing (a fractional ``controller.computation_delay``
  switches the output between samples) is refused with ``NotImplementedError``;
  :func:`drakecreep.sim.simulation.simulate` says so up front.

Same equations, same state ordering, no Python in the simulation loop (measured about 10x faster end to
end than the Python leaf systems, see ``analysis/bench_simulation.py``; the update in the plant's output, not a
system of its own, 1.2-1.5x faster than that with the same bits, ``analysis/bench_compiled.py``).

Signals from outside (a measured reference, an external force): build the feed drive with
``ConstantVectorSource`` placeholders (``build_diagram(..., reference=ConstantVectorSource([0, 0]))``) and
name them in ``inputs``; their values become symbolic variables, and the compiled diagram gets an input
port ``inputs`` (their values concatenated, in the order named) that a ``TrajectorySource`` can drive
(:func:`drakecreep.gap.drake_replay.replay_drakecreep`).
"""

from dataclasses import dataclass

import numpy as np
from pydrake.symbolic import Expression, MakeVectorVariable, Variable
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import Demultiplexer, Multiplexer, SymbolicVectorSystem, ZeroOrderHold

__all__ = ["CompiledDrive", "compile_diagram", "symbolic_equations"]


@dataclass
class SymbolicEquations:
    """The diagram's equations as symbolic expressions."""

    time: Variable
    xc: np.ndarray
    xd: np.ndarray
    derivatives: np.ndarray
    update: np.ndarray
    period: float
    signals: np.ndarray
    xc0: np.ndarray
    xd0: np.ndarray
    inputs: np.ndarray = None
    signal_names: list = None


def symbolic_equations(feed_drive, inputs=(), signals=None):
    """Evaluate ``feed_drive``'s derivatives, discrete update and signals symbolically.

    Parameters
    ----------
    feed_drive : drakecreep.model.diagram.FeedDrive
    inputs : sequence of str
        Names of ``ConstantVectorSource`` subsystems whose values become symbolic input variables
        (``SymbolicEquations.inputs``, concatenated in this order).
    signals : sequence of str, optional
        The recorded signals to evaluate, in this order (names of ``feed_drive.signal_names``); default all.

    Returns
    -------
    SymbolicEquations

    Raises
    ------
    ValueError
        A name in ``signals`` that is not a signal of ``feed_drive``, or one named twice.
    """
    if signals is not None:
        unknown = [n for n in signals if n not in feed_drive.signal_names]
        if unknown or len(set(signals)) < len(signals):
            raise ValueError(f"signals: got {list(signals)}; allowed: distinct names among "
                             + ", ".join(feed_drive.signal_names))
    diagram = feed_drive.diagram
    context0 = diagram.CreateDefaultContext()
    xc0 = context0.get_continuous_state_vector().CopyToVector()
    nd_groups = context0.num_discrete_state_groups()
    # every sampled leaf (controller, sampled compensator) has its own group; they share one timing
    # (checked below), so their states are concatenated into one vector held by one sampler
    sizes = [context0.get_discrete_state(i).size() for i in range(nd_groups)]
    xd0 = (np.concatenate([context0.get_discrete_state(i).value() for i in range(nd_groups)])
           if nd_groups else np.zeros(0))

    sym = diagram.ToSymbolic()
    ctx = sym.CreateDefaultContext()
    t = Variable("t")
    ctx.SetTime(Expression(t))
    xc = MakeVectorVariable(len(xc0), "xc")
    xd = MakeVectorVariable(len(xd0), "xd")
    ctx.SetContinuousState([Expression(v) for v in xc])
    u = []
    for name in inputs:
        source = sym.GetSubsystemByName(name)
        value = source.get_mutable_source_value(source.GetMyMutableContextFromRoot(ctx))
        names = MakeVectorVariable(value.size(), name)
        value.SetFromVector([Expression(v) for v in names])
        u.extend(names)
    period = 0.0
    update = np.zeros(0, dtype=object)
    if len(xd0):
        start = 0
        for i, n in enumerate(sizes):
            ctx.SetDiscreteState(i, [Expression(v) for v in xd[start:start + n]])
            start += n
        attribute = sym.GetUniquePeriodicDiscreteUpdateAttribute()
        if attribute is None:
            raise NotImplementedError(
                "the fast path needs all discrete updates at one period and offset (a fractional "
                "controller.computation_delay adds a second offset): use simulation.backend: leaf"
            )
        if attribute.offset_sec() != 0.0:
            raise NotImplementedError("the fast path needs discrete updates with zero offset")
        period = attribute.period_sec()
        values = sym.EvalUniquePeriodicDiscreteUpdate(ctx)
        update = np.concatenate([values.get_vector(i).CopyToVector() for i in range(nd_groups)])
    derivatives = sym.EvalTimeDerivatives(ctx).CopyToVector()
    values = {}
    where = {name: source for name, source, _ in feed_drive.signals}
    names = feed_drive.signal_names if signals is None else list(signals)
    evaluated = []
    for name in names:
        system, port, index = where[name]
        key = f"{system}.{port}"
        if key not in values:
            values[key] = sym.GetOutputPort(key).Eval(ctx)
        evaluated.append(values[key][index])
    return SymbolicEquations(
        time=t, xc=xc, xd=xd, derivatives=derivatives, update=update, period=period,
        signals=np.array(evaluated, dtype=object), xc0=xc0, xd0=xd0, inputs=np.array(u, dtype=object),
        signal_names=names,
    )


@dataclass
class CompiledDrive:
    """A compiled feed drive: a Diagram of ``SymbolicVectorSystem``s.

    The diagram's output port ``signals`` carries the recorded signals (in ``signal_names`` order)
    followed by the continuous state.
    """

    diagram: object
    plant: object
    sampler: object
    equations: SymbolicEquations
    signal_names: list

    def default_context(self):
        """A context holding the feed drive's initial state."""
        context = self.diagram.CreateDefaultContext()
        self.set_initial_state(context)
        return context

    def set_initial_state(self, context):
        """Write the source diagram's initial state into ``context`` (this diagram's own context)."""
        eq = self.equations
        self.diagram.GetMutableSubsystemContext(self.plant, context).SetContinuousState(eq.xc0)
        if self.sampler is not None:
            self.sampler.SetVectorState(self.diagram.GetMutableSubsystemContext(self.sampler, context), eq.xd0)


def compile_diagram(feed_drive, inputs=(), signals=None):
    """Compile ``feed_drive`` into ``SymbolicVectorSystem``s (see module docstring).

    Parameters
    ----------
    feed_drive : drakecreep.model.diagram.FeedDrive
    inputs : sequence of str
        ``ConstantVectorSource`` subsystems to turn into the exported input port ``inputs``.
    signals : sequence of str, optional
        The recorded signals the output port ``signals`` carries, in this order (names of
        ``feed_drive.signal_names``); default all. The plant's output is evaluated at every sample tick (the
        hold samples the update from it) and at every log, so a caller that reads few signals names them: the same
        bits, 1.07-1.22 times faster with three than with all 15-17 (``analysis/bench_drive_fit.py``).

    Returns
    -------
    CompiledDrive

    Raises
    ------
    ValueError
        As :func:`symbolic_equations`: a name in ``signals`` that is not a signal of ``feed_drive``, or one named twice.
    """
    eq = symbolic_equations(feed_drive, inputs, signals)
    nu = len(eq.inputs)
    builder = DiagramBuilder()
    recorded = np.concatenate([eq.signals, [Expression(v) for v in eq.xc]])
    # the periodic update g(t, x_c, x_d, inputs) is more of the plant's output (its input carries x_d and the
    # inputs), sampled by a zero-order hold with the diagram's period whose state is the discrete state: at each
    # tick it samples g evaluated with the state before the tick, and the hold has no feedthrough, so there is no
    # algebraic loop. (A discrete SymbolicVectorSystem next to continuous states trips a DRAKE_DEMAND in
    # SymbolicVectorSystem::DoCalcTimeDerivatives in Drake 1.51, which every leaf gets called. Until session 78 g
    # was a memoryless SymbolicVectorSystem of its own; SymbolicVectorSystem wants a state, so it carried a constant
    # continuous one, and every derivative evaluation of the diagram evaluated that system's input, the plant's
    # whole output through a multiplexer, for its zero derivative: 1.2-1.5x of a simulation's CPU, for the same
    # bits, analysis/bench_compiled.py.)
    plant = builder.AddSystem(
        SymbolicVectorSystem(time=eq.time, state=eq.xc, input=np.concatenate([eq.xd, eq.inputs]),
                             dynamics=eq.derivatives, output=np.concatenate([recorded, eq.update]))
    )
    plant.set_name("plant")
    sampler = None
    signals_port = plant.get_output_port(0)
    if len(eq.xd):
        split = builder.AddSystem(Demultiplexer([len(recorded), len(eq.xd)]))
        split.set_name("recorded_and_update")
        builder.Connect(plant.get_output_port(0), split.get_input_port(0))
        sampler = builder.AddSystem(ZeroOrderHold(eq.period, len(eq.xd)))
        sampler.set_name("sampler")
        builder.Connect(split.get_output_port(1), sampler.get_input_port())
        signals_port = split.get_output_port(0)
    if nu:
        # the exported input feeds the plant beside the held discrete state (the plant alone reads it)
        if sampler is not None:
            plant_in = builder.AddSystem(Multiplexer([len(eq.xd), nu]))
            plant_in.set_name("held_and_inputs")
            builder.Connect(sampler.get_output_port(), plant_in.get_input_port(0))
            builder.Connect(plant_in.get_output_port(0), plant.get_input_port(0))
            builder.ExportInput(plant_in.get_input_port(1), "inputs")
        else:
            builder.ExportInput(plant.get_input_port(0), "inputs")
    elif sampler is not None:
        builder.Connect(sampler.get_output_port(), plant.get_input_port(0))
    builder.ExportOutput(signals_port, "signals")
    diagram = builder.Build()
    diagram.set_name("feed_drive_compiled")
    return CompiledDrive(
        diagram=diagram, plant=plant, sampler=sampler, equations=eq, signal_names=eq.signal_names
    )
