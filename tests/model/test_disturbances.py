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


def test_lead_error_phase_counts_from_the_start_angle_and_survives_scalar_conversion():
    """``e = a [sin(2 pi r (theta - theta0) / P + phi) - sin(phi)]``: zero at the start (the screw starts
    relaxed), its slope ``a 2 pi / P cos(...)`` in the torque; AutoDiffXd and symbolic copies keep the phase."""
    import numpy as np

    from drakecreep.model.disturbances import LeadError

    a, period, lead, theta0, phi = 2e-6, 5e-3 / 12, 5e-3, 0.7, 1.1
    r = lead / (2 * math.pi)
    sys_ = LeadError(a, period, lead, theta0, phi)
    for copy in (sys_, sys_.ToAutoDiffXd(), sys_.ToSymbolic()):
        assert copy.phase == phi and copy.angle0 == theta0
    for theta in (theta0, theta0 + 0.3, theta0 - 2.0):
        ctx = sys_.CreateDefaultContext()
        sys_.GetInputPort("motor_state").FixValue(ctx, [theta, 10.0])
        sys_.GetInputPort("axial_force").FixValue(ctx, [50.0])
        arg = 2 * math.pi * r * (theta - theta0) / period + phi
        e = a * (math.sin(arg) - math.sin(phi))
        motion = sys_.GetOutputPort("nut_motion").Eval(ctx)
        assert motion[0] == pytest.approx(theta + e / r, abs=1e-12)
        slope = a * 2 * math.pi * r / period * math.cos(arg)
        assert motion[1] == pytest.approx(10.0 * (1 + slope / r), rel=1e-12)
        assert sys_.GetOutputPort("torque").Eval(ctx)[0] == pytest.approx(50.0 * slope, rel=1e-12)
    ctx = sys_.CreateDefaultContext()
    sys_.GetInputPort("motor_state").FixValue(ctx, [theta0, 0.0])
    sys_.GetInputPort("axial_force").FixValue(ctx, [0.0])
    assert np.isclose(sys_.GetOutputPort("nut_motion").Eval(ctx)[0], theta0, rtol=0, atol=1e-15)


def test_lead_error_second_harmonic_error_slope_and_scalar_copies():
    """``e = a [sin(psi + phi) - sin(phi)] + a2 [sin(2 psi + phi2) - sin(phi2)]``: zero at the start angle, its
    slope the derivative of ``e`` (the torque ``F e'`` and the nut's speed), kept by the scalar copies."""
    from drakecreep.model.disturbances import LeadError

    a, period, lead, theta0, phi, a2, phi2 = 2e-6, 5e-3 / 6, 5e-3, 0.7, 1.1, 0.9e-6, -2.0
    r = lead / (2 * math.pi)
    sys_ = LeadError(a, period, lead, theta0, phi, a2, phi2)
    for copy in (sys_, sys_.ToAutoDiffXd(), sys_.ToSymbolic()):
        assert (copy.amplitude2, copy.phase2) == (a2, phi2)
    assert sys_.error(theta0) == 0.0
    for theta in (theta0 + 0.3, theta0 - 2.0, theta0 + 11.0):
        psi = 2 * math.pi * r * (theta - theta0) / period
        e = a * (math.sin(psi + phi) - math.sin(phi)) + a2 * (math.sin(2 * psi + phi2) - math.sin(phi2))
        assert sys_.error(theta) == pytest.approx(e, rel=1e-12)
        h = 1e-6
        assert sys_.slope(theta) == pytest.approx((sys_.error(theta + h) - sys_.error(theta - h)) / (2 * h), rel=1e-6)
        ctx = sys_.CreateDefaultContext()
        sys_.GetInputPort("motor_state").FixValue(ctx, [theta, 10.0])
        sys_.GetInputPort("axial_force").FixValue(ctx, [50.0])
        assert sys_.GetOutputPort("nut_motion").Eval(ctx)[0] == pytest.approx(theta + e / r, abs=1e-12)
        assert sys_.GetOutputPort("torque").Eval(ctx)[0] == pytest.approx(50.0 * sys_.slope(theta), rel=1e-12)
    # the second harmonic alone switches the system into the diagram
    from drakecreep.params import preset

    p = with_value(preset("paper"), "disturbance.lead_error_2_amplitude", 1e-6)
    assert p.disturbance.has_lead_error and not preset("paper").disturbance.has_lead_error
    names = {s.get_name() for s in build_diagram(p, Scenario(feed=1e-3, duration=0.1)).diagram.GetSystems()}
    assert "lead_error" in names


