"""Tests of drakecreep.paper.creep: the paper's creep boundary (eqs. 3, 6, 10, 11)."""

import numpy as np
import pytest

from drakecreep.paper import creep
from drakecreep.errors import InputError
from drakecreep.model.friction import StribeckFriction

K, M, C = 51.6e6, 40.0, 900.0


def test_natural_frequency_and_damping_ratio_closed_form():
    assert creep.natural_frequency(4.0, 1.0) == pytest.approx(2.0)
    # zeta = (C + C1) / (2 sqrt(K M))
    assert creep.damping_ratio(100.0, 1.0, 3.0, -1.0) == pytest.approx(0.1)


def test_v0_is_where_D_equals_D0():
    """Eq. 11 is eq. 10 solved for v: D(v0) must equal sqrt(4 pi zeta)."""
    Fs, Fd, C1 = 30.0, 20.0, -300.0
    v0 = creep.critical_speed(Fs, Fd, K, M, C, C1)
    zeta = creep.damping_ratio(K, M, C, C1)
    assert creep.friction_drop_ratio(Fs, Fd, v0, K, M) == pytest.approx(creep.critical_D0(zeta),
                                                                       rel=1e-12)
    assert creep.creep_predicted(0.9 * v0, Fs, Fd, K, M, C, C1)
    assert not creep.creep_predicted(1.1 * v0, Fs, Fd, K, M, C, C1)


def test_negative_effective_damping_gives_nan_and_creep():
    assert np.isnan(creep.critical_speed(30.0, 20.0, K, M, 100.0, -200.0))
    assert np.isnan(creep.critical_D0(-0.01))
    assert creep.creep_predicted(10.0, 30.0, 20.0, K, M, 100.0, -200.0)


def test_vectorized_over_damping():
    v0 = creep.critical_speed(30.0, 20.0, K, M, np.array([-1.0, 100.0, 400.0]))
    assert np.isnan(v0[0]) and v0[1] > v0[2] > 0.0  # more damping -> lower critical speed


def test_friction_slope_matches_analytic_stribeck_derivative():
    Fc, Fs, vs, fv = 20.0, 26.0, 1e-4, 200.0
    law = StribeckFriction(viscous=fv, stribeck_velocity=vs, regularization_velocity=1e-12)
    v = np.array([2e-5, 1e-4, 5e-4])
    c1 = creep.friction_slope(lambda x: law.steady_state_force(x, Fc, Fs), v)
    exact = -(Fs - Fc) * 2.0 * v / vs**2 * np.exp(-(v / vs) ** 2) + fv
    np.testing.assert_allclose(c1, exact, rtol=1e-5)
    assert c1[1] < 0.0  # falling branch at v = vs


def test_friction_slope_uses_analytic_derivative_and_rejects_zero_speed():
    assert creep.friction_slope(np.sin, 0.3, derivative=np.cos) == pytest.approx(np.cos(0.3))
    with pytest.raises(InputError):
        creep.friction_slope(np.sin, 0.0)


def test_self_consistent_critical_speed_is_fixed_point():
    Fc, Fs = 20.0, 26.0
    law = StribeckFriction(viscous=0.0, stribeck_velocity=1e-3, regularization_velocity=1e-12)
    F = lambda x: law.steady_state_force(x, Fc, Fs)  # noqa: E731
    v = creep.critical_speed_self_consistent(F, Fs, Fc, K, M, C)
    assert v > 0.0
    assert creep.critical_speed(Fs, Fc, K, M, C, creep.friction_slope(F, v)) == pytest.approx(v,
                                                                                             rel=1e-8)


def test_creep_condition_of_a_lumped_drive_is_the_equations_at_its_feed():
    from drakecreep.model.lumped import lumped
    from drakecreep.params import preset

    drive = lumped(preset("paper"), 3)
    for v in (0.1e-3, 1e-3):
        c = creep.creep_condition(drive, v)
        c1 = creep.friction_slope(drive.steady_friction, v)
        args = (drive.breakaway, drive.coulomb, drive.stiffness, drive.mass, drive.damping)
        assert c.friction_slope == pytest.approx(c1)
        assert c.critical_speed == pytest.approx(creep.critical_speed(*args, c1), nan_ok=True)  # nan: C + C1 <= 0
        assert c.critical_speed_self_consistent == pytest.approx(creep.critical_speed_of(drive))
        assert c.D0 == pytest.approx(np.sqrt(4 * np.pi * c.zeta) if c.zeta > 0 else np.nan, nan_ok=True)
        assert c.creep == (not v >= c.critical_speed)  # eq. 11: creep below v0 (and where C + C1 <= 0)
