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
    _check_one_source(law, 2e-4, [1e-6] * law.num_states)


def _check_one_source(law, v, z):
    """The law's force at ``(v, z)`` in float, AutoDiffXd and a symbolic Expression evaluated there agree."""
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


# --------------------------------------------------------------------------- GMS (defect 8)

def _gms(**kw):
    from drakecreep.model.friction import GMSFriction

    return GMSFriction(**COMMON, bristle_stiffness=1e7, bristle_damping=1e3, **kw)


def test_gms_elements_sum_to_sigma0_and_let_go_one_after_another():
    law = _gms(elements=4)
    assert law.num_states == 4
    assert law.stiffnesses.sum() == pytest.approx(1e7)
    assert law.shares.sum() == pytest.approx(1.0)
    breakaway = law.shares * FS / law.stiffnesses  # displacement at which each element reaches its limit
    assert np.all(np.diff(breakaway) > 0)


@pytest.mark.parametrize("v", [-2e-3, -3e-4, 5e-5, 1e-4, 4e-4, 3e-3])
def test_gms_steady_state_equals_the_stribeck_curve(v):
    law = _gms(elements=4, attraction=1e4)
    sol = solve_ivp(lambda t, w: law.state_rates(v, w, FC, FS), (0, 0.5), np.zeros(4), method="LSODA",
                    rtol=1e-10, atol=1e-12)
    force = law.force(v, sol.y[:, -1], FC, FS)
    expected = StribeckFriction(**COMMON).steady_state_force(v, FC, FS)
    assert force == pytest.approx(expected, rel=1e-6)
    assert law.steady_state_force(v, FC, FS) == pytest.approx(expected, rel=1e-9)


def _presliding(law, x_of_t, v_of_t, t_end, n=4001):
    t = np.linspace(0.0, t_end, n)
    sol = solve_ivp(lambda s, w: law.state_rates(v_of_t(s), w, FC, FS), (0, t_end), np.zeros(law.num_states),
                    t_eval=t, method="LSODA", rtol=1e-10, atol=1e-12, max_step=t_end / n)
    x = x_of_t(t)
    f = np.array([law.force(v_of_t(s), sol.y[:, i], FC, FS) for i, s in enumerate(t)])
    return t, x, f


def test_gms_presliding_is_a_hysteresis_loop_that_follows_masing_at_reversal():
    """Virgin curve to x_r, reversal: the return branch is F_r - 2 F_virgin((x_r - x) / 2) (Masing), and the
    loop encloses an area (energy lost per cycle) -- rate-independent, not viscous. Viscous and micro-damping
    off, so that the force is the elements' alone."""
    from drakecreep.model.friction import GMSFriction

    law = GMSFriction(**{**COMMON, "viscous": 0.0}, bristle_stiffness=1e7, bristle_damping=0.0, elements=6,
                      attraction=1e5)
    amp = 4e-6  # beyond the last element's breakaway (H_6 Fs / sigma0 = 7.4 um would be full sliding)
    period = 1.0
    xt = lambda t: amp * np.sin(2 * np.pi * t / period)  # noqa: E731
    vt = lambda t: amp * 2 * np.pi / period * np.cos(2 * np.pi * t / period)  # noqa: E731
    t, x, f = _presliding(law, xt, vt, 0.75 * period)
    quarter = t <= 0.25 * period
    virgin = lambda d: np.interp(d, x[quarter], f[quarter])  # noqa: E731
    fr = f[quarter][-1]
    back = (t > 0.25 * period) & (t <= 0.75 * period)
    predicted = fr - 2 * virgin((amp - x[back]) / 2)
    # Masing holds up to the 2 % stick-slip blend of each element
    assert np.max(np.abs(f[back] - predicted)) < 0.01 * fr
    # initial stiffness after reversal is sigma0 (every element sticks again)
    i = np.argmax(back)
    slope = (f[i + 5] - f[i]) / (x[i + 5] - x[i])
    assert slope == pytest.approx(1e7, rel=0.05)
    # the loop is open: at x = 0 the loading and unloading forces differ by a dry-friction amount
    width = virgin(0.0) - np.interp(0.0, x[back][::-1], f[back][::-1])
    assert width > 0.1 * FC  # at x = 0 the loading branch is at 0, the unloading one well below


