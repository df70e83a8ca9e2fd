import math

import numpy as np
import pytest

from drakecreep.model.controller import CascadeController, force_limit
from drakecreep.params import ControllerParams

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
    g = _gains()
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
