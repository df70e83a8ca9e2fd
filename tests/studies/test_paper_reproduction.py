import os

import pytest

from drakecreep.errors import InputError
from drakecreep.studies.paper_reproduction import (
    CALIBRATED_FIELDS, CALIBRATION_ROWS, calibrate, check_trends, paper_rows, reproduce,
)
from drakecreep.params import get_value, preset


@pytest.fixture(scope="module")
def calibrated_rows():
    rows, _ = reproduce(preset("paper_calibrated"))
    return rows


def test_paper_rows_are_tables_8_and_9():
    rows = paper_rows()
    assert [(r["load_case"], r["feed_mm_s"]) for r in rows] == [(1, 1.0), (2, 1.0), (3, 1.0), (3, 0.5), (3, 1.0), (3, 2.0)]
    assert rows[2]["experiment_mm_s"] == rows[4]["experiment_mm_s"] == 0.031


def test_predicted_rows_are_not_the_calibration_rows(calibrated_rows):
    calibrated = {r["row"] for r in calibrated_rows if r["calibrated"]}
    predicted = [r for r in calibrated_rows if not r["calibrated"]]
    assert calibrated == set(CALIBRATION_ROWS) and len(calibrated) <= 2
    assert {r["row"] for r in predicted} == {1, 2, 3, 5}
    # no predicted row is the same experiment as a calibration row (rows 3 and 5 are one experiment)
    experiments = {(r["load_case"], r["feed_mm_s"]) for r in calibrated_rows if r["calibrated"]}
    assert not experiments & {(r["load_case"], r["feed_mm_s"]) for r in predicted}


def test_predicted_rows_beat_the_papers_worst_error(calibrated_rows):
    for r in calibrated_rows:
        assert abs(r["error_vs_experiment_percent"]) < 11.7, r
    for r in calibrated_rows:
        if r["calibrated"]:
            assert abs(r["error_vs_experiment_percent"]) < 1.0, r


def test_the_papers_trends_hold_in_the_calibrated_model(calibrated_rows):
    trends = check_trends(calibrated_rows)
    assert trends["experiment_mm_s"] == dict(grows_with_load=True, grows_with_speed_mm_s=True, rate_falls_with_speed=True)
    assert trends["ours_mm_s"] == trends["experiment_mm_s"]


def test_uncalibrated_paper_preset_is_far_too_smooth():
    rows, _ = reproduce(preset("paper"))
    assert all(r["ours_mm_s"] < 0.01 * r["experiment_mm_s"] for r in rows)


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("DRAKECREEP_SLOW"),
                    reason="refits paper_calibrated (~100 s); the default suite checks the stored amplitudes against "
                           "the current model in test_predicted_rows_beat_the_papers_worst_error (calibration rows "
                           "within 1 %); set DRAKECREEP_SLOW=1")
def test_calibration_is_deterministic_and_gives_the_stored_preset():
    # paper_calibrated is the paper preset (nut's drag on the screw, one-sample delay) plus the two fitted
    # amplitudes: refitting from the paper preset must give the stored values
    start = preset("paper")
    _, info = calibrate(start)
    stored = preset("paper_calibrated")
    assert info["rows"] == list(CALIBRATION_ROWS) and info["start"] == [1.0, 1.0]
    for path, _ in CALIBRATED_FIELDS:
        assert info["values"][path] == pytest.approx(get_value(stored, path), rel=1e-9)
    assert max(abs(v) for v in info["residuals_percent"]) < 1.0
    assert info["converged"] is True  # the fitted point passed the convergence check


@pytest.mark.parametrize("rows", [(3, 5), (1, 2, 3), (7, 1), ()])
def test_bad_calibration_rows_are_input_errors(rows):
    with pytest.raises(InputError):
        calibrate(rows=rows)
