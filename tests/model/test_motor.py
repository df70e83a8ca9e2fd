import numpy as np
import pytest

from drakecreep.model.motor import Motor, motor_inertia
from drakecreep.params import MotorParams


def _context(system, u, load, x):
    c = system.CreateDefaultContext()
    system.get_input_port(0).FixValue(c, [u])
    system.get_input_port(1).FixValue(c, [load])
    c.SetContinuousState(x)
    return c


def test_derivatives_by_hand():
    p = MotorParams(rotor_inertia=1e-4, coupling_inertia=2e-5, peak_torque=5.0,
                    current_loop_time_constant=1e-3, viscous_damping=1e-3)
    m = Motor(p, load_inertia=3e-5)
    J = 1e-4 + 2e-5 + 3e-5
    assert motor_inertia(p, 3e-5) == pytest.approx(J)
    xdot = m.EvalTimeDerivatives(_context(m, 2.0, 0.5, [0.1, 10.0, 1.5])).CopyToVector()
    np.testing.assert_allclose(xdot, [10.0, (1.5 - 0.5 - 1e-3 * 10.0) / J, (2.0 - 1.5) / 1e-3])


def test_torque_command_is_limited():
    p = MotorParams(peak_torque=5.0, current_loop_time_constant=0.0)
    m = Motor(p)
    c = _context(m, 50.0, 0.0, [0.0, 0.0])
    assert m.GetOutputPort("motor_torque").Eval(c)[0] == 5.0
    c = _context(m, -50.0, 0.0, [0.0, 0.0])
    assert m.GetOutputPort("motor_torque").Eval(c)[0] == -5.0


def test_scalar_conversion_keeps_settings():
    p = MotorParams(current_loop_time_constant=1e-3)
    m = Motor(p, load_inertia=2e-4, initial_state=[0.3, 0.0, 0.1])
    for converted in (m.ToAutoDiffXd(), m.ToSymbolic()):
        assert converted.params == p and converted.load_inertia == 2e-4
        np.testing.assert_allclose(converted.initial_state, [0.3, 0.0, 0.1])
    np.testing.assert_allclose(m.CreateDefaultContext().get_continuous_state_vector().CopyToVector(), [0.3, 0.0, 0.1])
