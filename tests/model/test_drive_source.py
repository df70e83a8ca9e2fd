"""The constant-speed drive (paper Fig. 2): no controller, motor side at exactly the feed speed."""

import math

import numpy as np
import pytest

from drakecreep.model.diagram import build_diagram
from drakecreep.model.drive_source import DriveScenario, scenario_with_drive
from drakecreep.errors import InputError
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
from drakecreep.model.lumped import lumped
from drakecreep.paper.creep import critical_speed_of

SOFT = 1.0e6  # N/m screw-nut stiffness: a soft spring dominating the axial chain, as in Fig. 2


@pytest.fixture(scope="module")
def soft():
    # the paper's Fig. 2 mechanism: all friction on the driven mass, as eq. 11 and lumped() assume
    # (with the nut's drag on the screw, the motor turning at a fixed speed would take it out of the dynamics)
    # and the nut at the friction level this test was measured with (0.01 N m, 0.01: 26 N at load case 3);
    # the catalogue nut (157 N) moves v0 to 7.9 mm/s, above the speeds below
    p = with_value(with_value(preset("paper"), "nut.axial_stiffness", SOFT), "friction.nut_friction_on", "table")
    return with_value(with_value(p, "nut.preload_torque", 0.01), "nut.load_friction_coefficient", 0.01)


def test_diagram_has_no_controller_and_the_motor_turns_at_the_feed(soft):
    scen = DriveScenario(feed=0.5e-3, load_case=3, duration=1.2, drive="constant_speed")
    drive = build_diagram(soft, scen)
    assert "controller" not in drive.systems and "torque_command" not in drive.signal_names
    result = simulate(soft, scen)
    v = result.signals["motor_velocity"]
    assert np.all(v == pytest.approx(0.5e-3, rel=1e-12))
    x = result.signals["motor_position"] - result.signals["motor_position"][0]
    assert np.allclose(x, 0.5e-3 * result.time, rtol=0, atol=1e-12)
    # the cascade stays the default for a plain scenario
    assert "controller" in build_diagram(soft, Scenario(feed=0.5e-3, load_case=3, duration=1.2)).systems


def test_soft_spring_creeps_below_and_not_above_a_critical_speed(soft):
    def creeps(feed):
        m = simulate(soft, DriveScenario(feed=feed, load_case=3, duration=2.0, drive="constant_speed")).metrics
        return m.creep, m.stick_slip_cycles

    slow, fast = creeps(0.2e-3), creeps(2.0e-3)
    assert slow[0] and slow[1] >= 10  # sustained stick-slip, not a single stop
    assert not fast[0]
    # the paper's v0 lies between the two speeds for this drive
    assert 0.2e-3 < critical_speed_of(lumped(soft, 3)) < 2.0e-3


def test_bad_drive_is_an_input_error(soft):
    with pytest.raises(InputError, match="drive"):
        DriveScenario(feed=1e-3, drive="belt")
    with pytest.raises(InputError, match="drive"):
        build_diagram(soft, Scenario(feed=1e-3), drive="belt")
    assert type(scenario_with_drive(None, feed=1e-3)) is Scenario
    assert scenario_with_drive("constant_speed", feed=1e-3).drive == "constant_speed"
    assert math.isfinite(critical_speed_of(lumped(soft, 3)))
