import math

import numpy as np
import pytest

from drakecreep.params import LoadCase, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
from drakecreep.model.axis import friction_map
from drakecreep.model.nut_table import (NutTable, friction_levels, friction_split, moving_mass, position_level,
                                       table_friction_levels)


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


def test_the_friction_map_scales_the_tables_friction_where_it_is(paper):
    """``friction.position_map_*``: the table's friction (every term of its law) is ``1 + m(x)`` times the law's,
    ``m`` the replay axis's own :func:`~drakecreep.model.axis.friction_map`; its rates are the law's (the bristle
    state is normalized by the level); float, AutoDiffXd and Expression alike."""
    from pydrake.symbolic import Expression, Variable

    mapped = paper
    for path, value in (("friction.position_map_0", 0.2), ("friction.position_map_2", -0.3),
                        ("friction.position_map_start", -0.05), ("friction.position_map_end", 0.15)):
        mapped = with_value(mapped, path, value)
    load = paper.load_case(0)
    state, push = [0.031, 2e-4, 0.4], [300.0]
    plain, table = NutTable(paper, load), NutTable(mapped, load)
    derivs = []
    for system in (plain, table):
        c = system.CreateDefaultContext()
        system.get_input_port(0).FixValue(c, push)
        c.SetContinuousState(state)
        derivs.append((system.EvalTimeDerivatives(c).CopyToVector(), system.GetOutputPort("friction_force").Eval(c)[0]))
    P = {"friction_map_0": 0.2, "friction_map_1": 0.0, "friction_map_2": -0.3, "friction_map_3": 0.0,
         "friction_map_start": -0.05, "friction_map_end": 0.15}
    level = 1.0 + friction_map(P, 0.031)
    assert position_level(mapped.friction, 0.031) == pytest.approx(level) and abs(level - 1.0) > 0.05
    assert derivs[1][1] == pytest.approx(level * derivs[0][1])
    mass = moving_mass(paper)
    assert derivs[1][0][1] == pytest.approx((push[0] - load.fx - level * derivs[0][1]) / mass)
    assert derivs[1][0][2] == pytest.approx(derivs[0][0][2])  # the bristles' rate: the law's
    assert position_level(paper.friction, 0.031) == 1.0  # no map: exactly the law
    # the AutoDiffXd and Expression copies keep the map
    for converted in (table.ToAutoDiffXd(), table.ToSymbolic()):
        c = converted.CreateDefaultContext()
        converted.get_input_port(0).FixValue(c, push)
        if isinstance(converted.CreateDefaultContext().get_time(), Expression):
            c.SetContinuousState([Expression(v) for v in state])
            value = converted.GetOutputPort("friction_force").Eval(c)[0].Evaluate()
        else:
            c.SetContinuousState(state)
            value = converted.GetOutputPort("friction_force").Eval(c)[0].value()
        assert value == pytest.approx(derivs[1][1])
    symbolic = table.ToSymbolic()
    c = symbolic.CreateDefaultContext()
    symbolic.get_input_port(0).FixValue(c, push)
    x = Variable("x")
    c.SetContinuousState([Expression(x), Expression(state[1]), Expression(state[2])])
    force = symbolic.GetOutputPort("friction_force").Eval(c)[0]
    assert x in force.GetVariables() and force.Evaluate({x: 0.031}) == pytest.approx(derivs[1][1])


def test_a_friction_map_is_checked(paper):
    """A map whose travel ends before it starts, or whose level could reach 0, is refused naming the field."""
    from drakecreep.errors import InputError

    with pytest.raises(InputError, match=r"friction.position_map_end: got -1.0; allowed: a position > "):
        with_value(paper, "friction.position_map_end", -1.0)
    half = with_value(paper, "friction.position_map_0", 0.6)
    with pytest.raises(InputError, match=r"friction.position_map_0..3: got 'magnitudes summing to 1.1'"):
        with_value(half, "friction.position_map_3", -0.5)
    with pytest.raises(InputError, match=r"friction.position_map_1: got 0.95; allowed: a finite number in \[-0.9"):
        with_value(paper, "friction.position_map_1", 0.95)


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


# --------------------------------------------------------------------------- issue 16: a structural mode on the table

def test_a_structural_mode_on_the_table_has_the_modes_of_the_two_mass_chain(paper):
    """Friction and damping off, the motor side held: the table ``(1 - s) M`` on the chain ``k`` and the mode's mass
    ``s M`` on its spring ``s M (2 pi f)^2`` vibrate at the eigenfrequencies of that two-degree-of-freedom chain
    (the mechanism's AutoDiff linearization); the mode's deflection is 0 in steady sliding."""
    from drakecreep.model.screw import axial_stiffness
    from drakecreep.servo import linearize as lin

    p = paper
    for path, value in [("table.seal_force", 0.0), ("table.guide_friction_coefficient", 0.0),
                        ("nut.preload_torque", 0.0), ("nut.load_friction_coefficient", 0.0),
                        ("friction.viscous", 0.0), ("friction.law", "coulomb"), ("screw.bearing_damping", 0.0),
                        ("nut.axial_damping", 0.0), ("table.mode_mass_share", 0.3), ("table.mode_frequency", 40.0),
                        ("table.mode_damping_ratio", 0.0)]:
        p = with_value(p, path, value)
    sc = Scenario(feed=1e-3)
    op = lin.operating_point(p, sc)
    mech = lin.linearize_mechanism(p, sc, op)
    assert mech.state_labels == ["table.x", "table.v", "table.mode_deflection", "table.mode_rate"]
    M = moving_mass(p)
    m_mode, k_mode = 0.3 * M, 0.3 * M * (2 * math.pi * 40.0) ** 2
    k = axial_stiffness(p.screw, p.nut, op.table[0])
    stiffness = np.array([[k + k_mode, -k_mode], [-k_mode, k_mode]])
    expected = np.sort(np.sqrt(np.linalg.eigvals(np.linalg.solve(np.diag([M - m_mode, m_mode]), stiffness))))
    got = np.sort(np.abs(np.linalg.eigvals(mech.A)))[::2]
    assert got == pytest.approx(expected, rel=1e-4)
    assert NutTable(with_value(p, "table.mode_mass_share", 0.0), LoadCase()).num_continuous_states() == 2


@pytest.mark.parametrize("scalar", ["float", "autodiff"])
def test_a_friction_drift_scales_the_tables_friction_with_the_time_of_the_run(paper, scalar):
    """``friction.time_drift`` r: the table's friction is ``max(1 + r t, 0)`` times the law's at time t (the friction
    port reads the time: a cached value would keep the start's)."""
    drifting = NutTable(with_value(paper, "friction.time_drift", -0.25), LoadCase())
    plain = NutTable(paper, LoadCase())
    if scalar == "autodiff":
        drifting, plain = drifting.ToAutoDiffXd(), plain.ToAutoDiffXd()
    value = (lambda f: f.value()) if scalar == "autodiff" else (lambda f: f)
    forces = []
    for system in (drifting, plain):
        c = system.CreateDefaultContext()
        state = c.get_continuous_state_vector().CopyToVector()
        state[1] = 0.01  # sliding at 10 mm/s
        c.SetContinuousState(state)
        out = []
        for t in (0.0, 2.0, 6.0):
            c.SetTime(t)
            out.append(value(system.GetOutputPort("friction_force").Eval(c)[0]))
        forces.append(out)
    (d0, d2, d6), (p0, p2, p6) = forces
    assert p0 > 0 and (d0, d2, d6) == pytest.approx((p0, 0.5 * p2, 0.0), rel=1e-12, abs=1e-12)
