import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, VectorLogSink

from drakecreep.model.diagram import build_plant
from drakecreep.params import with_value
from drakecreep.model.screw import (ScrewDrive, axial_damping, axial_stiffness, chain_force, chain_stretch,
                                   screw_inertia, shaft_axial_stiffness)


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


def _lossless(p):
    """``p`` without friction and damping."""
    for path, value in [("table.seal_force", 0.0), ("table.guide_friction_coefficient", 0.0),
                        ("nut.preload_torque", 0.0), ("nut.load_friction_coefficient", 0.0),
                        ("friction.viscous", 0.0), ("friction.law", "coulomb"), ("screw.bearing_damping", 0.0),
                        ("nut.axial_damping", 0.0), ("motor.viscous_damping", 0.0)]:
        p = with_value(p, path, value)
    return p


def _mode(p):
    """The two-mass mode [rad/s] ``sqrt(k (1/m1 + 1/m2))``, the chain's stiffness at table position 0."""
    r = p.screw.lead / (2 * math.pi)
    m1 = (p.motor.rotor_inertia + p.motor.coupling_inertia + screw_inertia(p.screw)) / r**2
    m2 = p.table.mass + p.nut.mass
    return math.sqrt(axial_stiffness(p.screw, p.nut, 0.0) * (1 / m1 + 1 / m2))


def _free_vibration_peak(params, table_offset, accuracy):
    """Peak frequency [Hz] of the table speed over 0.5 s of the plant without torque, started at rest with the
    table displaced by ``table_offset`` [m] (the frequency, not the amplitude, is checked: ``accuracy``)."""
    plant = build_plant(params)
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
    x0[-2] = table_offset
    ctx.SetContinuousState(x0)
    sim = Simulator(d, ctx)
    sim.get_mutable_integrator().set_target_accuracy(accuracy)
    sim.AdvanceTo(0.5)
    v = log.FindLog(ctx).data()[1]
    spectrum = np.abs(np.fft.rfft(v * np.hanning(len(v)), n=8 * len(v)))
    return np.fft.rfftfreq(8 * len(v), dt)[np.argmax(spectrum)]


def test_two_mass_natural_frequency_without_friction(paper):
    """Friction and damping off: the free vibration is at sqrt(k (1/m1 + 1/m2)) / 2 pi."""
    p = paper
    p = _lossless(p)
    f_sim = _free_vibration_peak(p, 1e-6, 1e-7)  # table displaced 1 um: stretches the screw
    assert f_sim == pytest.approx(_mode(p) / (2 * math.pi), rel=5e-3)


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


# --------------------------------------------------------------------------- issue 16: the nut's lost motion

@pytest.mark.parametrize("scalar", ["float", "autodiff", "expression"])
def test_backlash_is_a_dead_zone_of_the_chain_for_every_scalar_type(paper, scalar):
    """No force (and no damping) within +-b/2 of the unstretched chain; beyond, the spring on the stretch less b/2."""
    from pydrake.symbolic import Variable

    b = 10e-6
    screw = ScrewDrive(with_value(paper, "nut.backlash", b).screw, with_value(paper, "nut.backlash", b).nut)
    if scalar == "autodiff":
        screw = screw.ToAutoDiffXd()
    elif scalar == "expression":
        screw = screw.ToSymbolic()
    c = screw.CreateDefaultContext()
    r = paper.screw.lead / (2 * math.pi)
    x, v = 1.5e-3, 2e-2
    k, d = axial_stiffness(paper.screw, paper.nut, x), axial_damping(paper.screw, paper.nut, x)
    for stretch, expected in [(3e-6, 0.0), (-4.9e-6, 0.0), (8e-6, k * 3e-6 + d * 1e-3), (-12e-6, -k * 7e-6 + d * 1e-3)]:
        theta = (x + stretch) / r
        omega = (v + 1e-3) / r
        if scalar == "expression":  # the force as an Expression of the motor angle, evaluated there
            th = Variable("theta")
            screw.get_input_port(0).FixValue(c, np.array([th, omega], dtype=object))
            screw.get_input_port(1).FixValue(c, np.array([x, v], dtype=object))
            force = screw.GetOutputPort("axial_force").Eval(c)[0].Evaluate({th: theta})
        else:
            screw.get_input_port(0).FixValue(c, [theta, omega])
            screw.get_input_port(1).FixValue(c, [x, v])
            out = screw.GetOutputPort("axial_force").Eval(c)[0]
            force = out.value() if scalar == "autodiff" else out
        assert force == pytest.approx(expected, rel=1e-9, abs=1e-9)


def test_chain_stretch_is_the_inverse_of_the_chain_force():
    k, c, b = 4.0e7, 500.0, 12e-6
    for force in (-250.0, -1e-3, 0.0, 1e-3, 80.0):
        s = chain_stretch(force, k, b)
        assert chain_force(s, 0.0, k, c, b) == pytest.approx(force, rel=1e-9, abs=1e-12)
    assert chain_stretch(0.0, k, b) == 0.0  # at rest without a load: the middle of the gap
    assert chain_stretch(100.0, k, 0.0) == 100.0 / k


def test_free_vibration_across_the_gap_has_the_period_of_a_piecewise_linear_oscillator(paper):
    """Friction, damping and torque off: the relative motion of motor side and table bounces across the gap.
    Engaged by ``A`` beyond the gap's edge it is half a sine on each side (``pi / w`` each) and crosses the gap
    ``b`` at the speed ``w A`` it leaves the flank with (``b / (w A)`` each way): the period ``(2 pi + 2 b / A) / w``,
    ``w`` the linear chain's mode. Without the gap the same start oscillates at ``w / 2 pi``."""
    p = with_value(_lossless(paper), "screw.youngs_modulus", 2.06e19)  # a chain stiffness fixed along the travel
    b, A, w = 4e-6, 1e-6, _mode(p)
    # the table back by A beyond the gap's edge: the chain stretched by A
    assert _free_vibration_peak(p, -A, 1e-8) == pytest.approx(w / (2 * math.pi), rel=5e-3)
    loose = with_value(p, "nut.backlash", b)
    assert _free_vibration_peak(loose, -(0.5 * b + A), 1e-8) == pytest.approx(w / (2 * math.pi + 2 * b / A), rel=5e-3)
