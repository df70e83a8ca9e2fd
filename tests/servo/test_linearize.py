import math

import numpy as np
import pytest

from drakecreep.servo import linearize as lin
from drakecreep.params import with_value
from drakecreep.scenario import Scenario


@pytest.fixture(scope="module")
def stribeck(paper):
    return with_value(paper, "friction.law", "stribeck")


@pytest.fixture(scope="module")
def rigid_shaft(stribeck):
    """A shaft so stiff that the chain stiffness no longer depends on the nut position."""
    return with_value(stribeck, "screw.youngs_modulus", 2.06e19)


@pytest.mark.parametrize("law", ["lugre", "stribeck", "coulomb", "lugre, saturating drive", "stribeck, backlash",
                                 "lugre, structural mode"])
@pytest.mark.parametrize("feed", [1e-3, 0.1e-3])
def test_operating_point_is_steady_sliding(paper, law, feed):
    p = with_value(paper, "friction.law", law.split(",")[0])
    if "saturating" in law:  # the command that holds the load is larger than the torque the drive applies
        from drakecreep.model.steady import nut_on_table, steady_sliding

        held = steady_sliding(nut_on_table(p), Scenario(feed=feed, load_case=3))[3]
        p = with_value(p, "motor.saturation_torque", 1.2 * held)
    if "backlash" in law:  # the chain bears the sliding force across its closed gap
        p = with_value(p, "nut.backlash", 10e-6)
    if "structural mode" in law:  # a third of the moving mass on a 40 Hz mode: at rest on the table when sliding
        p = with_value(with_value(p, "table.mode_mass_share", 0.3), "table.mode_frequency", 40.0)
    sc = Scenario(feed=feed, load_case=3)
    op = lin.operating_point(p, sc)
    x, xdot = lin.closed_loop_derivatives(p, sc, op)
    names = lin.linearize_closed_loop(p, sc, op).state_labels
    rates = dict(zip(names, xdot))
    r = p.screw.lead / (2 * math.pi)
    assert rates["motor.theta"] == pytest.approx(feed / r, rel=1e-12)
    assert rates["table.x"] == pytest.approx(feed, rel=1e-12)
    # forces balance: accelerations, integrator, current lag and bristle state do not move
    assert abs(rates["motor.omega"]) < 1e-9 * feed / r * 1e3
    assert abs(rates["table.v"]) < 1e-9
    assert abs(rates["controller.integrator"]) < 1e-9 * op.spring_force
    assert abs(rates["motor.tau"]) < 1e-9
    if law.startswith("lugre"):
        assert abs(rates["table.w"]) < 1e-9
    if "structural mode" in law:
        assert abs(rates["table.mode_deflection"]) < 1e-15 and abs(rates["table.mode_rate"]) < 1e-9
    if "saturating" in law:
        assert op.controller[0] > 1.5 * op.torque / r  # 1 / sqrt(1 - 1 / 1.2^2) = 1.81
    if "backlash" in law:  # the chain is stretched half the lost motion further than without it
        closed = lin.operating_point(with_value(p, "nut.backlash", 0.0), sc)
        stretch = (op.motor[0] * r - op.table[0]) - (closed.motor[0] * r - closed.table[0])
        assert stretch == pytest.approx(5e-6, rel=1e-6)


def test_operating_point_matches_a_simulation(paper):
    """Simulating the continuous-controller diagram with ideal sensors settles where the constructed point is."""
    from drakecreep.sim.simulation import simulate

    p = with_value(paper, "controller.sampled", False)
    p = with_value(with_value(p, "sensors.encoder_counts_per_rev", 0), "sensors.scale_resolution", 0.0)
    p = with_value(p, "simulation.steady_start", 0.3)
    p = with_value(p, "simulation.accuracy", 1e-7)
    # the linear analysis lumps the nut's friction on the table (model.steady.nut_on_table): simulate that diagram
    p = with_value(with_value(p, "friction.nut_friction_on", "table"), "simulation.convergence_check", False)
    sc = Scenario(feed=10e-3, load_case=3, duration=0.8)
    res = simulate(p, sc)
    op = lin.operating_point(p, sc)
    s = res.signals
    assert res.ok
    assert s["table_speed"][-1] == pytest.approx(op.feed, rel=1e-4)
    assert s["spring_force"][-1] == pytest.approx(op.spring_force, rel=1e-4)
    assert s["integrator"][-1] == pytest.approx(op.controller[0], rel=1e-4)
    assert s["friction_state_0"][-1] == pytest.approx(op.table[2], rel=1e-4)


