"""Plot helpers of report/plots.py: labels with units."""

from drakecreep.params import preset
from drakecreep.report.plots import axis_label, column_label


def test_axis_labels_carry_the_parameters_si_unit():
    p = preset("paper")
    assert axis_label(p, "nut.axial_stiffness") == "nut.axial_stiffness (N/m)"
    assert axis_label(p, "loads.cases[2].fx") == "loads.cases[2].fx (N)"
    assert axis_label(p, "friction.static_ratio") == "friction.static_ratio"  # dimensionless
    assert axis_label(p, "feed") == "feed (m/s)"


def test_metric_columns_become_labels_with_units():
    assert column_label("fluctuation_rate_percent") == "fluctuation rate (%)"
    assert column_label("max_fluctuation_mm_s") == "max fluctuation (mm/s)"
    assert column_label("stick_fraction") == "stick fraction"


def test_feed_title_names_the_multibody_model():
    from types import SimpleNamespace

    from drakecreep.report.plots import feed_title
    from drakecreep.scenario import Scenario

    run = SimpleNamespace(params=preset("paper"), scenario=Scenario(feed=2e-4, load_case=3, duration=2.0),
                          metrics=None, ok=True, stats={"model": "two_mass"})
    assert "multibody" not in feed_title(run)
    run.stats = {"model": "multibody", "n_segments": 2, "rigid_joints": True}
    assert "multibody model (N = 2, rigid fixed joints)" in feed_title(run)
    run.stats = {"model": "multibody", "n_segments": 6, "rigid_joints": False}
    assert "multibody model (N = 6, Tables 1-2 fixed joints)" in feed_title(run)
