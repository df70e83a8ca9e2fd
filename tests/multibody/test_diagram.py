"""The multibody feed drive in closed loop (``simulate(model="multibody")``) against the two-mass model."""

import math

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.multibody.diagram import MultibodyOptions, build_multibody_diagram
from drakecreep.params import with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate


def _short(params, steady_start):
    params = with_value(params, "simulation.convergence_check", False)
    return with_value(params, "simulation.steady_start", steady_start)


def _frictionless(params):
    for key, value in (("friction.law", "coulomb"), ("friction.viscous", 0.0), ("table.seal_force", 0.0),
                       ("table.guide_friction_coefficient", 0.0), ("nut.preload_torque", 0.0),
                       ("nut.load_friction_coefficient", 0.0)):
        params = with_value(params, key, value)
    return params


def test_starts_at_the_loaded_equilibrium(paper):
    """At t = 0 the screw carries the load case's Fx and the motor holds it through the lead."""
    fd = build_multibody_diagram(paper, Scenario(feed=1e-3, load_case=3, duration=0.1), MultibodyOptions(n_segments=4))
    ctx = fd.diagram.CreateDefaultContext()
    fd.set_initial_state(ctx)
    fx = paper.load_case(3).fx
    assert fd.equilibrium_residual < 1e-6
    assert fd.diagram.GetOutputPort("screw.axial_force").Eval(ctx)[0] == pytest.approx(fx, rel=1e-4)
    ratio = paper.screw.lead / (2.0 * math.pi)
    assert fd.initial_torque == pytest.approx(fx * ratio, rel=1e-4)
    assert fd.diagram.GetOutputPort("motor.motor_torque").Eval(ctx)[0] == pytest.approx(fd.initial_torque)
    np.testing.assert_allclose(fd.diagram.GetOutputPort("table.table_state").Eval(ctx), [0.0, 0.0], atol=1e-12)


def test_smooth_feed_mean_speed_equals_the_feed(paper):
    """At 1 mm/s (load case 3, LuGre) the two-mass model slides smoothly; so does the full multibody model,
    its mean table speed within 1 % of the feed and no stick-slip."""
    params = _short(paper, 0.3)
    scenario = Scenario(feed=1e-3, load_case=3, duration=0.6)
    two = simulate(params, scenario)
    assert not two.metrics.creep
    result = simulate(params, scenario, model="multibody", multibody=MultibodyOptions(n_segments=4))
    assert result.ok and result.stats["model"] == "multibody"
    # the same signals, but the friction laws' internal states (the two-mass table exports its bristle state)
    assert {k for k in two.signals if not k.startswith("friction_state")} == set(result.signals)
    m = result.metrics
    assert not m.creep
    assert m.mean_speed == pytest.approx(1e-3, rel=0.01)
    assert m.fluctuation_rate < 0.01


def test_frictionless_rigid_joints_match_the_two_mass_model(paper):
    """Without friction and with rigid fixed joints both models follow the start-up ramp alike: table speed
    within 2 % of the feed over 0.2 s (the multibody axial mode is 2 % lower: the screw's own mass)."""
    params = _frictionless(_short(paper, 0.1))
    scenario = Scenario(feed=1e-3, load_case=3, duration=0.2)
    two = simulate(params, scenario)
    mb = simulate(params, scenario, model="multibody",
                  multibody=MultibodyOptions(n_segments=4, rigid_joints=True, friction=False))
    assert mb.ok and len(mb.time) == len(two.time)
    v1, v2 = mb.signals["table_speed"], two.signals["table_speed"]
    assert np.max(np.abs(v2)) > 1.1e-3  # the ramp overshoots: there is a transient to compare
    assert np.max(np.abs(v1 - v2)) < 0.02 * 1e-3
    assert np.max(np.abs(mb.signals["spring_force"] - two.signals["spring_force"])) < 1.0  # N, of 434 N


@pytest.mark.parametrize("kwargs, field", [
    (dict(model="three_mass"), "model"),
    (dict(multibody=MultibodyOptions()), "multibody"),
])
def test_bad_model_arguments(paper, kwargs, field):
    with pytest.raises(InputError) as err:
        simulate(paper, Scenario(feed=1e-3, duration=0.5), **kwargs)
    assert err.value.field == field