@pytest.mark.parametrize("law", ["lugre", "stribeck"])
def test_autodiff_matches_finite_differences(paper, law):
    p = with_value(paper, "friction.law", law)
    sc = Scenario(feed=0.2e-3, load_case=2)
    op = lin.operating_point(p, sc)
    A = lin.linearize_closed_loop(p, sc, op).A
    J = lin.finite_difference_jacobian(p, sc, op)
    assert np.all(np.abs(J - A) <= 1e-5 * np.abs(A) + 1e-9 * np.max(np.abs(A)))


@pytest.mark.parametrize("feed", [1e-3, 0.1e-3])
def test_parts_wired_like_the_diagram(paper, feed):
    """Plant + controller linearizations wired in python-control give the diagram's own closed-loop poles."""
    sc = Scenario(feed=feed, load_case=3)
    op = lin.operating_point(paper, sc)
    whole = np.sort_complex(lin.linearize_closed_loop(paper, sc, op).poles())
    parts = np.sort_complex(lin.closed_loop_from_parts(
        lin.linearize_plant(paper, sc, op), lin.linearize_controller(paper, sc, op)).poles())
    assert np.allclose(parts, whole, rtol=1e-9, atol=1e-9 * np.max(np.abs(whole)))


def test_named_signals(paper):
    sc = Scenario(feed=1e-3, load_case=1)
    P = lin.linearize_plant(paper, sc)
    K = lin.linearize_controller(paper, sc)
    assert P.input_labels == ["torque_command"]
    assert P.output_labels == list(lin.PLANT_OUTPUTS)
    assert K.input_labels == list(lin.CONTROLLER_INPUTS)
    assert K.output_labels == ["torque_command"]
    assert "table.w" in P.state_labels


def test_plant_matches_analytic_two_mass_model(rigid_shaft):
    import control

    sc = Scenario(feed=0.15e-3, load_case=3)
    op = lin.operating_point(rigid_shaft, sc)
    assert op.friction_slope < 0  # on the falling branch: the friction slope matters here
    P = lin.linearize_plant(rigid_shaft, sc, op)
    tm = lin.two_mass_model(rigid_shaft, sc, op)
    w = np.logspace(0, 4, 60)
    drake = control.frequency_response(P, w).complex[[1, 3], 0, :]
    hand = control.frequency_response(tm, w).complex[:, 0, :]
    assert np.max(np.abs(drake - hand) / np.abs(hand)) < 1e-6


def test_mechanism_is_paper_equation_2(rigid_shaft):
    """M s^2 + (C + C1) s + K = 0 for the screw + table with the motor motion prescribed (static friction)."""
    for feed in (1e-3, 0.1e-3):
        sc = Scenario(feed=feed, load_case=3)
        op = lin.operating_point(rigid_shaft, sc)
        poles = np.sort_complex(lin.linearize_mechanism(rigid_shaft, sc, op).poles())
        theory = np.sort_complex(np.roots([op.mass, op.damping + op.friction_slope, op.stiffness]))
        assert np.allclose(poles, theory, rtol=1e-6)


def test_lugre_linearization_has_bristle_dynamics(paper):
    sc = Scenario(feed=0.2e-3, load_case=3)
    op = lin.operating_point(paper, sc)
    P = lin.linearize_plant(paper, sc, op)
    i = P.state_labels.index("table.w")
    law = paper.friction
    g = op.Fc + (op.Fs - op.Fc) * math.exp(-((op.feed / law.stribeck_velocity) ** 2))
    assert P.A[i, i] == pytest.approx(-law.bristle_stiffness * op.feed / g, rel=1e-9)


def test_negative_friction_slope_destabilizes_the_loop(paper):
    fast = lin.linearize_closed_loop(paper, Scenario(feed=1e-3, load_case=3))
    slow = lin.linearize_closed_loop(paper, Scenario(feed=0.1e-3, load_case=3))
    assert np.max(fast.poles().real) < 0
    assert np.max(slow.poles().real) > 0


def test_no_steady_sliding_is_an_input_error(paper):
    from drakecreep.errors import InputError

    p = with_value(with_value(paper, "controller.position_gain", 0.0), "controller.velocity_feedforward", 0.5)
    with pytest.raises(InputError, match="position_gain"):
        lin.operating_point(p, Scenario(feed=1e-3, load_case=3))


def test_a_friction_map_is_refused_by_name_before_any_linearization(paper):
    """A level that changes along the travel has no steady sliding to linearize about: one line naming the field."""
    from drakecreep.errors import InputError

    mapped = with_value(paper, "friction.position_map_1", 0.25)
    with pytest.raises(InputError) as err:
        lin.operating_point(mapped, Scenario(feed=1e-3))
    assert err.value.field == "friction.position_map_1" and "linear analyses" in str(err.value)
    with pytest.raises(InputError) as err:  # nor one that drifts over time
        lin.operating_point(with_value(paper, "friction.time_drift", -0.1), Scenario(feed=1e-3))
    assert err.value.field == "friction.time_drift" and "linear analyses" in str(err.value)