def test_gms_does_not_drift_where_lugre_does_under_an_oscillating_subbreakaway_load():
    """A 1 kg block under 0.5 Fc + 0.3 Fc sin(2 pi 20 t), below breakaway at all times: LuGre's bristles
    slide a little every cycle and the block drifts (Dupont et al., IEEE TAC 47(5), 2002); GMS shakes down
    to closed presliding loops and stays put."""
    lugre = LuGreFriction(**COMMON, bristle_stiffness=1e7, bristle_damping=1e3)
    gms = _gms(elements=4)
    mass = 1.0

    def rhs(law):
        def f(t, s):
            v, w = s[1], s[2:]
            load = 0.5 * FC + 0.3 * FC * np.sin(2 * np.pi * 20 * t)
            return [v, (load - law.force(v, w, FC, FS)) / mass, *law.state_rates(v, w, FC, FS)]
        return f

    drift = {}
    for name, law in (("lugre", lugre), ("gms", gms)):
        sol = solve_ivp(rhs(law), (0, 0.6), np.zeros(2 + law.num_states), method="LSODA", rtol=1e-9, atol=1e-13,
                        dense_output=True, max_step=2e-3)
        drift[name] = sol.sol(0.6)[0] - sol.sol(0.3)[0]
    assert drift["lugre"] > 5e-6  # tens of um per second
    assert abs(drift["gms"]) < 1e-9


def test_gms_one_source_for_float_autodiff_and_symbolic():
    law = _gms(elements=3)
    v, w = 2e-4, [0.1, 0.3, 0.33]
    expected = law.force(v, w, FC, FS)
    ad = law.force(AutoDiffXd(v, np.array([1.0])), [AutoDiffXd(x) for x in w], FC, FS)
    assert ad.value() == pytest.approx(expected)
    sv = Variable("v")
    ws = [Variable(f"w{i}") for i in range(3)]
    expr = law.force(Expression(sv), [Expression(x) for x in ws], FC, FS)
    assert expr.Evaluate({sv: v, **dict(zip(ws, w))}) == pytest.approx(expected)


def test_gms_selectable_from_params(paper):
    from drakecreep.model.friction import GMSFriction
    from drakecreep.params import with_value

    p = with_value(with_value(paper, "friction.law", "gms"), "friction.gms_elements", 5)
    law = make_friction_law(p.friction)
    assert isinstance(law, GMSFriction) and law.num_states == 5
    assert law.bristle_stiffness == p.friction.bristle_stiffness


ASYM = dict(coulomb_asymmetry=0.2, viscous_asymmetry=-0.4)


@pytest.mark.parametrize("name", ["coulomb", "stribeck", "lugre", "gms"])
def test_asymmetric_levels_scale_each_direction_and_keep_the_mean(name, paper):
    """Moving +x the dry level is (1 + a_c) and the viscous (1 + a_v) times the symmetric law's, -x (1 - a)."""
    from drakecreep.params import with_value

    sym = make_friction_law(with_value(paper, "friction.law", name).friction)
    law = make_friction_law(with_value(with_value(with_value(paper, "friction.law", name), "friction.coulomb_asymmetry",
                                                  0.2), "friction.viscous_asymmetry", -0.4).friction)
    for v in (3e-4, 2e-3):  # well above v_reg (1 um/s)
        dry = sym.steady_state_force(v, FC, FS) - sym.viscous * v
        for s in (1.0, -1.0):
            expected = s * dry * (1 + 0.2 * s) + sym.viscous * (1 - 0.4 * s) * s * v
            assert float(law.steady_state_force(s * v, FC, FS)) == pytest.approx(expected, rel=1e-9)
    # the mean of the two directions is the symmetric law's, so a fitted asymmetry leaves the level alone
    v = 1e-3
    mean = (law.steady_state_force(v, FC, FS) - law.steady_state_force(-v, FC, FS)) / 2
    assert float(mean) == pytest.approx(float(sym.steady_state_force(v, FC, FS)), rel=1e-12)


def test_symmetric_law_has_no_direction_term():
    """a = 0 (every preset) builds the same expression as before the asymmetry existed: no tanh of v added."""
    law = StribeckFriction(**COMMON)
    sv = Variable("v")
    assert law.viscous_force(Expression(sv)).EqualTo(COMMON["viscous"] * Expression(sv))
    assert law.sliding_level(Expression(sv), FC, FS).EqualTo(stribeck_curve(Expression(sv), FC, FS, 1e-4))


@pytest.mark.parametrize("law", [CoulombFriction(**COMMON, **ASYM), StribeckFriction(**COMMON, **ASYM),
                                 LuGreFriction(**COMMON, **ASYM, bristle_stiffness=1e7, bristle_damping=1e3)])
def test_asymmetric_law_one_source_for_float_autodiff_and_symbolic(law):
    for v in (2e-4, -3e-4):
        _check_one_source(law, v, [0.4] * law.num_states)


def test_asymmetric_lugre_settles_on_its_own_level_in_each_direction():
    law = LuGreFriction(**COMMON, **ASYM, bristle_stiffness=1e7, bristle_damping=1e3)
    for v in (4e-4, -4e-4):
        sol = solve_ivp(lambda t, z: law.state_rates(v, z, FC, FS), (0, 3.0), [0.0], method="LSODA", rtol=1e-10,
                        atol=1e-14)
        assert law.force(v, sol.y[:, -1], FC, FS) == pytest.approx(float(law.steady_state_force(v, FC, FS)), rel=1e-6)
