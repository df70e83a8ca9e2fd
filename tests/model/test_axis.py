"""MeasuredAxis: the replay axis with its coefficients as numeric parameters."""

import math

import numpy as np
import pytest
from pydrake.autodiffutils import AutoDiffXd
from pydrake.symbolic import Expression

from drakecreep.errors import InputError
from drakecreep.model.axis import AXIS_PARAMETERS, MeasuredAxis, MeasuredAxis_, axis_friction, axis_parameters, \
    set_axis_parameters


def _xdot(system, state, force, t=0.0, **values):
    ctx = system.CreateDefaultContext()
    ctx.SetTime(t)
    ctx.SetContinuousState(state)
    set_axis_parameters(system, ctx, **values)
    system.GetInputPort("force").FixValue(ctx, [force])
    return system.EvalTimeDerivatives(ctx).CopyToVector()


def test_rigid_axis_is_newton_with_the_friction_and_offset():
    p = dict(mass=95.0, viscous=200.0, coulomb=20.0, offset=-3.0, regularization_velocity=1e-4)
    xdot = _xdot(MeasuredAxis(False), [0.1, 0.05], 60.0, **p)
    friction = 20.0 * math.tanh(0.05 / 1e-4) + 200.0 * 0.05
    assert xdot[0] == 0.05
    assert xdot[1] == pytest.approx((60.0 - friction + 3.0) / 95.0, rel=1e-12)


def test_asymmetry_ripple_and_drift_terms():
    vec = axis_parameters(coulomb=20.0, coulomb_asym=2.0, regularization_velocity=1e-6)
    assert axis_friction(0.1, vec) == pytest.approx(22.0)
    assert axis_friction(-0.1, vec) == pytest.approx(-18.0)
    drift = axis_parameters(coulomb=20.0, friction_drift=0.01, regularization_velocity=1e-6)
    assert axis_friction(0.1, drift, 0.0, 10.0) == pytest.approx(22.0)
    ripple = dict(mass=1.0, time_ripple_sin=5.0, ripple_frequency=10.0)
    assert _xdot(MeasuredAxis(False), [0.0, 0.0], 0.0, t=0.025, **ripple)[1] == pytest.approx(5.0)


def test_two_mass_axis_spring_and_mass_split():
    p = dict(mass=100.0, motor_mass_fraction=0.25, stiffness=1e6, damping=0.0)
    xdot = _xdot(MeasuredAxis(True), [1e-5, 0.0, 0.0, 0.0], 0.0, **p)
    assert xdot[1] == pytest.approx(-10.0 / 25.0)
    assert xdot[3] == pytest.approx(10.0 / 75.0)


def test_scalar_types_and_validation():
    for T in (AutoDiffXd, Expression):
        MeasuredAxis_[T](True).CreateDefaultContext()
    assert MeasuredAxis(False).ToAutoDiffXd() is not None
    with pytest.raises(InputError, match="axis.mass"):
        axis_parameters(mass=0.0)
    with pytest.raises(InputError, match="axis.nonsense"):
        axis_parameters(nonsense=1.0)
    assert len(axis_parameters()) == len(AXIS_PARAMETERS)
    np.testing.assert_array_equal(MeasuredAxis(False).CreateDefaultContext().get_numeric_parameter(0).CopyToVector(),
                                  axis_parameters())
