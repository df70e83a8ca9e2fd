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
