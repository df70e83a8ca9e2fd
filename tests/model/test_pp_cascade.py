"""PPCascade: the EMPS P-P law as a sampled Drake system."""

import numpy as np
import pytest
from pydrake.symbolic import Expression

from drakecreep.errors import InputError
from drakecreep.model.pp_cascade import PPCascade, PPCascade_, pp_initial_state


def _update(system, state, x_ref, q):
    ctx = system.CreateDefaultContext()
    ctx.SetDiscreteState(state)
    system.GetInputPort("x_ref").FixValue(ctx, [x_ref])
    system.GetInputPort("position").FixValue(ctx, [q])
    return system.EvalUniquePeriodicDiscreteUpdate(ctx).get_vector().CopyToVector()


def test_one_sample_of_the_documented_law():
    kp, kv, h = 160.18, 243.45, 1e-3
    c = PPCascade(kp, kv, 10.0, h, (0.5, 0.5), gain=35.15)
    state = pp_initial_state((0.5, 0.5), 0.0, 0.0, 0.0, h)  # at rest at 0
    new = _update(c, state, 1e-5, 2e-6)
    qf, qf_prev = 0.5 * 2e-6 + 0.5 * 0.0, 0.0
    u = kp * kv * (1e-5 - 2e-6) - kv * (qf - qf_prev) / h
    assert new[2] == pytest.approx(u)
    assert new[-1] == pytest.approx(u)  # no delay: applied at once
    assert _update(c, state, 1.0, 0.0)[2] == 10.0  # saturation


def test_encoder_counts_and_delay_queue():
    c = PPCascade(1.0, 1.0, 1e9, 1e-3, (1.0,), resolution=1e-6, delay=2)
    state = pp_initial_state((1.0,), 2, 0.0, 0.0, 1e-3, u_history=(7.0, 8.0, 9.0))
    new = _update(c, state, 0.0, 2.7e-6)
    assert new[0] == pytest.approx(2e-6)  # counted, floor
    assert list(new[1:4]) == pytest.approx([new[1], 7.0, 8.0])
    assert new[-1] == 8.0  # u from two samples ago


def test_symbolic_and_bad_delay():
    PPCascade_[Expression](1.0, 1.0, 10.0, 1e-3, (0.5, 0.5)).CreateDefaultContext()
    with pytest.raises(InputError, match="delay"):
        PPCascade(1.0, 1.0, 10.0, 1e-3, delay=float("nan"))
    with pytest.raises(InputError, match="initial_state"):
        PPCascade(1.0, 1.0, 10.0, 1e-3, initial_state=np.zeros(7))
