"""The ``drakecreep`` kind's HTML report (its end-to-end use: tests/cli/test_diagnose_drakecreep.py)."""

import pytest

from drakecreep.report.drive_report import edge_value


def test_fields_are_shown_in_the_units_feed_drive_engineers_read():
    assert edge_value(2.0e-6, "m") == (pytest.approx(2.0), "um")  # a lead error's amplitude
    assert edge_value(5.0e-3, "m") == (pytest.approx(5.0), "mm")  # a lead
    assert edge_value(-4.0e-4, "m") == (pytest.approx(-400.0), "um")  # by size, whatever the sign
    assert edge_value(7.5e-4, "m/s") == (pytest.approx(0.75), "mm/s")  # a Stribeck velocity
    assert edge_value(2.0e8, "N/m") == (pytest.approx(200.0), "N/um")
    assert edge_value(4.0, "N") == (4.0, "N") and edge_value(0.3, "rad") == (0.3, "rad")
