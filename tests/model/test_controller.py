import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from drakecreep.errors import InputError
from drakecreep.model.controller import CascadeController, force_limit
from drakecreep.params import ControllerParams, load_params, save_params, with_value

LEAD = 5e-3
R = LEAD / (2 * math.pi)


def _gains(**kw):
    base = dict(position_gain=40.0, velocity_feedforward=1.0, velocity_gain=1e5, velocity_integral_gain=4e6,
                velocity_period=2.5e-4, position_period=1e-3)
    base.update(kw)
    return ControllerParams(**base)


def _fix(ctrl, c, x_ref=1e-4, v_ref=1e-3, theta=0.1, omega=0.2, x_table=0.0):
    ctrl.get_input_port(0).FixValue(c, [x_ref, v_ref])
    ctrl.get_input_port(1).FixValue(c, [theta, omega])
    ctrl.get_input_port(2).FixValue(c, [x_table])


def test_continuous_pi_by_hand():
    g = _gains(sampled=False)
    ctrl = CascadeController(g, LEAD, 1e4, initial_force=10.0)
    c = ctrl.CreateDefaultContext()
    _fix(ctrl, c)
    v_cmd = 40.0 * (1e-4 - 0.1 * R) + 1e-3
    e = v_cmd - 0.2 * R
    u = 1e5 * e + 10.0
    assert ctrl.GetOutputPort("controller_signals").Eval(c) == pytest.approx([v_cmd, u, 10.0])
    assert ctrl.GetOutputPort("torque_command").Eval(c)[0] == pytest.approx(u * R)
    assert ctrl.EvalTimeDerivatives(c).CopyToVector()[0] == pytest.approx(4e6 * e)


def test_back_calculation_in_saturation():
    g = _gains(sampled=False)
    ctrl = CascadeController(g, LEAD, 50.0)
    c = ctrl.CreateDefaultContext()
    _fix(ctrl, c)
    sig = ctrl.GetOutputPort("controller_signals").Eval(c)
    assert sig[1] == 50.0
    e = sig[0] - 0.2 * R
    u = 1e5 * e
    rate = ctrl.EvalTimeDerivatives(c).CopyToVector()[0]
    assert rate == pytest.approx(4e6 * e + (4e6 / 1e5) * (50.0 - u))
    no_aw = CascadeController(_gains(sampled=False, anti_windup=False), LEAD, 50.0)
    c2 = no_aw.CreateDefaultContext()
    _fix(no_aw, c2)
    assert no_aw.EvalTimeDerivatives(c2).CopyToVector()[0] == pytest.approx(4e6 * e)


def test_sampled_update_by_hand():
    # without computation delay (the default became 1 sample in issue 15; the delay has its own tests below)
    g = _gains(computation_delay=0.0)
    ctrl = CascadeController(g, LEAD, 1e4, initial_force=5.0, initial_angle=0.099)
    c = ctrl.CreateDefaultContext()
    _fix(ctrl, c, x_table=3e-5)
    x = c.get_discrete_state_vector().CopyToVector()
    np.testing.assert_allclose(x, [0.0, 5.0, 0.099, 5.0, 0.0])
    new = ctrl.EvalUniquePeriodicDiscreteUpdate(c).get_vector(0).CopyToVector()
    speed = (0.1 - 0.099) / 2.5e-4 * R
    v_cmd = 40.0 * (1e-4 - 0.1 * R) + 1e-3
    e = v_cmd - speed
    np.testing.assert_allclose(new, [v_cmd, 5.0 + 2.5e-4 * 4e6 * e, 0.1, 1e5 * e + 5.0, 1.0])
    # between position samples the speed command is held
    c.SetDiscreteState(0, [7e-4, 5.0, 0.1, 0.0, 1.0])
    assert ctrl.EvalUniquePeriodicDiscreteUpdate(c).get_vector(0).CopyToVector()[0] == 7e-4
    # the position divider wraps
    c.SetDiscreteState(0, [7e-4, 5.0, 0.1, 0.0, 3.0])
    assert ctrl.EvalUniquePeriodicDiscreteUpdate(c).get_vector(0).CopyToVector()[4] == 0.0


