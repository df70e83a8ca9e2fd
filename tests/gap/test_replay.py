import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from drakecreep.errors import InputError
from drakecreep.gap.idim import PUBLISHED_IDIM, fit_idim
from drakecreep.gap.measured import EMPS_CONTROLLER, MeasuredMeta, MeasuredRun, emps_data_dir, load_emps
from drakecreep.gap.replay import PUBLISHED_REPLAY_ERRORS, RigidModel, replay, replay_errors, rigid_step

EMPS = emps_data_dir()

MODEL = RigidModel(M=95.0, Fv=200.0, Fc=20.0, offset=-3.0)


def _ivp(model, x0, v0, force, h, width=1e-9):
    def f(_, y):
        return [y[1], (force - model.offset - model.Fv * y[1] - model.Fc * np.tanh(y[1] / width)) / model.M]

    sol = solve_ivp(f, (0.0, h), [x0, v0], method="Radau", rtol=1e-10, atol=[1e-14, 1e-12])
    return sol.y[0, -1], sol.y[1, -1]


@pytest.mark.parametrize("force, v0", [(150.0, 0.01), (-150.0, 0.01), (5.0, -0.002), (300.0, 0.0)])
def test_step_matches_solve_ivp(force, v0):
    """Moving legs and a reversal: the exact step agrees with a narrow-tanh solve_ivp."""
    h = 0.02
    x, v = rigid_step(MODEL, 0.0, v0, force, h)
    xi, vi = _ivp(MODEL, 0.0, v0, force, h)
    assert x == pytest.approx(xi, abs=1e-9)
    assert v == pytest.approx(vi, abs=1e-6)


def test_step_without_viscous_friction_matches_solve_ivp():
    model = RigidModel(M=10.0, Fv=0.0, Fc=5.0, offset=0.0)
    x, v = rigid_step(model, 0.0, 0.05, -20.0, 0.05)  # decelerates through zero, leaves backwards
    xi, vi = _ivp(model, 0.0, 0.05, -20.0, 0.05)
    assert x == pytest.approx(xi, abs=1e-9)
    assert v == pytest.approx(vi, abs=1e-6)


def test_step_sticks_and_breaks_away():
    # at rest, |F - offset| <= Fc: stays exactly at rest
    assert rigid_step(MODEL, 0.1, 0.0, 16.9, 0.5) == (0.1, 0.0)
    # reaching zero speed with a small force: stops and stays stopped (a tanh sign would creep)
    x, v = rigid_step(MODEL, 0.0, 1e-3, 10.0, 0.5)
    assert v == 0.0 and 0 < x < 1e-3 * MODEL.M / MODEL.Fv
    # above breakaway it leaves in the direction of the net force
    _, v = rigid_step(MODEL, 0.0, 0.0, -30.0, 1e-3)
    assert v < 0


def test_model_checks():
    with pytest.raises(InputError, match="> 0"):
        RigidModel(M=0.0, Fv=1.0, Fc=1.0)
    with pytest.raises(InputError, match=">= 0"):
        RigidModel(M=1.0, Fv=-1.0, Fc=1.0)
    assert RigidModel.from_idim(PUBLISHED_IDIM).Fc == PUBLISHED_IDIM["Fc"]


def _synthetic_run(model, delay=0):
    t = np.arange(0.0, 4.0, 1e-3)
    x_ref = 0.05 * (1 - np.cos(2 * np.pi * t / 2.0)) + 0.004 * np.sin(2 * np.pi * 3 * t)
    meta = MeasuredMeta(u_units="V", u_gain=35.0, controller=EMPS_CONTROLLER)
    seed = MeasuredRun(t=t, x_ref=x_ref, x_motor=x_ref, u=0 * t, meta=meta)
    sim = replay(seed, model, initial_velocity=0.0, delay=delay)
    return MeasuredRun(t=t, x_ref=x_ref, x_motor=sim.x_sim, u=sim.u_sim, meta=meta), sim


def test_replay_of_its_own_output_is_exact():
    run, sim = _synthetic_run(MODEL)
    again = replay(run, MODEL, initial_velocity=0.0)
    np.testing.assert_array_equal(again.x_sim, sim.x_sim)
    err = replay_errors(again)
    assert err == {"position": 0.0, "velocity": 0.0, "acceleration": 0.0, "force": 0.0}
    # another mass: the errors see it
    other = replay_errors(replay(run, RigidModel(M=120.0, Fv=200.0, Fc=20.0, offset=-3.0), initial_velocity=0.0))
    assert other["acceleration"] > 1.0 and other["position"] > 0


def test_delay_changes_the_loop():
    run, sim = _synthetic_run(MODEL, delay=1)
    assert sim.delay == 1
    np.testing.assert_array_equal(replay(run, MODEL, initial_velocity=0.0, delay=1).x_sim, sim.x_sim)
    assert replay_errors(replay(run, MODEL, initial_velocity=0.0, delay=0))["force"] > 1.0
    with pytest.raises(InputError, match="integer >= 0"):
        replay(run, MODEL, delay=-1)


def test_replay_needs_the_documented_controller():
    run, _ = _synthetic_run(MODEL)
    bare = MeasuredRun(t=run.t, x_ref=run.x_ref, x_motor=run.x_motor, u=run.u,
                       meta=MeasuredMeta(u_units="V", u_gain=35.0))
    with pytest.raises(InputError, match="p_p_cascade"):
        replay(bare, MODEL)


@pytest.fixture(scope="module")
def estimation():
    run = load_emps("estimation").run()
    return run, fit_idim(run)


def test_emps_estimation_documented_loop(estimation):
    """The documented loop (no delay), derivatives of both positions by the IDIM filter.

    Pins what we reach (band 2 %, a regression guard) and states that it is BELOW the published
    errors for every signal: this replay does not reproduce the published table.
    """
    run, fit = estimation
    err = replay_errors(replay(run, fit))
    ours = {"position": 0.001086, "velocity": 0.1229, "acceleration": 4.350, "force": 4.558}
    for k, value in ours.items():
        assert err[k] == pytest.approx(value, rel=0.02), k
        assert err[k] < PUBLISHED_REPLAY_ERRORS["estimation"][k], k


def test_emps_estimation_one_sample_delay_matches_published(estimation):
    """One sample of computational delay and the simulator's own velocity/acceleration.

    Band 10 % of the published value for velocity, acceleration and force: the published simulator
    (solver, how its derivatives were taken) is not documented, so agreement to 10 % is what we claim
    (reached: +0.4 %, -5.1 %, +0.6 %). Position is NOT reproduced: 0.0016 % against 0.0138 %.
    """
    run, fit = estimation
    err = replay_errors(replay(run, fit, delay=1), derivatives="model")
    published = PUBLISHED_REPLAY_ERRORS["estimation"]
    for k in ("velocity", "acceleration", "force"):
        assert err[k] == pytest.approx(published[k], rel=0.10), k
    assert err["position"] < published["position"] / 5
    assert math.isclose(err["position"], 0.0016, rel_tol=0.05)
