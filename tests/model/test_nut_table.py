import math

import numpy as np
import pytest

from drakecreep.params import LoadCase, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
from drakecreep.model.nut_table import NutTable, friction_levels, friction_split, moving_mass, table_friction_levels


def test_friction_levels_by_hand(paper):
    load = LoadCase(fx=434.0, fy=407.0, fz=1001.0)
    fc, fs = friction_levels(paper, load)
    m = paper.table.mass + paper.nut.mass
    expected = (paper.table.seal_force + paper.table.guide_friction_coefficient * (abs(m * 9.81 + 1001) + 407)
                + 2 * math.pi * paper.nut.preload_torque / paper.screw.lead + paper.nut.load_friction_coefficient * 434)
    assert fc == pytest.approx(expected)
    assert fs == pytest.approx(paper.friction.static_ratio * expected)
    assert moving_mass(paper) == m


def test_a_lifting_load_unloads_the_guides(paper):
    """Fz > 0 presses the table down, Fz < 0 lifts it: the guides carry |m g + Fz| + |Fy|."""
    m, g, mu = moving_mass(paper), paper.loads.gravity, paper.table.guide_friction_coefficient
    guides = [friction_split(paper, LoadCase(fz=fz))[0] for fz in (0.0, -0.5 * m * g, -m * g, 200.0)]
    seals = paper.table.seal_force
    assert guides[0] == pytest.approx(seals + mu * m * g)
    assert guides[1] == pytest.approx(seals + mu * 0.5 * m * g)  # half the weight lifted off
    assert guides[2] == pytest.approx(seals)  # weightless: only the seals drag
    assert guides[3] == pytest.approx(seals + mu * (m * g + 200.0))
    # lifting harder than the weight presses the table against the upper raceways
    assert friction_split(paper, LoadCase(fz=-2 * m * g))[0] == pytest.approx(seals + mu * m * g)
    assert friction_split(paper, LoadCase(fy=-50.0))[0] == pytest.approx(seals + mu * (m * g + 50.0))


def test_more_load_more_friction(paper):
    levels = [friction_levels(paper, paper.load_case(i))[0] for i in (0, 1, 2, 3)]
    assert levels == sorted(levels)


def test_derivatives_by_hand(paper):
    load = paper.load_case(3)
    table = NutTable(paper, load)
    c = table.CreateDefaultContext()
    table.get_input_port(0).FixValue(c, [500.0])
    f = paper.friction
    fc, fs = table_friction_levels(paper, load)  # the guides' share: the nut's drag is on the screw
    x, v, z = 1e-3, 2e-4, 1e-7  # z: bristle deflection (m); the state is sigma0 z / Fc
    c.SetContinuousState([x, v, f.bristle_stiffness * z / fc])
    g = fc + (fs - fc) * math.exp(-((v / f.stribeck_velocity) ** 2))
    zdot = v - f.bristle_stiffness * abs(v) * z / g
    friction = f.bristle_stiffness * z + f.bristle_damping * zdot + f.viscous * v
    xdot = table.EvalTimeDerivatives(c).CopyToVector()
    np.testing.assert_allclose(xdot, [v, (500.0 - load.fx - friction) / moving_mass(paper),
                                      f.bristle_stiffness * zdot / fc])
    assert table.GetOutputPort("friction_force").Eval(c)[0] == pytest.approx(friction)
    converted = table.ToAutoDiffXd()
    assert converted.load == load and converted.fc == table.fc


@pytest.mark.parametrize("law", ["coulomb", "stribeck", "lugre"])
def test_friction_dissipates_energy_over_a_run(short_paper, law):
    p = with_value(short_paper, "friction.law", law)
    r = simulate(p, Scenario(feed=1e-4, load_case=3, duration=0.6))
    power = r.signals["friction_force"] * r.signals["table_speed"]  # power taken out of the table
    energy = np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(r.time))
    assert energy > 0
    # and it is most of the work the friction level would do over the travel
    fc, _ = table_friction_levels(p, p.load_case(3))
    travel = r.signals["table_position"][-1] - r.signals["table_position"][0]
    assert energy > 0.5 * fc * travel