@pytest.mark.parametrize("kwargs, field", [
    (dict(n_segments=1), "multibody.n_segments"),
    (dict(rigid_joints=1), "multibody.rigid_joints"),
    (dict(integrator="euler"), "multibody.integrator"),
    (dict(rigid_twist_factor=0.5), "multibody.rigid_twist_factor"),
])
def test_bad_options(kwargs, field):
    with pytest.raises(InputError) as err:
        MultibodyOptions(**kwargs)
    assert err.value.field == field


def test_travel_beyond_one_segment_is_refused(paper):
    with pytest.raises(InputError) as err:
        build_multibody_diagram(paper, Scenario(feed=0.1, duration=5.0), MultibodyOptions(n_segments=6))
    assert err.value.field == "duration"


@pytest.mark.parametrize("options", [MultibodyOptions(n_segments=3, rigid_joints=True), MultibodyOptions(n_segments=4)],
                         ids=["rigid3", "full4"])
def test_compiled_loop_gives_the_leaf_equations(paper, options):
    """The loop compiled into SymbolicVectorSystems (the default backend) has the leaf systems' equations: at a
    random state and time in the start-up ramp the time derivatives, the controller's discrete update and the
    recorded signals agree to 1e-9 relative."""
    from drakecreep.sim.compiled import compile_diagram

    scenario = Scenario(feed=0.2e-3, load_case=3, duration=1.0)
    leaf = build_multibody_diagram(paper, scenario, options)
    comp = build_multibody_diagram(paper, scenario, options, compiler=compile_diagram)
    assert comp.compiled is not None and "controller" not in comp.systems
    contexts = []
    for fd in (leaf, comp):
        ctx = fd.diagram.CreateDefaultContext()
        fd.set_initial_state(ctx)
        contexts.append(ctx)
    x0 = contexts[0].get_continuous_state_vector().CopyToVector()
    # the same state at t = 0, and no other: the discrete update is part of the compiled plant's output (until
    # session 78 a system of its own held one constant extra state)
    np.testing.assert_array_equal(contexts[1].get_continuous_state_vector().CopyToVector(), x0)
    rng = np.random.default_rng(17)
    nx = len(x0)
    x = x0 + 1e-5 * rng.standard_normal(nx)  # a few um / mrad around the loaded equilibrium, mm/s speeds
    x[-3:] = x0[-3:] + [0.05, 2e-6, -3e-6]  # current loop torque (N m), the two LuGre bristle states (m)
    xd = contexts[0].get_discrete_state_vector().CopyToVector()
    xd = xd + 1e-3 * np.abs(xd).max() * rng.standard_normal(len(xd))
    for ctx in contexts:
        ctx.SetTime(0.031)
        ctx.SetContinuousState(x)
        ctx.get_mutable_discrete_state_vector().SetFromVector(xd)
    dl = leaf.diagram.EvalTimeDerivatives(contexts[0]).CopyToVector()
    dc = comp.diagram.EvalTimeDerivatives(contexts[1]).CopyToVector()
    np.testing.assert_allclose(dc, dl, rtol=1e-9, atol=1e-9 * np.max(np.abs(dl)))
    ul = leaf.diagram.EvalUniquePeriodicDiscreteUpdate(contexts[0]).get_vector(0).CopyToVector()
    uc = comp.diagram.EvalUniquePeriodicDiscreteUpdate(contexts[1]).get_vector(0).CopyToVector()
    np.testing.assert_allclose(uc, ul, rtol=1e-9, atol=1e-12)
    for _, (system, port, index), _ in leaf.signals:
        a = leaf.diagram.GetOutputPort(f"{system}.{port}").Eval(contexts[0])[index]
        b = comp.diagram.GetOutputPort(f"{system}.{port}").Eval(contexts[1])[index]
        assert b == pytest.approx(a, rel=1e-9, abs=1e-12), f"{system}.{port}[{index}]"


