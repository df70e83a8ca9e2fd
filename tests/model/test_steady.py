"""model.steady: the force that holds a steady feed, and whether the drive has it."""

import math
import subprocess
import sys

import pytest

from drakecreep.model.controller import force_limit
from drakecreep.model.nut_table import friction_levels
from drakecreep.model.steady import nut_on_table, sliding_overload, steady_sliding
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario


def test_the_steady_force_is_load_friction_and_motor_drag():
    """At 1 mm/s under load case 3: the screw carries Fx + F(v), the motor adds its viscous drag, and the command is
    that torque through the lead; the paper rig holds it."""
    p = nut_on_table(preset("paper"))
    sc = Scenario(feed=1e-3, load_case=3)
    (law, fc, fs), friction, spring, torque, force = steady_sliding(p, sc)
    assert (fc, fs) == friction_levels(p, p.load_case(3))
    assert friction == pytest.approx(float(law.steady_state_force(1e-3, fc, fs)))
    assert spring == pytest.approx(p.load_case(3).fx + friction)
    ratio = p.screw.lead / (2 * math.pi)
    assert torque == pytest.approx(spring * ratio + p.motor.viscous_damping * 1e-3 / ratio)
    assert force == pytest.approx(torque / ratio) and abs(force) < force_limit(p)
    assert sliding_overload(preset("paper"), sc) is None


def test_a_drive_too_weak_for_its_load_is_overloaded_and_gms_is_never_asked():
    weak = with_value(preset("paper"), "motor.peak_torque", 1e-3)
    force, limit = sliding_overload(weak, Scenario(feed=1e-3, load_case=0))
    assert limit == pytest.approx(2 * math.pi * 1e-3 / 5e-3) and force > limit
    # the nut's friction is lumped on the table: the same total level whichever side the params put it on
    on_table = with_value(weak, "friction.nut_friction_on", "table")
    assert sliding_overload(on_table, Scenario(feed=1e-3, load_case=0)) == pytest.approx((force, limit))
    assert nut_on_table(on_table) is on_table
    assert sliding_overload(with_value(weak, "friction.law", "gms"), Scenario(feed=1e-3, load_case=0)) is None


def test_the_model_layer_check_does_not_import_python_control():
    """simulate asks it before every run: the servo layer's python-control import costs 1.3 s."""
    code = ("import sys; from drakecreep.model.steady import sliding_overload; "
            "print('control' in sys.modules, 'drakecreep.servo' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "False"]
