import numpy as np
import pytest
from pydrake.autodiffutils import AutoDiffXd
from pydrake.symbolic import Expression, Variable
from scipy.integrate import solve_ivp

from drakecreep.model.friction import CoulombFriction, LuGreFriction, StribeckFriction, make_friction_law, stribeck_curve

FC, FS = 20.0, 30.0
COMMON = dict(viscous=150.0, stribeck_velocity=1e-4, regularization_velocity=1e-6)


def test_stribeck_curve_limits():
    assert stribeck_curve(0.0, FC, FS, 1e-4) == pytest.approx(FS)
    assert stribeck_curve(1e-2, FC, FS, 1e-4) == pytest.approx(FC)
    assert stribeck_curve(1e-4, FC, FS, 1e-4) == pytest.approx(FC + (FS - FC) / np.e)
    assert stribeck_curve(1e-4, FC, FS, 1e-4, exponent=1.0) == pytest.approx(FC + (FS - FC) / np.e)


@pytest.mark.parametrize("v", [-2e-3, -3e-4, 5e-5, 1e-4, 4e-4, 3e-3])
def test_lugre_steady_state_equals_the_stribeck_curve(v):
    law = LuGreFriction(**COMMON, bristle_stiffness=1e7, bristle_damping=1e3)
    sol = solve_ivp(lambda t, z: law.state_rates(v, z, FC, FS), (0, 3.0), [0.0], method="LSODA", rtol=1e-10, atol=1e-14)
    force = law.force(v, sol.y[:, -1], FC, FS)
    expected = StribeckFriction(**COMMON).steady_state_force(v, FC, FS)
    assert force == pytest.approx(expected, rel=1e-6)
    assert law.steady_state_force(v, FC, FS) == pytest.approx(expected, rel=1e-6)


def test_stateless_laws_are_odd_and_oppose_motion():
    v = np.linspace(1e-5, 1e-2, 50)
    for law in (CoulombFriction(**COMMON), StribeckFriction(**COMMON)):
        f = law.steady_state_force(v, FC, FS)
        assert np.all(f > 0)
        np.testing.assert_allclose(law.steady_state_force(-v, FC, FS), -f)


def test_stribeck_slope_is_negative_just_above_zero_speed():
    law = StribeckFriction(**COMMON)
    v = np.array([5e-5, 6e-5])
    f = law.steady_state_force(v, FC, FS)
    assert f[1] < f[0]  # the drop that feeds creep (the paper's C1 < 0)


@pytest.mark.parametrize("law", [CoulombFriction(**COMMON), StribeckFriction(**COMMON),
                                 LuGreFriction(**COMMON, bristle_stiffness=1e7, bristle_damping=1e3)])
def test_one_source_for_float_autodiff_and_symbolic(law):
    v, z = 2e-4, [1e-6] * law.num_states
    expected = law.force(v, z, FC, FS)
    ad = law.force(AutoDiffXd(v, np.array([1.0])), [AutoDiffXd(zi) for zi in z], FC, FS)
    assert ad.value() == pytest.approx(expected)
    sv = Variable("v")
    zs = [Variable(f"z{i}") for i in range(law.num_states)]
    expr = law.force(Expression(sv), [Expression(zi) for zi in zs], FC, FS)
    env = {sv: v, **{zi: val for zi, val in zip(zs, z)}}
    assert expr.Evaluate(env) == pytest.approx(expected)


def test_make_friction_law_from_params(paper):
    law = make_friction_law(paper.friction)
    assert isinstance(law, LuGreFriction) and law.bristle_stiffness == paper.friction.bristle_stiffness


def test_lugre_without_dry_friction_is_viscous_only():
    # frictionless guides with the nut's share on the screw leave Fc = Fs = 0 on the table: the
    # zero-friction limit (bristles relax at once), not a division by zero
    law = LuGreFriction(bristle_stiffness=1e8, bristle_damping=2e3, **COMMON)
    assert law.force(2e-4, [0.0], 0.0, 0.0) == pytest.approx(150.0 * 2e-4)
    assert law.state_rates(2e-4, [0.0], 0.0, 0.0) == [0.0]