def test_axial_screw_stick_slips_as_the_full_screw(paper):
    """At 0.1 mm/s (load case 3, LuGre, rigid joints, N = 3) the model stick-slips; with the screw reduced to its
    axial and torsion motion (``screw_bending=False``) the table speed follows the full screw's within 1 % of
    the feed through the first stick-slip cycles (0.2 s), and both creep. (Stick-slip amplifies differences:
    the two traces part by 1 % of the feed at 0.25 s; the verdict and the amplitude over 5 s are compared in
    analysis/bench_multibody.py.)"""
    params = _short(paper, 0.1)
    scenario = Scenario(feed=0.1e-3, load_case=3, duration=0.2)
    runs = [simulate(params, scenario, model="multibody",
                     multibody=MultibodyOptions(n_segments=3, rigid_joints=True, screw_bending=bending))
            for bending in (True, False)]
    assert all(r.ok and r.metrics.creep and r.metrics.stick_slip_cycles >= 2 for r in runs)
    v_full, v_axial = (r.signals["table_speed"] for r in runs)
    assert np.max(np.abs(v_full)) > 2e-4  # slips at twice the feed and more: there is something to follow
    assert np.max(np.abs(v_axial - v_full)) < 0.01 * 1e-4


def test_axial_screw_option_needs_rigid_joints():
    with pytest.raises(InputError) as err:
        MultibodyOptions(screw_bending=False)
    assert err.value.field == "multibody.screw_bending"


@pytest.mark.parametrize("compiled", [False, True], ids=["leaf", "compiled"])
def test_force_ripple_acts_on_the_table_along_x(paper, compiled):
    """``disturbance.force_ripple`` (Tables 8-9's force ripple, :class:`LoadRipple`) adds
    ``-A sin(2 pi f t)`` to the table's x force and nothing else; the lead error is refused."""
    from drakecreep.multibody.diagram import _indices
    from drakecreep.sim.compiled import compile_diagram

    scenario = Scenario(feed=1e-3, load_case=3, duration=0.5)
    options = MultibodyOptions(n_segments=3, rigid_joints=True)
    rippled = with_value(with_value(paper, "disturbance.force_ripple", 2.0), "disturbance.ripple_frequency", 5.0)
    forces = []
    for params in (paper, rippled):
        fd = build_multibody_diagram(params, scenario, options, compiler=compile_diagram if compiled else None)
        ctx = fd.diagram.CreateDefaultContext()
        fd.set_initial_state(ctx)
        ctx.SetTime(0.03)
        plant = fd.drive.plant
        forces.append(plant.get_applied_generalized_force_input_port().Eval(plant.GetMyContextFromRoot(ctx)))
    expected = np.zeros_like(forces[0])
    expected[_indices(fd.drive)["table"]["vx"]] = -2.0 * math.sin(2.0 * math.pi * 5.0 * 0.03)
    np.testing.assert_allclose(forces[1] - forces[0], expected, atol=1e-12)
    with pytest.raises(InputError) as err:
        build_multibody_diagram(with_value(paper, "disturbance.lead_error_amplitude", 1e-6), scenario, options)
    assert err.value.field == "disturbance.lead_error_amplitude"
    with pytest.raises(InputError) as err:  # the cogging is the two-mass model's too
        build_multibody_diagram(with_value(paper, "disturbance.cogging_2_force", 1.0), scenario, options)
    assert err.value.field == "disturbance.cogging_2_force"
    with pytest.raises(InputError) as err:  # and the friction map
        build_multibody_diagram(with_value(paper, "friction.position_map_3", 0.2), scenario, options)
    assert err.value.field == "friction.position_map_3"
    with pytest.raises(InputError) as err:  # and the drive's saturation
        build_multibody_diagram(with_value(paper, "motor.saturation_torque", 2.0), scenario, options)
    assert err.value.field == "motor.saturation_torque"
    with pytest.raises(InputError) as err:  # and the nut's lost motion
        build_multibody_diagram(with_value(paper, "nut.backlash", 8e-6), scenario, options)
    assert err.value.field == "nut.backlash" and str(err.value).endswith(
        "allowed: 0 with the multibody model (its ScrewJoint has no lost motion; the nut's lost motion is a two-mass "
        "model effect)")
    with pytest.raises(InputError) as err:  # and the table's structural mode
        build_multibody_diagram(with_value(paper, "table.mode_mass_share", 0.2), scenario, options)
    assert err.value.field == "table.mode_mass_share"
    with pytest.raises(InputError) as err:  # and a friction drift over time
        build_multibody_diagram(with_value(paper, "friction.time_drift", -0.1), scenario, options)
    assert err.value.field == "friction.time_drift"
