import math

import pytest

from drakecreep.errors import InputError
from drakecreep.scenario import Scenario
from drakecreep.servo.tuning import POSITION_BANDWIDTH_RATIO, tune

SC = Scenario(feed=1e-3, load_case=3)


@pytest.fixture(scope="module")
def tuned(paper):
    return tune(paper, SC, bandwidth_Hz=30.0, phase_margin_deg=55.0)


def test_tuned_loop_meets_the_targets(tuned):
    s = tuned.summary()
    assert s["velocity"]["phase_margin_deg"] == pytest.approx(55.0, abs=1e-4)
    assert s["velocity"]["bandwidth_Hz"] == pytest.approx(30.0, rel=1e-4)
    assert s["velocity"]["crossover_Hz"] == pytest.approx(tuned.crossover_Hz, rel=1e-6)
    assert tuned.position_gain == pytest.approx(2 * math.pi * 30.0 / POSITION_BANDWIDTH_RATIO)
    assert s["position"]["closed_loop_stable"] and s["velocity"]["closed_loop_stable"]
    assert tuned.params.controller.velocity_gain == tuned.velocity_gain


def test_wider_bandwidth_needs_more_gain(paper, tuned):
    wide = tune(paper, SC, bandwidth_Hz=45.0, phase_margin_deg=55.0)
    assert wide.velocity_gain > tuned.velocity_gain


@pytest.mark.parametrize("bw, pm, field", [(-1.0, 60.0, "bandwidth"), (40.0, 95.0, "phase-margin"),
                                           (2000.0, 60.0, "bandwidth")])
def test_bad_targets(paper, bw, pm, field):
    with pytest.raises(InputError) as err:
        tune(paper, SC, bw, pm)
    assert err.value.field == field
