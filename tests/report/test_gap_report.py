"""Units at the edge of the Drake diagnosis report (drakecreep.report.gap_report)."""

import pytest

from drakecreep.report.gap_report import _edge


def test_parameters_are_shown_in_the_units_feed_drive_engineers_read():
    assert _edge("lead_error_cos", 2.5e-6) == (pytest.approx(2.5), "um")
    assert _edge("lead", 5e-3) == (pytest.approx(5.0), "mm")
    assert _edge("stiffness", 2e8) == (pytest.approx(200.0), "N/um")
    assert _edge("coulomb", 20.0) == (20.0, "N")
