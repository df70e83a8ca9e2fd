"""drakecreep.gap.claims.replay_test: the held-out replay must shrink, pooled and in most runs."""

import pytest

from drakecreep.gap.claims import replay_test


def test_a_pooled_shrink_above_the_threshold_in_most_runs_passes():
    r = replay_test([1.0, 1.0, 1.0], [0.5, 0.6, 0.9], threshold=0.2)
    assert r["passes"] and r["runs_better"] == 3
    assert r["shrink"] == pytest.approx(1 - 2.0 / 3.0)


def test_below_the_threshold_or_in_a_minority_of_runs_fails():
    assert not replay_test([1.0, 1.0, 1.0], [0.9, 0.9, 0.95], threshold=0.2)["passes"]
    # one run improves a lot, two get worse: the pooled shrink alone is not enough
    r = replay_test([1.0, 1.0, 10.0], [1.1, 1.1, 1.0], threshold=0.1)
    assert r["shrink"] > 0.1 and r["runs_better"] == 1 and not r["passes"]


def test_the_sign_flip_p_value_is_the_share_of_sign_patterns_with_a_mean_at_least_the_observed():
    import numpy as np

    from drakecreep.gap.claims import sign_flip_p

    # every one of five runs better: only the observed pattern reaches its mean, 1 of 32
    assert sign_flip_p([0.6, 0.09, 0.09, 0.017, 0.016]) == pytest.approx(1 / 32)
    # one run slightly worse: flipping it raises the mean, 2 of 32
    assert sign_flip_p([0.834, -0.003, 0.694, 1.127, 0.108]) == pytest.approx(2 / 32)
    # four runs cannot go below 1/16, one run is no test
    assert sign_flip_p([1.0, 2.0, 3.0, 4.0]) == pytest.approx(1 / 16) and sign_flip_p([1.0]) == 1.0
    # a useless candidate: on symmetric noise the p value is uniform-ish, P(p <= 0.05) about 1/32 for five runs
    rng = np.random.default_rng(0)
    rate = np.mean([sign_flip_p(rng.normal(size=5)) <= 0.05 for _ in range(400)])
    assert rate < 0.06


def test_a_nominal_that_replays_exactly_leaves_nothing_to_shrink():
    """Noise-free synthetic runs replayed by their own model: zero nominal energy is no shrink, not a division by
    zero, and the candidate that adds error is refused."""
    r = replay_test([0.0, 0.0], [0.0, 0.0], threshold=0.0)
    assert r["shrink"] == 0.0 and not r["passes"]
    worse = replay_test([0.0, 0.0], [1e-6, 0.0], threshold=0.0)
    assert worse["shrink"] < 0 and not worse["passes"]
