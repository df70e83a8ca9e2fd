import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from drakecreep.sim.compiled import compile_diagram, symbolic_equations
from drakecreep.model.diagram import build_diagram
from drakecreep.params import with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate


def test_symbolic_equations_evaluate_like_the_leaf_systems(paper):
    drive = build_diagram(paper, Scenario(feed=1e-3))
    eq = symbolic_equations(drive)
    # 7 states: motor 2, current lag 1, table 2, LuGre bristles of the table and of the nut on the screw;
    # discrete: the controller's 5 plus its queue of n = computation_delay forces (1 in the preset since issue 15)
    assert paper.controller.computation_delay == 1.0
    assert len(eq.xc) == 7 and len(eq.xd) == 6 and eq.period == paper.controller.velocity_period
    c = drive.diagram.CreateDefaultContext()
    c.SetTime(0.02)
    xc = eq.xc0 + np.array([1e-3, 0.5, 0.01, 2e-6, 1e-4, 0.3, 0.2])
    c.SetContinuousState(xc)
    env = {eq.time: 0.02, **dict(zip(eq.xc, xc)), **dict(zip(eq.xd, eq.xd0))}
    expected = drive.diagram.EvalTimeDerivatives(c).CopyToVector()
    got = np.array([e.Evaluate(env) for e in eq.derivatives])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_compiled_and_leaf_backends_give_the_same_trajectory(short_paper):
    scenario = Scenario(feed=1e-3, load_case=2, duration=0.4)
    fast = simulate(short_paper, scenario, backend="compiled")
    slow = simulate(short_paper, scenario, backend="leaf")
    for name in ("table_speed", "motor_speed", "friction_force", "force_command"):
        scale = np.max(np.abs(slow.signals[name])) + 1e-12
        np.testing.assert_allclose(fast.signals[name], slow.signals[name], atol=1e-9 * scale)


def test_continuous_controller_compiles_without_discrete_state(paper):
    drive = build_diagram(with_value(paper, "controller.sampled", False), Scenario())
    compiled = compile_diagram(drive)
    assert compiled.sampler is None and len(compiled.equations.xc) == 8  # + the nut's LuGre state


def test_a_compiled_diagram_of_some_signals_simulates_them_to_the_same_bits(paper):
    drive = build_diagram(paper, Scenario(feed=1e-3, duration=0.05))
    some = ("force_command", "motor_angle", "nut_friction_force")
    logged = {}
    for names in (None, some):
        compiled = compile_diagram(drive, signals=names)
        b = DiagramBuilder()
        system = b.AddSystem(compiled.diagram)
        log = LogVectorOutput(system.GetOutputPort("signals"), b, paper.controller.velocity_period)
        root = b.Build()
        context = root.CreateDefaultContext()
        compiled.set_initial_state(root.GetMutableSubsystemContext(system, context))
        Simulator(root, context).AdvanceTo(0.05)
        data = log.FindLog(context).data()
        logged[names] = {n: data[i] for i, n in enumerate(compiled.signal_names)}
        assert data.shape[0] == len(compiled.signal_names) + len(compiled.equations.xc)
    assert list(logged[some]) == list(some)
    for n in some:
        np.testing.assert_array_equal(logged[some][n], logged[None][n])
    assert np.ptp(logged[some]["motor_angle"]) > 0  # the axis moved: the comparison is of a motion
    with pytest.raises(ValueError, match="signals: got .*'speed'.*; allowed: distinct names among x_ref"):
        compile_diagram(drive, signals=("motor_angle", "speed"))
    with pytest.raises(ValueError, match="signals: got"):
        compile_diagram(drive, signals=("motor_angle", "motor_angle"))


def test_the_compiled_diagram_holds_the_model_state_and_updates_it_as_the_leaves(paper):
    """The compiled diagram's state is the model's, nothing more (the discrete update is part of the plant's output,
    sampled by the hold), and its periodic update at a state off the start is the leaf systems'."""
    drive = build_diagram(paper, Scenario(feed=1e-3, duration=0.1))
    compiled = compile_diagram(drive)
    ctx = compiled.default_context()
    eq = compiled.equations
    assert ctx.num_continuous_states() == len(eq.xc) and ctx.num_discrete_state_groups() == 1
    leaf = drive.diagram.CreateDefaultContext()
    rng = np.random.default_rng(3)
    xc = eq.xc0 + 1e-4 * rng.standard_normal(len(eq.xc))
    xd = eq.xd0 + 0.1 * rng.standard_normal(len(eq.xd))
    for c in (ctx, leaf):
        c.SetTime(0.02)
        c.SetContinuousState(xc)
    ctx.SetDiscreteState(0, xd)
    leaf.SetDiscreteState(0, xd)
    got = compiled.diagram.EvalUniquePeriodicDiscreteUpdate(ctx).get_vector(0).CopyToVector()
    expected = drive.diagram.EvalUniquePeriodicDiscreteUpdate(leaf).get_vector(0).CopyToVector()
    assert np.ptp(expected - xd) > 0  # the update moves the state: the comparison is of an update
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.max(np.abs(expected)))
