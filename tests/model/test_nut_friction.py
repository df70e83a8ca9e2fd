import math

import numpy as np
import pytest

from drakecreep.sim.baseline import BaselineModel
from drakecreep.errors import InputError
from drakecreep.model.nut_friction import NutFriction, nut_friction_levels
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
from drakecreep.sim.sweep import _Batch, _batches, feed_report, make_cases
from drakecreep.model.nut_table import friction_levels, friction_split, table_friction_levels


@pytest.fixture(scope="module")
def on_screw():
    return with_value(with_value(preset(), "friction.nut_friction_on", "screw"), "simulation.steady_start", 0.3)


def test_levels_split_and_sum(paper, on_screw):
    load = paper.load_case(3)
    guides, nut = friction_split(paper, load)
    assert guides + nut == pytest.approx(friction_levels(paper, load)[0])
    # the preset's catalogue values: Tp = 0.09 N m (THK formula, Fa0 = 579 N), 1/efficiency - 1 = 0.08
    assert nut == pytest.approx(2 * math.pi * 0.09 / 5e-3 + 0.08 * 434)
    assert paper.friction.nut_friction_on == "screw"  # the default: the nut's drag on the screw
    on_table = with_value(paper, "friction.nut_friction_on", "table")
    assert table_friction_levels(on_table, load) == friction_levels(on_table, load)  # all on the table
    assert nut_friction_levels(on_table, load) == (0.0, 0.0)
    assert table_friction_levels(on_screw, load)[0] == pytest.approx(guides)
    assert nut_friction_levels(on_screw, load)[0] == pytest.approx(nut)


def test_drag_torque_by_hand(paper):
    lugre = NutFriction(paper.friction, 17.0, 22.1, 5e-3)
    c = lugre.CreateDefaultContext()
    omega, w = 0.2, 0.4
    lugre.get_input_port(0).FixValue(c, [0.0, omega])
    c.SetContinuousState([w])
    r = 5e-3 / (2 * math.pi)
    v = omega * r
    f = paper.friction
    g = 17.0 + (22.1 - 17.0) * math.exp(-((v / f.stribeck_velocity) ** 2))
    deflection_rate = v - abs(v) * w * 17.0 / g
    force = 17.0 * w + f.bristle_damping * deflection_rate + f.viscous * v
    assert lugre.GetOutputPort("friction_force").Eval(c)[0] == pytest.approx(force)
    assert lugre.GetOutputPort("friction_torque").Eval(c)[0] == pytest.approx(force * r)
    assert lugre.EvalTimeDerivatives(c).CopyToVector()[0] == pytest.approx(f.bristle_stiffness / 17.0 * deflection_rate)
    converted = lugre.ToAutoDiffXd()
    assert (converted.fc, converted.fs, converted.lead, converted.friction) == (17.0, 22.1, 5e-3, paper.friction)


def test_nut_drag_loads_the_motor_not_the_table(on_screw):
    r = simulate(on_screw, Scenario(feed=1e-3, load_case=3, duration=0.8))
    assert r.ok
    guides, nut = friction_split(on_screw, on_screw.load_case(3))
    steady = r.time >= 0.5
    assert np.mean(r.signals["friction_force"][steady]) == pytest.approx(guides + 200.0 * 1e-3, rel=0.02)
    assert np.mean(r.signals["nut_friction_force"][steady]) == pytest.approx(nut, rel=0.02)  # no viscous term
    # the screw now carries only the guides' friction (plus the axial load), so it stretches less
    total = simulate(with_value(on_screw, "friction.nut_friction_on", "table"), Scenario(feed=1e-3, load_case=3, duration=0.8))
    drop = np.mean(total.signals["spring_force"][steady]) - np.mean(r.signals["spring_force"][steady])
    assert drop == pytest.approx(nut, rel=0.05)


def test_the_viscous_coefficient_is_counted_once_on_either_side(paper):
    """``friction.viscous`` is the axis's one Fv: where the nut's Coulomb level acts must not change the steady
    force. At 20 mm/s a second Fv (the nut's drag carrying the drive's viscous term too, as before) would add
    Fv v = 4 N to the force command on the screw side."""
    scenario = Scenario(feed=0.02, load_case=0, duration=0.8)
    force = {}
    for side in ("table", "screw"):
        p = with_value(with_value(paper, "friction.nut_friction_on", side), "simulation.steady_start", 0.3)
        r = simulate(p, scenario)
        assert r.ok
        force[side] = float(np.mean(r.signals["force_command"][r.time >= 0.5]))
    assert abs(force["screw"] - force["table"]) < 0.1 * paper.friction.viscous * 0.02, force
    model = BaselineModel(with_value(paper, "friction.nut_friction_on", "screw"), scenario)
    assert model.friction(0.02, 0.0, model.fc_nut, model.fs_nut, viscous=False)[0] == pytest.approx(
        model.friction(0.02, 0.0, model.fc_nut, model.fs_nut)[0] - paper.friction.viscous * 0.02)


def test_compiled_equals_leaf_with_the_nut_on_the_screw(on_screw):
    scenario = Scenario(feed=1e-3, load_case=2, duration=0.4)
    fast, slow = simulate(on_screw, scenario), simulate(on_screw, scenario, backend="leaf")
    # same equations; the two evaluate them in a different order, so an encoder count (floor) can flip a
    # sample apart on round-off, which moves the force by ~1e-7 of its value for a sample or two
    np.testing.assert_allclose(fast.signals["nut_friction_force"], slow.signals["nut_friction_force"], rtol=1e-6,
                               atol=1e-9)


def test_plain_python_and_batch_paths_refuse_what_they_do_not_model(on_screw, paper):
    assert BaselineModel(on_screw, Scenario()).fc_nut > 0  # the plain-Python equations model the nut on the screw
    with pytest.raises(InputError, match="disturbance"):
        BaselineModel(preset("paper_calibrated"), Scenario())
    with pytest.raises(InputError, match="compensation"):
        BaselineModel(with_value(paper, "compensation.method", "static"), Scenario())
    cases = make_cases(paper, [dict(feed=1e-3), dict(feed=2e-3)], dict(duration=1.5), feed_report)
    assert isinstance(_batches(cases, 10, feed_report)[0], _Batch)
    cases = make_cases(on_screw, [dict(feed=1e-3), dict(feed=2e-3)], dict(duration=0.8), feed_report)
    assert isinstance(_batches(cases, 10, feed_report)[0], _Batch)
