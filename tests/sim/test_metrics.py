import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.sim.metrics import feed_metrics, following_error, speed_fluctuation, stick_slip


def test_speed_fluctuation_of_a_sine():
    t = np.linspace(0, 1, 10001)
    v = 1e-3 + 3e-5 * np.sin(2 * np.pi * 7 * t)
    mean, dev, rate = speed_fluctuation(v)
    assert mean == pytest.approx(1e-3, rel=1e-4)
    assert dev == pytest.approx(3e-5, rel=1e-3)
    assert rate == pytest.approx(0.03, rel=1e-3)


def test_stick_slip_counts_cycles_with_hysteresis():
    t = np.linspace(0, 1, 20001)
    feed = 1e-4
    v = np.clip(feed * 2 * np.sin(2 * np.pi * 10 * t), -0.1 * feed, None)  # 10 stops per second
    fraction, cycles = stick_slip(v, feed, 0.05)
    assert cycles == 10  # the first stop (t=0) does not count: it starts stuck
    assert 0.4 < fraction < 0.6
    noisy = feed + 0.01 * feed * np.sin(2 * np.pi * 500 * t)
    assert stick_slip(noisy, feed, 0.05) == (0.0, 0)
    assert stick_slip(-v, -feed, 0.05)[1] == 10  # a negative feed is the same creep


def test_ringing_after_a_slip_is_not_a_new_cycle():
    # integral-action stick-slip: each slip overshoots the feed, then rings about zero below it
    t = np.linspace(0, 1, 20001)
    feed = 1e-4
    phase = (t * 4) % 1.0  # 4 slips per second
    slip = 3 * feed * np.sin(np.pi * phase / 0.3) * (phase < 0.3)
    ring = 0.6 * feed * np.sin(2 * np.pi * 40 * t) * np.exp(-(phase - 0.3) / 0.05) * (phase >= 0.3)
    assert stick_slip(slip + ring, feed, 0.05)[1] == 4


def test_following_error_and_window():
    assert following_error([1.0, 2.0], [0.5, 2.0]) == pytest.approx((0.5, np.sqrt(0.125)))
    t = np.linspace(0, 2, 201)
    m = feed_metrics(t, np.full_like(t, 1e-3), t * 1e-3, t * 1e-3 - 2e-6, 1e-3, 1.0, 0.05)
    assert m.window_start == pytest.approx(1.0) and not m.creep
    assert m.report()["following_error_max_um"] == pytest.approx(2.0)
    with pytest.raises(InputError, match="steady_start"):
        feed_metrics(t, t, t, t, 1e-3, 5.0, 0.05)


def test_default_threshold_reads_the_regularized_creep_of_a_stuck_table_as_stuck():
    """At 0.01 mm/s a stuck table under a tanh-regularized law (v_reg = 1 um/s) still creeps at
    v_reg atanh(F/Fs), 1.5 um/s at 90 % of breakaway: the default share of the feed must call that stuck."""
    from drakecreep.params import FrictionParams, SimulationParams

    feed = 1e-5
    creep = FrictionParams().regularization_velocity * np.arctanh(0.9)
    phase = np.arange(4000) % 400
    v = np.where(phase < 300, creep, 3.0 * feed)  # stuck 3/4 of each cycle, then a slip past the feed
    fraction, cycles = stick_slip(v, feed, SimulationParams().stick_threshold)
    assert fraction == pytest.approx(0.75, abs=0.01)
    assert cycles == 9
