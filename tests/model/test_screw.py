import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, VectorLogSink

from drakecreep.model.diagram import build_plant
from drakecreep.params import with_value
from drakecreep.model.screw import ScrewDrive, axial_damping, axial_stiffness, screw_inertia, shaft_axial_stiffness


def test_stiffness_chain_by_hand(paper):
    s, n = paper.screw, paper.nut
    ea = s.youngs_modulus * math.pi / 4 * s.root_diameter**2
    ks = ea / s.nut_start_distance
    k = 1 / (1 / s.bearing_stiffness + 1 / ks + 1 / n.axial_stiffness)
    assert axial_stiffness(s, n, 0.0) == pytest.approx(k)
    c = k**2 * (s.bearing_damping / s.bearing_stiffness**2 + n.axial_damping / n.axial_stiffness**2)
    assert axial_damping(s, n, 0.0) == pytest.approx(c)
    assert screw_inertia(s) == pytest.approx(math.pi / 32 * s.density * s.length * s.nominal_diameter**4)


def test_shaft_softens_as_the_nut_moves_away(paper):
    s = paper.screw
    x = np.array([0.0, 0.1, 0.3])
    k = shaft_axial_stiffness(s, x)
    assert np.all(np.diff(k) < 0)
    ff = with_value(paper, "screw.mounting", "fixed-fixed").screw
    a = np.linspace(0.05, 0.55, 51) - ff.nut_start_distance
    kff = shaft_axial_stiffness(ff, a)
    assert np.argmin(kff) == 25  # softest with the nut mid-span
    assert np.all(kff >= k[0] * 0 + ff.youngs_modulus * math.pi / 4 * ff.root_diameter**2 * 4 / ff.length - 1e-6)


def test_force_and_torque_by_hand(paper):
    screw = ScrewDrive(paper.screw, paper.nut)
    c = screw.CreateDefaultContext()
    theta, omega, x, v = 2.0, 30.0, 1.5e-3, 2e-2
    screw.get_input_port(0).FixValue(c, [theta, omega])
    screw.get_input_port(1).FixValue(c, [x, v])
    r = paper.screw.lead / (2 * math.pi)
    f = axial_stiffness(paper.screw, paper.nut, x) * (theta * r - x) + axial_damping(paper.screw, paper.nut, x) * (omega * r - v)
    assert screw.GetOutputPort("axial_force").Eval(c)[0] == pytest.approx(f)
    assert screw.GetOutputPort("load_torque").Eval(c)[0] == pytest.approx(f * r)
    assert screw.ToAutoDiffXd().screw == paper.screw


def test_two_mass_natural_frequency_without_friction(paper):
    """Friction and damping off: the free vibration is at sqrt(k (1/m1 + 1/m2)) / 2 pi."""
    p = paper
    for path, value in [("table.seal_force", 0.0), ("table.guide_friction_coefficient", 0.0),
                        ("nut.preload_torque", 0.0), ("nut.load_friction_coefficient", 0.0),
                        ("friction.viscous", 0.0), ("friction.law", "coulomb"), ("screw.bearing_damping", 0.0),
                        ("nut.axial_damping", 0.0), ("motor.viscous_damping", 0.0)]:
        p = with_value(p, path, value)
    plant = build_plant(p)
    builder = DiagramBuilder()
    builder.AddSystem(plant)
    zero = builder.AddSystem(ConstantVectorSource([0.0]))
    builder.Connect(zero.get_output_port(), plant.get_input_port(0))
    dt = 2e-5
    log = builder.AddSystem(VectorLogSink(2, dt))
    builder.Connect(plant.GetOutputPort("table_state"), log.get_input_port())
    d = builder.Build()
    ctx = d.CreateDefaultContext()
    x0 = ctx.get_continuous_state_vector().CopyToVector()
    x0[-2] = 1e-6  # table displaced 1 um: stretches the screw
    ctx.SetContinuousState(x0)
    sim = Simulator(d, ctx)
    sim.get_mutable_integrator().set_target_accuracy(1e-7)  # the frequency, not the amplitude, is checked
    sim.AdvanceTo(0.5)
    v = log.FindLog(ctx).data()[1]
    spectrum = np.abs(np.fft.rfft(v * np.hanning(len(v)), n=8 * len(v)))
    f_sim = np.fft.rfftfreq(8 * len(v), dt)[np.argmax(spectrum)]
    r = p.screw.lead / (2 * math.pi)
    m1 = (p.motor.rotor_inertia + p.motor.coupling_inertia + screw_inertia(p.screw)) / r**2
    m2 = p.table.mass + p.nut.mass
    f_expected = math.sqrt(axial_stiffness(p.screw, p.nut, 0.0) * (1 / m1 + 1 / m2)) / (2 * math.pi)
    assert f_sim == pytest.approx(f_expected, rel=5e-3)


