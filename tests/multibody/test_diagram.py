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
