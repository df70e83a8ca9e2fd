"""The lumped drive (eq. 11's one mass on one spring) carries the friction the model puts on the table."""

import math

import pytest

from drakecreep.model.lumped import axial_mode_frequency, lumped
from drakecreep.model.nut_table import friction_split
from drakecreep.paper.creep import critical_speed_of
from drakecreep.params import preset, with_value


@pytest.mark.parametrize("load_case", [0, 3])
def test_nut_on_the_screw_leaves_only_the_guides_on_the_lumped_mass(load_case):
    p = preset("paper")
    assert p.friction.nut_friction_on == "screw"
    guides, nut = friction_split(p, p.load_case(load_case))
    assert nut > 5 * guides  # the catalogue nut: the share that would dominate if it were lumped
    d = lumped(p, load_case)
    assert d.coulomb == pytest.approx(guides, rel=1e-12)
    assert d.breakaway == pytest.approx(p.friction.static_ratio * guides, rel=1e-12)


def test_nut_on_the_table_lumps_everything_as_the_paper_does():
    p = with_value(preset("paper"), "friction.nut_friction_on", "table")
    guides, nut = friction_split(p, p.load_case(3))
    assert lumped(p, 3).coulomb == pytest.approx(guides + nut, rel=1e-12)


def test_critical_speed_follows_the_friction_on_the_mass():
    # eq. 11: v0 grows with the friction drop Fs - Fd, so lumping the nut's drag on the table moves it up
    p = preset("paper")
    on_table = with_value(p, "friction.nut_friction_on", "table")
    v_screw, v_table = critical_speed_of(lumped(p, 3)), critical_speed_of(lumped(on_table, 3))
    assert math.isfinite(v_screw) and math.isfinite(v_table)
    assert v_table > 5 * v_screw


def test_axial_mode_frequency_is_the_two_mass_mode():
    # 73.5 Hz for the paper preset (docs/multibody.md), independent of where the friction sits
    assert axial_mode_frequency(preset("paper")) == pytest.approx(73.5, abs=0.1)


def test_the_lumped_mass_carries_the_friction_maps_level_where_the_table_is():
    """``friction.position_map_*`` scales the table's friction where it is: the lumped drive at ``x`` takes that
    level (:func:`drakecreep.model.nut_table.position_level`), and without a map it is the law's."""
    from drakecreep.model.nut_table import position_level

    p = preset("paper")
    mapped = with_value(with_value(p, "friction.position_map_1", 0.4), "friction.position_map_end", 0.2)
    for x in (0.0, 0.07, 0.15):
        level = position_level(mapped.friction, x)
        assert lumped(mapped, 3, x).coulomb == pytest.approx(level * lumped(p, 3, x).coulomb, rel=1e-12)
        assert lumped(mapped, 3, x).breakaway == pytest.approx(level * lumped(p, 3, x).breakaway, rel=1e-12)
    assert position_level(mapped.friction, 0.15) > 1.2 > 0.8 > position_level(mapped.friction, 0.0)
