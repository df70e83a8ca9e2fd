import math

import numpy as np
import pytest

from drakecreep.gap.effects import (
    EFFECT_NAMES,
    EFFECTS,
    EffectContext,
    get_effect,
    idim_data,
    position_grid_step,
    replay_with_effects,
    synthesize_run,
)
from drakecreep.errors import InputError
from drakecreep.gap.benchmark import out_and_back
from drakecreep.gap.measured import EMPS_CONTROLLER, MeasuredMeta, SensorMeta
from drakecreep.gap.replay import RigidModel, replay

META = MeasuredMeta(u_units="V", u_gain=35.15, controller=EMPS_CONTROLLER, sensors=SensorMeta(encoder_resolution=5e-8))
MODEL = RigidModel(M=90.0, Fv=200.0, Fc=20.0, offset=-3.0)
T = np.arange(3000) * 1e-3


def test_library_has_at_least_eight_effects_with_parameters_and_signatures():
    assert len(EFFECTS) >= 8
    assert len(set(EFFECT_NAMES)) == len(EFFECTS)
    for e in EFFECTS:
        assert e.signature and e.description
        assert e.n_params >= 1
    with pytest.raises(InputError):
        get_effect("gremlins")


def test_replay_without_terms_matches_the_foundation_replay():
    run = synthesize_run(T, out_and_back(0.05, 0.01), META, MODEL)
    ours = replay_with_effects(run, MODEL)
    ref = replay(run, MODEL)
    np.testing.assert_allclose(ours["x"], ref.x_sim, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ours["u"], ref.u_sim, rtol=0, atol=1e-9)


def test_delay_term_matches_the_foundation_delay():
    run = synthesize_run(T, out_and_back(0.05, 0.01), META, MODEL)
    delay = get_effect("control_delay").replay_term([], 1, EffectContext(), {})
    ours = replay_with_effects(run, MODEL, [delay])
    ref = replay(run, MODEL, delay=1)
    np.testing.assert_allclose(ours["x"], ref.x_sim, rtol=0, atol=1e-12)


def test_idim_data_drops_standing_samples_and_keeps_decimation():
    run = synthesize_run(T, out_and_back(0.05, 0.01), META, MODEL)
    all_ = idim_data([run])
    moving = idim_data([run], v_min=1e-3)
    assert all_.n == len(range(50, 3000 - 50, 10))
    assert moving.n < all_.n
    assert np.all(np.abs(moving.dq) > 1e-3)


def test_cogging_columns_recover_a_force_ripple():
    """A ripple added to the plant comes back from the linear columns with its amplitude and phase."""
    ctx = EffectContext(screw_lead=5e-3, motor_period=5e-3)
    cog = get_effect("cogging")
    truth = cog.replay_term([3.0, -2.0, 0.0, 0.0], 3, ctx, {})
    run = synthesize_run(T, out_and_back(0.02, 0.01), META, MODEL, [truth])
    sig = idim_data([run], v_min=1e-3, motor_period=5e-3)
    from drakecreep.gap.idim import regressor

    X = np.column_stack([regressor(sig.dq, sig.ddq), cog.columns(sig, ctx, 3, {})])
    theta, *_ = np.linalg.lstsq(X, sig.tau, rcond=None)
    assert theta[4] == pytest.approx(3.0, abs=0.3)
    assert theta[5] == pytest.approx(-2.0, abs=0.3)
    assert abs(theta[6]) < 0.3 and abs(theta[7]) < 0.3


def test_lead_error_term_changes_only_the_measurement():
    ctx = EffectContext(screw_lead=5e-3)
    term = get_effect("lead_error").replay_term([2e-6, 0.0, 0.0, 0.0], 1, ctx, {"M": 90.0, "Fv": 200.0})
    x = 1.25e-3  # a quarter of the lead: sin = 1
    assert term.measure(x) == pytest.approx(x + 2e-6, abs=1e-15)
    assert term.force is None


def test_physical_checks():
    ctx = EffectContext()
    nominal = {"M": 90.0, "Fv": 200.0}
    assert get_effect("stribeck").physical([5.0], 0.01, ctx, nominal)
    assert not get_effect("stribeck").physical([-5.0], 0.01, ctx, nominal)
    assert get_effect("backlash").physical([-30.0], 1e-5, ctx, nominal)
    assert not get_effect("backlash").physical([10.0], 1e-5, ctx, nominal)


def test_position_grid_step():
    x = np.arange(-100, 100) * 5e-8 + 0.0
    assert position_grid_step(x) == pytest.approx(5e-8)
    assert position_grid_step(x + 1.234e-9 * np.random.default_rng(0).random(x.size)) <= 1e-9
    assert math.isclose(position_grid_step(np.array([0.0, 1e-6, 3e-6])), 1e-6)