# --------------------------------------------------------------------------- issue 15: defects 6 and 7

def _chain(p, x=0.0):
    return axial_stiffness(p.screw, p.nut, x), axial_damping(p.screw, p.nut, x)


def test_loss_factor_damping_equals_the_identified_one_at_the_test_frequency(paper):
    """A loss factor eta = c / sqrt(k m) from a half-power test at omega = sqrt(k/m) gives back c at that omega,
    and c x (omega_test / omega) at another frequency."""
    from drakecreep.model.screw import nut_element

    n = paper.nut
    f_test = math.sqrt(n.axial_stiffness / n.mass) / (2 * math.pi)  # ~1975 Hz (paper Table 3: Hertz 1917 Hz)
    at_test = with_value(with_value(paper, "screw.chain_damping", "loss_factor"), "screw.damping_frequency", f_test)
    assert nut_element(at_test.screw, at_test.nut)[1] == pytest.approx(n.axial_damping)
    at_mode = with_value(paper, "screw.chain_damping", "loss_factor")
    assert nut_element(at_mode.screw, at_mode.nut)[1] == pytest.approx(
        n.axial_damping * f_test / at_mode.screw.damping_frequency)
    # the stiffness does not change
    assert _chain(at_mode)[0] == pytest.approx(_chain(paper)[0])


def test_loss_factor_raises_the_structural_damping_ratio_of_the_paper_rig_tenfold(paper):
    from drakecreep.model.lumped import lumped

    def zeta(p):
        d = lumped(p, 3)
        return d.damping / (2 * math.sqrt(d.stiffness * d.mass))

    viscous = zeta(paper)
    hysteretic = zeta(with_value(paper, "screw.chain_damping", "loss_factor"))
    assert 0.001 < viscous < 0.003
    assert 0.015 < hysteretic < 0.03


def test_default_damping_frequency_is_the_paper_rigs_axial_mode(paper):
    from drakecreep.model.lumped import axial_mode_frequency

    assert paper.screw.damping_frequency == pytest.approx(axial_mode_frequency(paper), rel=0.005)


def test_seat_joints_in_series_by_hand(paper):
    from drakecreep.paper.joints import axial_path_joints

    j = axial_path_joints()
    (kbs, cbs), (kns, cns) = j["bearing_seat"], j["nut_seat"]
    # Table 2 inner ring-shaft fit (2.2e9 N/m) is the softest joint of the bearing seat
    assert 1.0e9 < kbs < 2.2e9 and kns > 1e10
    p = paper
    for path, value in (("screw.seat_joint_stiffness", kbs), ("screw.seat_joint_damping", cbs),
                        ("nut.seat_joint_stiffness", kns), ("nut.seat_joint_damping", cns)):
        p = with_value(p, path, value)
    s, n = p.screw, p.nut
    ks = shaft_axial_stiffness(s, 0.0)
    k = 1 / (1 / s.bearing_stiffness + 1 / kbs + 1 / ks + 1 / n.axial_stiffness + 1 / kns)
    c = k**2 * (s.bearing_damping / s.bearing_stiffness**2 + cbs / kbs**2
                + n.axial_damping / n.axial_stiffness**2 + cns / kns**2)
    assert _chain(p) == pytest.approx((k, c))
    assert _chain(p)[0] < _chain(paper)[0]
    # the plain-Python equations (batch and baseline paths) use the same elements
    from drakecreep.scenario import Scenario
    from drakecreep.sim.baseline import BaselineModel

    assert BaselineModel(p, Scenario(feed=1e-3)).stiffness(0.0) == pytest.approx((k, c))
