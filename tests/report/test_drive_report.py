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


def test_an_interval_the_runs_do_not_bound_reads_so():
    """A fitted field whose interval spans more than six decades above its lower bound, or is infinite, is
    reported as not bounded (in the summary and in the report's table alike); a signed field is bounded when
    finite."""
    import math

    from drakecreep.gap.drive_fit import NOT_BOUNDED, FittedParameter, _interval

    seal = FittedParameter("table.seal_force", 4.0, 1e-302, 1e306, 4.0, "N")
    assert not seal.bounded() and _interval(seal.lower, seal.upper) == NOT_BOUNDED
    assert FittedParameter("table.seal_force", 4.0, 3.9, 4.2, 4.0, "N").bounded()
    assert not FittedParameter("table.seal_force", 4.0, 0.0, math.inf, 4.0, "N").bounded()
    assert FittedParameter("loads.constant_force", -2.0, -3.0, -1.0, 0.0, "N").bounded()
    assert not FittedParameter("loads.constant_force", -2.0, -math.inf, -1.0, 0.0, "N").bounded()
