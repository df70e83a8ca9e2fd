import numpy as np
import pytest

from drakecreep.gap.benchmark import (
    HIDDEN_EFFECTS,
    diagnose_dataset,
    draw_hidden,
    generate_dataset,
    out_and_back,
    score_rows,
)


def test_generation_is_seeded_quantized_and_split():
    a, b = generate_dataset(11), generate_dataset(11)
    assert a.hidden == b.hidden == draw_hidden(11)
    np.testing.assert_array_equal(a.train[0].x_motor, b.train[0].x_motor)
    np.testing.assert_array_equal(a.test[2].u, b.test[2].u)
    q = a.truth["encoder"]
    x = a.train[0].x_motor
    assert np.max(np.abs(x / q - np.round(x / q))) < 1e-6
    assert len(a.train) == len(a.test) == 3
    speeds = a.truth["speeds_m_s"]
    assert len(set(np.round(speeds, 6))) == 6


def test_hidden_draws_none_one_or_two():
    draws = [draw_hidden(s) for s in range(200)]
    counts = np.bincount([len(d) for d in draws], minlength=3)
    assert counts.sum() == 200 and np.all(counts > 20)
    assert all(h in HIDDEN_EFFECTS for d in draws for h in d)
    assert all(len(set(d)) == len(d) for d in draws)


def test_a_hidden_cogging_is_attributed_blind():
    ds = generate_dataset(21, hidden=("cogging",))
    res = diagnose_dataset(ds, replay=False)
    assert ds.snr > 1
    assert res["claimed"][0] == "cogging"
    order = res["ranking"][0]["params"]["cogging.order_per_motor_rev"]["value"]
    assert order == ds.truth["effects"]["cogging"]["order"]


def test_out_and_back_returns_home():
    x = out_and_back(0.05, 0.01)
    assert x[0] == pytest.approx(0.01) and x[-1] == pytest.approx(0.01, abs=1e-12)
    assert np.max(np.gradient(x, 1e-3)) == pytest.approx(0.05, rel=1e-3)


def test_score_rows():
    rows = [
        {"hidden": ["cogging"], "snr": 5.0, "claimed": ["cogging"], "top3": ["cogging"], "excess_shrink": 0.9,
         "idim_rms_N": {"before": 2.0, "after": 1.0}, "recovery": {"rel_error": 0.1}},
        {"hidden": ["backlash"], "snr": 4.0, "claimed": ["stribeck"], "top3": ["stribeck", "backlash"],
         "excess_shrink": 0.1, "idim_rms_N": {"before": 2.0, "after": 1.8}, "recovery": {}},
        {"hidden": [], "snr": 0.0, "claimed": [], "top3": [], "excess_shrink": None,
         "idim_rms_N": {"before": 1.0, "after": 1.0}, "recovery": {}},
        {"hidden": [], "snr": 0.0, "claimed": ["stribeck"], "top3": ["stribeck"], "excess_shrink": None,
         "idim_rms_N": {"before": 1.0, "after": 0.9}, "recovery": {}},
    ]
    s = score_rows(rows)
    assert s["top1_snr3"]["rate"] == 0.5 and s["top3_snr3"]["rate"] == 1.0
    assert s["false_claims_null"]["rate"] == 0.5
    assert s["wrong_claims_with_effects"]["rate"] == 0.5
    assert s["median_excess_shrink_snr3"] == pytest.approx(0.5)
    assert s["parameter_recovery_median_rel_error"] == {"cogging": 0.1}
