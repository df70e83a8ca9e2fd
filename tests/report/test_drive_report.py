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


def test_the_gain_chart_marks_a_lead_error_decided_on_the_transmission():
    """A lead error claimed on the screw's transmission can sit under its force bar (the shipped example: +7.3
    against 13.3 points); its bar is hatched and the legend says why, so the green bar under its red one reads."""
    import matplotlib.pyplot as plt

    from drakecreep.gap.drive_fit import EffectResult
    from drakecreep.report.drive_report import _gain_figure

    lead = EffectResult("lead_error", {}, 1.0, {}, 7.3, 4.0, 13.3, {"shrink": 0.99, "transmission": {"shrink": 0.999}},
                        True, improves=True)
    ripple = EffectResult("force_ripple", {}, 0.03, {}, -0.02, 0.2, 0.6, {"shrink": 0.03}, False)
    fig = _gain_figure([lead, ripple])
    ax = fig.axes[0]
    gains = ax.containers[0]
    assert [b.get_hatch() for b in gains] == ["//", None]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("transmission" in t for t in labels) and len(labels) == 3
    assert [h.get_hatch() for h in ax.get_legend().legend_handles] == [None, None, "//"]
    plt.close(fig)
    fig = _gain_figure([ripple])
    assert not any("transmission" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    plt.close(fig)


def test_the_gain_chart_tells_a_candidate_under_the_training_gain_floor_apart():
    """A candidate that improves the held-out replay beyond its bars but explains under MIN_TRAIN_SHARE of the
    training error (3cw) is neither green (claimed) nor grey (no held-out improvement): olive, with its legend."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgba

    from drakecreep.gap.drive_fit import EffectResult
    from drakecreep.report.drive_report import _gain_figure

    delay = EffectResult("control_delay", {}, 0.05, {}, 0.68, 0.2, 0.54, {"shrink": 0.04}, False, improves=True)
    stribeck = EffectResult("stribeck", {}, 0.6, {}, 3.0, 0.4, 1.0, {"shrink": 0.5}, True, improves=True)
    fig = _gain_figure([stribeck, delay])
    ax = fig.axes[0]
    assert [b.get_facecolor() for b in ax.containers[0]] == [to_rgba("tab:green"), to_rgba("tab:olive")]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[2] == "improves the replay, but removes under 20 % of the training error: not claimed"
    plt.close(fig)
