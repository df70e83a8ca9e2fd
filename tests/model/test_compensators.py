"""Compensators at the velocity-loop rate on the encoder speed (issue 15, defect 5)."""

import math

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.model.compensators import (
    DisturbanceObserver, LuGreCompensator, Sampling, StaticCompensator, compensator_model, compensator_sampling,
)
from drakecreep.params import CompensationParams, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
from drakecreep.studies.compensation import with_method

H = 2.5e-4


def _fix(system, c, angle, v_ref=1e-4, torque=0.0, true_speed=123.0):
    # the ideal tachometer port carries a value the sampled compensators must not use
    system.GetInputPort("reference").FixValue(c, [0.0, v_ref])
    system.GetInputPort("motor_measured").FixValue(c, [angle, true_speed])
    system.GetInputPort("torque_command").FixValue(c, [torque])
    system.GetInputPort("table_state").FixValue(c, [0.0, 7.0])
    system.GetInputPort("table_position_measured").FixValue(c, [0.0])


def _step(system, c):
    c.SetDiscreteState(0, system.EvalUniquePeriodicDiscreteUpdate(c).get_vector(0).CopyToVector())
    return system.GetOutputPort("torque").Eval(c)[0]


def test_static_measured_reads_the_encoder_difference(paper):
    model = compensator_model(paper, 3)
    lead = paper.screw.lead
    r = lead / (2 * math.pi)
    comp = StaticCompensator(model, lead, velocity_blend=1.0, sampling=Sampling(period=H, delay=0.0, angle0=0.2))
    c = comp.CreateDefaultContext()
    _fix(comp, c, angle=0.2 + 0.01)
    v = 0.01 / H * r  # the backward difference of the counts, table side
    law = model.g(v) * math.tanh(v / model.regularization_velocity) + model.viscous * v
    assert _step(comp, c) == pytest.approx(law * r, rel=1e-12)
    # the next sample differences against the angle it stored
    _fix(comp, c, angle=0.2 + 0.01 + 0.003)
    v = 0.003 / H * r
    law = model.g(v) * math.tanh(v / model.regularization_velocity) + model.viscous * v
    assert _step(comp, c) == pytest.approx(law * r, rel=1e-12)


def test_lugre_advances_its_state_exactly_over_the_period(paper):
    model = compensator_model(paper, 3)
    lead = paper.screw.lead
    r = lead / (2 * math.pi)
    comp = LuGreCompensator(model, lead, sampling=Sampling(period=H, delay=1.0, angle0=0.0))
    c = comp.CreateDefaultContext()
    d_angle = 2e-4 / r * H  # 0.2 mm/s at the table
    outputs, w = [], 0.0
    for k in range(1, 6):
        _fix(comp, c, angle=k * d_angle)
        outputs.append(_step(comp, c))
        w = c.get_discrete_state_vector().GetAtIndex(1)
    # by hand: v held, dw/dt = a - b w from w = 0
    v = 2e-4
    a, b = model.sigma0 / model.fc * v, model.sigma0 * v / model.g(v)
    w_hand = 0.0
    forces = []
    for _ in range(5):
        zdot = v - v * w_hand * model.fc / model.g(v)
        forces.append((model.fc * w_hand + model.sigma1 * zdot + model.viscous * v) * r)
        w_hand = w_hand * math.exp(-b * H) + a * (1 - math.exp(-b * H)) / b
    assert w == pytest.approx(w_hand, rel=1e-12)
    # one sample of computation delay: the motor gets force[k-1]
    np.testing.assert_allclose(outputs, [0.0] + forces[:4], rtol=1e-12)


def test_discrete_observer_recovers_a_constant_load_on_a_rigid_body():
    """raw_k = (tau_{k-1} + tau_{k-2}) / 2 - J (omega_k - omega_{k-1}) / h is exact for a rigid body."""
    J, load = 2e-3, 0.37
    dob = DisturbanceObserver(J, 1e5, sampling=Sampling(period=H, delay=0.0, angle0=0.0, torque0=load))
    c = dob.CreateDefaultContext()
    theta, omega = 0.0, 0.0
    command = [0.5, 0.9, -0.2, 0.4, 0.1, 0.6]
    estimates = []
    applied = 0.0
    for tau_c in command:
        # the motor turns over one period under the held torque (command + the observer's own output)
        acc = (tau_c + applied - load) / J
        theta, omega = theta + omega * H + 0.5 * acc * H * H, omega + acc * H
        _fix(dob, c, angle=theta, torque=tau_c)
        applied = _step(dob, c)
        estimates.append(applied)
    # Q = 1 - exp(-L h) = 1 - 1e-11: the estimate is the load from the second sample on
    np.testing.assert_allclose(estimates[1:], load, rtol=1e-9)


def test_compensator_torque_is_held_over_the_velocity_period(short_paper):
    p = with_value(with_value(short_paper, "simulation.steady_start", 0.05), "simulation.convergence_check", False)
    p = with_value(p, "simulation.log_period", H / 5)
    scenario = Scenario(feed=1e-4, load_case=3, duration=0.1)
    held = with_method(p, "lugre")
    assert held.compensation.speed_source == "encoder"  # the default with a sampled controller
    for backend in ("compiled", "leaf"):
        tau = simulate(held, scenario, backend=backend).signals["compensation_torque"]
        # entries 5k + 1 .. 5k + 4 lie inside (t_k, t_k+1) (at t_k itself the log's time may round either
        # side of the sample's update)
        blocks = tau[:5 * (len(tau) // 5)].reshape(-1, 5)[:, 1:]
        assert np.all(blocks == blocks[:, :1])
        assert np.count_nonzero(np.diff(blocks[:, 0])) > 0.9 * len(blocks)
    ideal = simulate(with_method(p, "lugre", speed_source="ideal"), scenario).signals["compensation_torque"]
    blocks = ideal[:5 * (len(ideal) // 5)].reshape(-1, 5)[:, 1:]
    assert np.count_nonzero(np.ptp(blocks, axis=1)) > 0.9 * len(blocks)


def test_speed_source_choices(paper):
    with pytest.raises(InputError) as err:
        CompensationParams(speed_source="tacho")
    assert "speed_source" in str(err.value)
    assert compensator_sampling(with_value(paper, "compensation.speed_source", "ideal")) is None
    continuous = with_value(paper, "controller.sampled", False)
    assert compensator_sampling(continuous) is None  # no loop rate to run at
    s = compensator_sampling(paper, angle0=0.5)
    assert (s.period, s.delay, s.angle0) == (paper.controller.velocity_period, 1.0, 0.5)


def test_conversion_forwards_the_sampling(paper):
    model = compensator_model(paper, 3)
    sampling = Sampling(period=H, delay=1.5, angle0=0.1, torque0=0.2)
    for system in (LuGreCompensator(model, paper.screw.lead, 0.5, "motor", sampling),
                   StaticCompensator(model, paper.screw.lead, 0.3, "table", sampling),
                   DisturbanceObserver(1e-3, 300.0, sampling=sampling)):
        for converted in (system.ToAutoDiffXd(), system.ToSymbolic()):
            assert converted.sampling == sampling
            np.testing.assert_array_equal(converted.initial_state, system.initial_state)
