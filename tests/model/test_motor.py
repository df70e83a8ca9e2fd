import numpy as np
import pytest

from drakecreep.model.motor import Motor, applied_torque, commanded_torque, motor_inertia
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


def test_a_saturating_drive_applies_less_than_its_command_and_the_inverse_says_how_much_to_ask():
    """``motor.saturation_torque`` tau_s: the (limited) command tau becomes tau / sqrt(1 + (tau / tau_s)^2), after
    the peak-torque limit and before the current loop; float, AutoDiffXd and Expression alike."""
    from pydrake.symbolic import Expression

    p = MotorParams(peak_torque=5.0, current_loop_time_constant=1e-3, saturation_torque=2.0)
    m = Motor(p)
    expected = 3.0 / np.sqrt(1.0 + (3.0 / 2.0) ** 2)
    xdot = m.EvalTimeDerivatives(_context(m, 3.0, 0.0, [0.0, 0.0, 0.5])).CopyToVector()
    assert xdot[2] == pytest.approx((expected - 0.5) / 1e-3)
    ideal = Motor(MotorParams(peak_torque=5.0, current_loop_time_constant=0.0, saturation_torque=2.0))
    torque = ideal.GetOutputPort("motor_torque").Eval(_context(ideal, 50.0, 0.0, [0.0, 0.0]))[0]
    assert torque == pytest.approx(5.0 / np.sqrt(1.0 + 2.5 ** 2)) == applied_torque(p, 5.0)  # limited first
    assert commanded_torque(p, applied_torque(p, 1.7)) == pytest.approx(1.7)
    assert commanded_torque(p, -2.0) == -np.inf and commanded_torque(p, 2.5) == np.inf  # beyond tau_s: no command
    linear = MotorParams(peak_torque=5.0)
    assert applied_torque(linear, 3.0) == 3.0 and commanded_torque(linear, 3.0) == 3.0
    ad, sym = m.ToAutoDiffXd(), m.ToSymbolic()
    assert ad.params == p and sym.params == p
    c = ad.CreateDefaultContext()
    ad.get_input_port(0).FixValue(c, [3.0])
    ad.get_input_port(1).FixValue(c, [0.0])
    c.SetContinuousState([0.0, 0.0, 0.5])
    assert ad.EvalTimeDerivatives(c).CopyToVector()[2].value() == pytest.approx(xdot[2])
    c = sym.CreateDefaultContext()
    sym.get_input_port(0).FixValue(c, [Expression(3.0)])
    sym.get_input_port(1).FixValue(c, [Expression(0.0)])
    c.SetContinuousState([Expression(0.0), Expression(0.0), Expression(0.5)])
    assert sym.EvalTimeDerivatives(c).CopyToVector()[2].Evaluate() == pytest.approx(xdot[2])
