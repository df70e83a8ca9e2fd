import math

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.model.sensors import differenced_speed
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.metrics import speed_fluctuation
from drakecreep.sim.simulation import simulate
from drakecreep.studies import table_fluctuation as tf

SHAPES = {path: nominal for path, (nominal, *_rest) in tf.SHAPES.items()}
LEAD_PERIOD = SHAPES["disturbance.lead_error_period"]
RIPPLE_HZ = SHAPES["disturbance.ripple_frequency"]
#: the five distinct experiments of Tables 8-9 (load case, feed mm/s)
KEYS = [(1, 1.0), (2, 1.0), (3, 1.0), (3, 0.5), (3, 2.0)]


def synthetic_responses(duration=1.0, log=2.5e-4):
    """Table positions with analytic unit responses: a lead error whose ripple grows 10 % per load case
    (feed-proportional speed ripple), a 5 Hz ripple independent of feed and load."""
    t = np.arange(0.0, duration + 0.5 * log, log)
    out = {}
    for lc, feed in KEYS:
        v = feed * 1e-3
        x0 = v * t
        r = tf.Responses(lc, feed, t, x0, steady_start=0.25)
        r.dx[("lead_error", LEAD_PERIOD)] = 1e-6 * (1.0 + 0.1 * (lc - 1)) * np.sin(2 * math.pi * x0 / LEAD_PERIOD)
        r.dx[("force_ripple", RIPPLE_HZ)] = 2.5e-7 * np.sin(2 * math.pi * RIPPLE_HZ * t + 0.3)
        out[(lc, feed)] = r
    return out


def synthetic_experiments(responses, amplitudes):
    return [dict(load_case=lc, feed_mm_s=f, experiment_mm_s=tf.predict(responses[(lc, f)], amplitudes, SHAPES) * 1e3)
            for lc, f in KEYS]


@pytest.fixture(scope="module")
def synthetic():
    responses = synthetic_responses()
    truth = {"lead_error": 0.8e-6, "force_ripple": 1.5}
    return responses, truth, synthetic_experiments(responses, truth)


def test_experiments_are_the_five_distinct_ones():
    exps = tf.experiments()
    assert [(e["load_case"], e["feed_mm_s"]) for e in exps] == KEYS
    assert exps[2]["rows"] == [3, 5] and exps[2]["experiment_mm_s"] == 0.031
    noise = tf.rounding_noise_percent(exps)
    assert noise[2] == pytest.approx(0.1 / math.sqrt(12) / 0.031)


def test_loo_recovers_the_true_hypothesis_and_predicts_held_out_rows(synthetic):
    responses, truth, exps = synthetic
    true = tf.leave_one_out(("lead_error", "force_ripple"), responses, exps, SHAPES)
    assert true["amplitudes"]["lead_error_um"] == pytest.approx(0.8, rel=0.02)
    assert true["amplitudes"]["force_ripple_N"] == pytest.approx(1.5, rel=0.02)
    assert true["held_out_max_abs_percent"] < 1.0
    for p in true["experiments"]:
        assert p["fold_amplitudes"]["lead_error_um"] == pytest.approx(0.8, rel=0.03)
    # a hypothesis with the wrong dependence on the feed cannot predict the extreme feeds
    wrong = tf.leave_one_out(("force_ripple",), responses, exps, SHAPES)
    assert wrong["held_out_mean_abs_percent"] > 10 * true["held_out_mean_abs_percent"] + 5.0
    assert true["bic"] < wrong["bic"]


def test_a_fold_never_sees_its_held_out_row(synthetic):
    responses, _, exps = synthetic
    hyp = ("lead_error", "force_ripple")
    base = tf.leave_one_out(hyp, responses, exps, SHAPES)
    held = 4  # load case 3 at 2 mm/s
    perturbed = [dict(e) for e in exps]
    perturbed[held]["experiment_mm_s"] *= 1.5
    moved = tf.leave_one_out(hyp, responses, perturbed, SHAPES)
    # the held-out prediction of that row is the same; its in-sample fit (which sees it) moves
    assert moved["experiments"][held]["held_out_mm_s"] == base["experiments"][held]["held_out_mm_s"]
    assert moved["experiments"][held]["in_sample_mm_s"] != pytest.approx(base["experiments"][held]["in_sample_mm_s"],
                                                                         rel=0.01)
    # and every other fold, which trains on it, moves
    assert moved["experiments"][0]["held_out_mm_s"] != pytest.approx(base["experiments"][0]["held_out_mm_s"], rel=1e-3)


def test_shapes_are_validated():
    with pytest.raises(InputError):
        tf._shape_values(preset("paper"), {"disturbance.no_such": 1.0})
    with pytest.raises(InputError):
        tf._shape_values(preset("paper"), {"sensors.speed_meter_period": -1.0})
    r = synthetic_responses()[(3, 1.0)]
    with pytest.raises(InputError):
        tf.predict(r, {}, dict(SHAPES, **{"sensors.speed_meter_period": 3.3e-4}))


def test_base_params_switch_every_effect_off():
    p = tf.base_params(preset("paper_calibrated"))
    assert p.disturbance.lead_error_amplitude == p.disturbance.force_ripple == 0.0
    assert p.sensors.scale_resolution == p.sensors.scale_interpolation_error == 0.0
    assert p.disturbance.lead_error_period == LEAD_PERIOD


def _drake_measured(params, feed_mm_s, period=1e-3):
    p = with_value(params, "simulation.steady_start", 0.4)
    res = simulate(p, Scenario(feed=feed_mm_s * 1e-3, load_case=3, duration=1.0))
    t, v = differenced_speed(res.time, res.signals["scale_position"], period)
    return speed_fluctuation(v[t >= 0.4])[1], res


def test_sensor_chain_gives_proportional_plus_constant_structure():
    """Through the Drake diagram's LinearScale: a grating interpolation error gives a measured-speed ripple
    2 pi a v / p (proportional to the feed), a counting step a quantum resolution / T (not)."""
    p = with_value(tf.base_params(), "simulation.convergence_check", False)
    grating = with_value(p, "sensors.scale_interpolation_error", 100e-9)
    slow, _ = _drake_measured(grating, 0.5)
    fast, res = _drake_measured(grating, 1.0)
    expected = 2 * math.pi * 100e-9 / 20e-6 * 1e-3  # m/s at 1 mm/s, before the 1 ms averaging (sinc 0.996)
    assert fast == pytest.approx(expected, rel=0.03)
    assert slow / fast == pytest.approx(0.5, abs=0.03)
    # the table itself does not move differently: the error is in the reading only
    assert np.max(np.abs(res.signals["scale_position"] - res.signals["table_position"])) == pytest.approx(100e-9, rel=0.01)
    # counting: n + f counts per period alternate between n and n + 1, max |v - mean| = max(f, 1 - f) x quantum,
    # whatever the feed's size (a whole number of counts per period would give ~0: 10 nm at 0.5 mm/s does)
    res = 13e-9
    quant = with_value(p, "sensors.scale_resolution", res)
    quantum = res / 1e-3
    for feed in (0.5, 1.0):
        counts = feed * 1e-3 * 1e-3 / res
        frac = counts - math.floor(counts)
        value, _ = _drake_measured(quant, feed)
        assert value == pytest.approx(max(frac, 1 - frac) * quantum, rel=0.03), (feed, counts)