def test_table_feedback_uses_the_scale():
    g = _gains(sampled=False, position_feedback="table")
    ctrl = CascadeController(g, LEAD, 1e4)
    c = ctrl.CreateDefaultContext()
    _fix(ctrl, c, x_table=4e-5)
    assert ctrl.GetOutputPort("controller_signals").Eval(c)[0] == pytest.approx(40.0 * (1e-4 - 4e-5) + 1e-3)


def test_conversion_forwards_every_setting(paper):
    ctrl = CascadeController(paper.controller, LEAD, force_limit(paper), initial_force=3.0, initial_angle=0.5)
    for converted in (ctrl.ToAutoDiffXd(), ctrl.ToSymbolic()):
        assert converted.gains == ctrl.gains
        assert (converted.lead, converted.limit, converted.initial_force, converted.initial_angle) == (
            LEAD, force_limit(paper), 3.0, 0.5)
    assert force_limit(paper) == pytest.approx(paper.motor.peak_torque * 2 * math.pi / paper.screw.lead)


# --------------------------------------------------------------------------- computation delay (issue 15)

def _step(ctrl, c):
    c.SetDiscreteState(0, ctrl.EvalUniquePeriodicDiscreteUpdate(c).get_vector(0).CopyToVector())


def test_whole_sample_delay_applies_the_command_n_samples_late():
    ctrl = CascadeController(_gains(computation_delay=2.0), LEAD, 1e4, initial_force=5.0, initial_angle=0.099)
    c = ctrl.CreateDefaultContext()
    _fix(ctrl, c)
    # state: the five of the undelayed controller, then force[k-1], force[k-2]
    np.testing.assert_allclose(c.get_discrete_state_vector().CopyToVector(), [0.0, 5.0, 0.099, 5.0, 0.0, 5.0, 5.0])
    newest, applied = [], []
    for k in range(5):
        _fix(ctrl, c, theta=0.1 + 1e-3 * k)  # the motor turns: a different command every sample
        _step(ctrl, c)
        newest.append(ctrl.GetOutputPort("controller_signals").Eval(c)[1])
        applied.append(ctrl.GetOutputPort("torque_command").Eval(c)[0] / R)
    assert len(set(np.round(newest, 6))) == 5
    np.testing.assert_allclose(applied, [5.0, 5.0] + newest[:3])


def test_fractional_delay_switches_inside_the_period():
    h = 2.5e-4
    ctrl = CascadeController(_gains(computation_delay=1.5), LEAD, 1e4, initial_force=5.0, initial_angle=0.099)
    sim = Simulator(ctrl)
    c = sim.get_mutable_context()
    _fix(ctrl, c)
    sim.Initialize()
    forces = []
    for t in np.arange(0.2, 3.0, 0.5) * h:  # before and after the switch at 0.5 h of each period
        sim.AdvanceTo(t)
        forces.append((t / h, ctrl.GetOutputPort("torque_command").Eval(c)[0] / R,
                       ctrl.GetOutputPort("controller_signals").Eval(c)[1]))
    # force[0] (computed at t = 0) reaches the motor at 1.5 h; force[1] at 2.5 h
    newest0, newest1 = forces[0][2], forces[2][2]
    assert newest0 != pytest.approx(5.0)
    np.testing.assert_allclose([f[1] for f in forces], [5.0, 5.0, 5.0, newest0, newest0, newest1])


def test_delay_is_validated_naming_the_field():
    for bad in (-1.0, float("nan"), "one"):
        with pytest.raises(InputError) as err:
            ControllerParams(computation_delay=bad)
        assert "computation_delay" in str(err.value)


def test_delay_round_trips_through_yaml(paper, tmp_path):
    params = with_value(paper, "controller.computation_delay", 1.25)
    save_params(params, tmp_path / "p.yaml")
    assert load_params(tmp_path / "p.yaml").controller.computation_delay == 1.25
    assert paper.controller.computation_delay == 1.0  # the preset's stated default


def test_conversion_forwards_the_delay(paper):
    g = with_value(paper, "controller.computation_delay", 2.5).controller
    ctrl = CascadeController(g, LEAD, force_limit(paper), initial_force=3.0)
    for converted in (ctrl.ToAutoDiffXd(), ctrl.ToSymbolic()):
        assert (converted.delay.n, converted.delay.frac) == (2, 0.5)
        assert converted.num_discrete_state_groups() == 1
        assert converted.CreateDefaultContext().get_discrete_state_vector().size() == 5 + 3