def test_load_ripple_phase_and_scalar_copies():
    """``force = -A sin(2 pi f t + phi)``; the AutoDiffXd and symbolic copies keep the phase."""
    from drakecreep.model.disturbances import LoadRipple

    ripple = LoadRipple(3.0, 17.0, -1.2)
    for copy in (ripple, ripple.ToAutoDiffXd(), ripple.ToSymbolic()):
        assert copy.phase == -1.2 and copy.frequency == 17.0
    for t in (0.0, 0.0123, 0.4):
        ctx = ripple.CreateDefaultContext()
        ctx.SetTime(t)
        assert ripple.get_output_port(0).Eval(ctx)[0] == pytest.approx(-3.0 * math.sin(2 * math.pi * 17.0 * t - 1.2),
                                                                       rel=1e-12)


def test_cogging_torque_its_harmonics_and_scalar_copies():
    """``torque = r [c sin(psi + phi) + c2 sin(2 psi + phi2)]`` with ``psi = 2 pi r theta / P``: a load torque fixed
    to the motor angle; the AutoDiffXd and symbolic copies keep every setting; the second harmonic alone switches
    it into the diagram."""
    from drakecreep.model.disturbances import Cogging
    from drakecreep.params import preset

    p = preset("paper")
    for path, value in (("disturbance.cogging_force", 3.0), ("disturbance.cogging_period", 5e-3 / 4),
                        ("disturbance.cogging_phase", 0.8), ("disturbance.cogging_2_force", 1.2),
                        ("disturbance.cogging_2_phase", -2.1)):
        p = with_value(p, path, value)
    d, lead = p.disturbance, p.screw.lead
    r = lead / (2 * math.pi)
    cog = Cogging(d, lead)
    for copy in (cog, cog.ToAutoDiffXd(), cog.ToSymbolic()):
        assert copy.disturbance == d and copy.lead == lead
    for theta in (0.0, 0.37, -5.0, 123.4):
        ctx = cog.CreateDefaultContext()
        cog.GetInputPort("motor_state").FixValue(ctx, [theta, 3.0])
        psi = 2 * math.pi * r * theta / (5e-3 / 4)
        expected = r * (3.0 * math.sin(psi + 0.8) + 1.2 * math.sin(2 * psi - 2.1))
        assert cog.GetOutputPort("torque").Eval(ctx)[0] == pytest.approx(expected, rel=1e-12, abs=1e-15)
    second = with_value(preset("paper"), "disturbance.cogging_2_force", 1.0)
    assert second.disturbance.has_cogging and not preset("paper").disturbance.has_cogging
    names = {s.get_name() for s in build_diagram(second, Scenario(feed=1e-3, duration=0.1)).diagram.GetSystems()}
    assert {"cogging", "cogging_torque_sum"} <= names


@pytest.mark.parametrize("case", [0, 3])
def test_a_cogging_diagram_starts_at_rest_its_command_holding_the_cogging(paper, case):
    """At the start the controller's force (and the current loop's torque) hold the screw's load and the
    cogging's at the start angle, so nothing moves: every derivative is 0. Without that the paper rig would
    start with a kick of the cogging's force (here 20 N at its crest)."""
    import numpy as np

    from drakecreep.model.diagram import initial_conditions

    p = with_value(with_value(paper, "disturbance.cogging_force", 20.0), "disturbance.cogging_phase", math.pi / 2)
    scenario = Scenario(feed=1e-3, load_case=case)
    ic = initial_conditions(p, scenario)
    x0 = ic["theta0"] * p.screw.lead / (2 * math.pi)  # the motor's travel at rest: the screw wound up by the load
    expected = 20.0 * math.sin(2 * math.pi * x0 / p.disturbance.cogging_period + math.pi / 2)
    assert ic["command0"] - ic["force0"] == pytest.approx(expected, rel=1e-12)
    assert abs(expected) > 15.0
    drive = build_diagram(p, scenario)
    c = drive.diagram.CreateDefaultContext()
    np.testing.assert_allclose(drive.diagram.EvalTimeDerivatives(c).CopyToVector(), 0.0, atol=1e-9)


def test_cogging_compiles_and_matches_the_leaf_systems(short_paper):
    p = with_value(with_value(short_paper, "disturbance.cogging_force", 4.0), "disturbance.cogging_phase", 0.3)
    scenario = Scenario(feed=1e-3, load_case=3, duration=0.4)
    fast = simulate(p, scenario, backend="compiled").metrics
    leaf = simulate(p, scenario, backend="leaf").metrics
    assert fast.max_fluctuation == pytest.approx(leaf.max_fluctuation, rel=0.02)
    plain = simulate(short_paper, scenario, backend="compiled").metrics
    assert fast.max_fluctuation != pytest.approx(plain.max_fluctuation, rel=0.02)  # it acts
