import math

import pytest

from drakecreep.sim.compiled import compile_diagram
from drakecreep.model.diagram import build_diagram
from drakecreep.params import with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate


def test_disturbances_off_leave_the_diagram_unchanged(paper):
    names = {s.get_name() for s in build_diagram(paper, Scenario()).diagram.GetSystems()}
    assert names == {"reference", "controller", "motor", "screw", "table", "encoder", "scale",
                     "nut_friction", "motor_load_sum"}  # the nut's drag on the screw (the default)


@pytest.fixture(scope="module")
def half_second(paper):
    """Metrics from 0.5 s, after the start transient."""
    return with_value(paper, "simulation.steady_start", 0.5)


def test_lead_error_ripple_is_two_pi_a_over_p_of_the_feed(half_second):
    a = 1e-6
    p = with_value(half_second, "disturbance.lead_error_amplitude", a)
    expected = 2 * math.pi * a / p.disturbance.lead_error_period
    rates = [simulate(p, Scenario(feed=f, load_case=0, duration=2.0)).metrics.fluctuation_rate for f in (0.5e-3, 2e-3)]
    for rate in rates:
        assert rate == pytest.approx(expected, rel=0.15)


def test_force_ripple_response_does_not_depend_on_the_feed(half_second):
    p = with_value(half_second, "disturbance.force_ripple", 2.0)
    flucts = [simulate(p, Scenario(feed=f, load_case=3, duration=2.0)).metrics.max_fluctuation for f in (0.5e-3, 2e-3)]
    assert flucts[0] > 1e-5
    assert flucts[1] == pytest.approx(flucts[0], rel=0.02)


def test_disturbed_diagram_compiles_and_matches_the_leaf_systems(short_paper):
    p = with_value(with_value(short_paper, "disturbance.lead_error_amplitude", 1e-6), "disturbance.force_ripple", 1.0)
    scenario = Scenario(feed=1e-3, load_case=3, duration=0.4)
    assert compile_diagram(build_diagram(p, scenario)).plant is not None
    fast = simulate(p, scenario, backend="compiled").metrics
    leaf = simulate(p, scenario, backend="leaf").metrics
    assert fast.max_fluctuation == pytest.approx(leaf.max_fluctuation, rel=0.02)
