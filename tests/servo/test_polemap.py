import numpy as np
import pytest

from drakecreep.servo import polemap
from drakecreep.errors import InputError
from drakecreep.params import with_value
from drakecreep.scenario import Scenario
from drakecreep.model.screw import axial_damping, axial_stiffness

SPEEDS = np.geomspace(0.02e-3, 3e-3, 16)


def test_static_friction_pole_crosses_where_c_plus_c1_changes_sign(paper):
    """Paper eq. 2: with the motor motion prescribed, the pole crosses the axis exactly at C + C1 = 0."""
    p = with_value(paper, "friction.law", "stribeck")
    c = polemap.friction_slope_crossings(p, 3, SPEEDS, model="mechanism")
    assert len(c["theory"]) == 1 and len(c["pole"]) == 1
    assert c["pole"][0] == pytest.approx(c["theory"][0], rel=1e-5)
    below = polemap.rightmost_pole(p, Scenario(feed=0.9 * c["theory"][0], load_case=3), "mechanism")
    above = polemap.rightmost_pole(p, Scenario(feed=1.1 * c["theory"][0], load_case=3), "mechanism")
    assert below.real > 0 > above.real


def test_whole_loop_crosses_at_a_different_speed(paper):
    """The servo-controlled motor side is no prescribed motion: the whole loop's crossing moves (shown, not hidden)."""
    p = with_value(paper, "friction.law", "stribeck")
    c = polemap.friction_slope_crossings(p, 3, SPEEDS, model="closed_loop")
    assert len(c["pole"]) == 1
    assert c["pole"][0] < 0.98 * c["theory"][0]


def test_scale_stiffness_keeps_damping(paper):
    p = polemap.scale_stiffness(paper, 2.0)
    assert axial_stiffness(p.screw, p.nut) == pytest.approx(2.0 * axial_stiffness(paper.screw, paper.nut), rel=1e-12)
    assert axial_damping(p.screw, p.nut) == pytest.approx(axial_damping(paper.screw, paper.nut), rel=1e-12)
    with pytest.raises(InputError):
        polemap.scale_stiffness(paper, 0.0)


def test_pole_map_small(paper):
    # at the nut friction level this map was measured with (0.01 N m, 0.01: 26 N at load case 3); with the
    # catalogue nut (157 N) the simulated point above the boundary still creeps at 0.1 mm/s
    paper = with_value(with_value(paper, "nut.preload_torque", 0.01), "nut.load_friction_coefficient", 0.01)
    sc = Scenario(feed=0.1e-3, load_case=3)
    # the grid's simulations on a pool of two processes (tests/report/test_loop_report.py's run in this one)
    pm = polemap.pole_map(paper, sc, k_scales=[0.5, 2.0], n_damping=3, sim_grid=(1, 2), workers=2)
    assert pm.closed_loop.shape == (3, 2) == pm.damping.shape
    # the lowest damping row (no viscous friction on the falling branch) is unstable, the highest is stable
    assert np.all(pm.closed_loop[0] > 0) and np.all(pm.closed_loop[-1] < 0)
    assert np.all(np.diff(pm.damping, axis=0) > 0)
    # paper's boundary: D^2 = 4 pi zeta at those points
    K = pm.stiffness
    y = pm.paper_boundary(K)
    D = pm.friction_drop / (pm.feed * np.sqrt(K * pm.mass))
    zeta = y / (2 * np.sqrt(K * pm.mass))
    assert np.allclose(D**2, 4 * np.pi * zeta)
    assert pm.sim_creep.shape == (2,) and pm.sim_creep[0] and not pm.sim_creep[1]


def test_pole_map_interpolates_each_column_to_the_poles_of_its_own_linearizations(paper, monkeypatch):
    """The map linearizes three points of a stiffness's column and interpolates the others (A is affine in the
    viscous coefficient): every point's rightmost poles are those of its own linearization; a column whose middle
    point does not agree with the interpolation is linearized point by point."""
    from drakecreep.model.steady import nut_on_table
    from drakecreep.servo.linearize import linearize_closed_loop, linearize_mechanism, operating_point

    sc = Scenario(feed=0.1e-3, load_case=3)
    pm = polemap.pole_map(paper, sc, k_scales=[0.5, 2.0], n_damping=5)
    p0 = nut_on_table(paper)
    for j, s in enumerate([0.5, 2.0]):
        ps = polemap.scale_stiffness(p0, s)
        op = operating_point(ps, sc)
        rest = op.damping + op.friction_slope - ps.friction.viscous
        for i in range(5):
            p = with_value(ps, "friction.viscous", max(0.0, pm.damping[i, j] - rest))
            for got, linearize in ((pm.closed_loop, linearize_closed_loop), (pm.mechanism, linearize_mechanism)):
                lin = linearize(p, sc)
                own = lin.poles().real.max()
                # an eigenvalue's round-off is about eps * |A| (backward-stable solver): 2.6e-9 for the loop's
                # |A| of 1.2e7, far above a real part of -0.05 (a slow pole near the axis) times 1e-7
                rounding = 1e-13 * np.abs(lin.A).max()
                assert got[i, j] == pytest.approx(own, rel=1e-7, abs=max(rounding, 1e-9 * max(1.0, abs(own)))), (i, j)
    calls = []
    real = polemap.linearize_closed_loop
    monkeypatch.setattr(polemap, "linearize_closed_loop", lambda *a: calls.append(1) or real(*a))
    interpolated = polemap.pole_map(paper, sc, k_scales=[1.0], n_damping=5)
    assert len(calls) == 3  # the ends and the middle of the one column
    calls.clear()
    monkeypatch.setattr(polemap, "AFFINE_TOLERANCE", -1.0)  # no column agrees: each point its own linearization
    again = polemap.pole_map(paper, sc, k_scales=[1.0], n_damping=5)
    assert len(calls) == 3 + 5
    for key in ("closed_loop", "mechanism"):
        assert np.allclose(getattr(again, key), getattr(interpolated, key), rtol=1e-7, atol=1e-9)


def test_parameter_locus(paper):
    loc = polemap.parameter_locus(paper, Scenario(feed=1e-3, load_case=3), "mass", [20.0, 80.0])
    assert len(loc["poles"]) == 2
    with pytest.raises(InputError):
        polemap.parameter_locus(paper, Scenario(), "colour", [1.0])


def test_the_damping_axis_is_linear_near_zero_and_logarithmic_beyond():
    """The paper rig at 0.1 mm/s spans -3.5e5 to 5.2e6 N s/m: a linear axis gave the unstable band 7 % of its height.
    The width is half the negative end (a tenth of the top when the whole range is positive, at least 1 N s/m);
    rows are even in asinh(y / width), so about a quarter of them lie below zero here."""
    assert polemap.damping_width((-3.5e5, 5.2e6)) == pytest.approx(1.75e5)
    assert polemap.damping_width((100.0, 1e4)) == pytest.approx(1e3)
    assert polemap.damping_width((0.0, 0.0)) == 1.0
    w = polemap.damping_width((-3.5e5, 5.2e6))
    rows = w * np.sinh(np.linspace(np.arcsinh(-3.5e5 / w), np.arcsinh(5.2e6 / w), 20))
    assert 0.2 < np.mean(rows < 0) < 0.35
