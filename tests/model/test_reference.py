import pytest

from drakecreep.model.reference import FeedReference


@pytest.mark.parametrize("t, x, v", [(0.0, 0.5, 0.0), (0.05, 0.5 + 0.5 * 2.0 * 0.05**2 / 0.1, 1.0),
                                     (0.3, 0.5 + 2.0 * (0.3 - 0.05), 2.0)])
def test_ramp_with_constant_acceleration(t, x, v):
    ref = FeedReference(2.0, 0.1, 0.5)
    c = ref.CreateDefaultContext()
    c.SetTime(t)
    assert ref.get_output_port(0).Eval(c) == pytest.approx([x, v])


def test_no_acceleration_phase_and_conversion():
    ref = FeedReference(1e-3, 0.0)
    c = ref.CreateDefaultContext()
    c.SetTime(2.0)
    assert ref.get_output_port(0).Eval(c) == pytest.approx([2e-3, 1e-3])
    assert ref.ToAutoDiffXd().feed == 1e-3
