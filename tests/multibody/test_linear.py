"""The multibody mechanics linearized at steady sliding, against the two-mass plant."""

import control
import numpy as np
import pytest

from drakecreep.multibody.diagram import MultibodyOptions
from drakecreep.multibody.linear import linearize_multibody_plant, residualize
from drakecreep.params import with_value
from drakecreep.scenario import Scenario
from drakecreep.servo.linearize import linearize_plant


def _response(A, B, C, D, out, w):
    n = A.shape[0]
    return np.array([C[out] @ np.linalg.solve(1j * x * np.eye(n) - A, B[:, 0]) + D[out, 0] for x in w])


@pytest.fixture(scope="module")
def nut_on_table(paper):
    """The two-mass linearization lumps the nut's friction on the table: the same friction in both models."""
    return with_value(paper, "friction.nut_friction_on", "table")


@pytest.fixture(scope="module")
def rigid_lin(nut_on_table):
    return linearize_multibody_plant(nut_on_table, Scenario(feed=1e-3, load_case=3),
                                     MultibodyOptions(n_segments=3, rigid_joints=True))


def test_motor_speed_response_matches_the_two_mass_plant_below_the_axial_mode(nut_on_table, rigid_lin):
    """Torque -> motor speed, 1-40 Hz (velocity-loop crossover ~31 Hz), rigid joints, the nut's friction on the
    table in both: within 2 % of the two-mass plant."""
    w = 2 * np.pi * np.logspace(0, np.log10(40), 20)
    two = linearize_plant(nut_on_table, Scenario(feed=1e-3, load_case=3))
    ref = np.asarray(control.frequency_response(two["motor_speed", "torque_command"], w).complex).reshape(-1)
    lin = rigid_lin
    mb = _response(lin["A"], lin["B"], lin["C"], lin["D"], lin["outputs"].index("motor_speed"), w)
    assert np.max(np.abs(mb - ref) / np.abs(ref)) < 0.02


def test_operating_point_is_steady(rigid_lin, paper):
    """The motor torque balances Fx and the friction at the feed; what acceleration is left is small."""
    ratio = paper.screw.lead / (2 * np.pi)
    assert rigid_lin["torque"] > paper.load_case(3).fx * ratio
    assert rigid_lin["acceleration_residual"] < 5.0  # rad/s^2 or m/s^2, against ~1e4 of a 1 N m torque step


def test_residualize_keeps_the_low_frequency_response(rigid_lin):
    lin = rigid_lin
    A, B, C, D = residualize(lin["A"], lin["B"], lin["C"], lin["D"], 1e4)
    assert A.shape[0] < lin["A"].shape[0]
    w = 2 * np.pi * np.logspace(0, 2, 10)
    full = _response(lin["A"], lin["B"], lin["C"], lin["D"], 1, w)
    red = _response(A, B, C, D, 1, w)
    assert np.max(np.abs(red - full) / np.abs(full)) < 1e-3
