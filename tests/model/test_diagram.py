import numpy as np
import pytest

from drakecreep.model.diagram import SIGNALS, build_diagram, build_plant, initial_conditions
from drakecreep.scenario import Scenario


@pytest.mark.parametrize("continuous", [False, True])
def test_starts_in_equilibrium_under_load(paper, continuous):
    drive = build_diagram(paper, Scenario(feed=1e-3, load_case=3), continuous=continuous)
    d = drive.diagram
    c = d.CreateDefaultContext()
    np.testing.assert_allclose(d.EvalTimeDerivatives(c).CopyToVector(), 0.0, atol=1e-9)
    assert d.GetOutputPort("screw.axial_force").Eval(c)[0] == pytest.approx(434.0)
    ic = initial_conditions(paper, Scenario(load_case=3))
    assert ic["force0"] == 434.0


@pytest.mark.parametrize("continuous", [False, True])
def test_a_saturating_drive_starts_in_equilibrium_with_the_command_that_holds_the_load(paper, continuous):
    """With ``motor.saturation_torque`` the controller starts from the larger command whose applied torque holds
    the load (``command0``), the current loop from that torque (``torque0``); beyond it the load is refused."""
    import math

    from drakecreep.errors import InputError
    from drakecreep.params import with_value

    ratio = paper.screw.lead / (2 * math.pi)
    held = 434.0 * ratio  # N m
    weak = with_value(paper, "motor.saturation_torque", 1.5 * held)
    drive = build_diagram(weak, Scenario(feed=1e-3, load_case=3), continuous=continuous)
    c = drive.diagram.CreateDefaultContext()
    np.testing.assert_allclose(drive.diagram.EvalTimeDerivatives(c).CopyToVector(), 0.0, atol=1e-9)
    ic = initial_conditions(weak, Scenario(load_case=3))
    assert ic["torque0"] == pytest.approx(held)
    assert ic["command0"] == pytest.approx(434.0 / math.sqrt(1.0 - 1.0 / 1.5 ** 2))
    with pytest.raises(InputError) as err:
        initial_conditions(with_value(paper, "motor.saturation_torque", 0.9 * held), Scenario(load_case=3))
    assert err.value.field == "motor.saturation_torque"


@pytest.mark.parametrize("case, fx", [(0, 0.0), (3, 434.0)])
def test_a_constant_force_adds_to_every_load_case_the_unloaded_one_too(paper, case, fx):
    """``loads.constant_force`` (a drive's offset, an incline) reaches the diagram through ``load_case``: the
    screw carries it at rest, beside the case's own fx, and the nut's load friction sees the sum."""
    from drakecreep.params import with_value

    pushed = with_value(paper, "loads.constant_force", -25.0)
    assert pushed.load_case(case).fx == pytest.approx(fx - 25.0)
    assert paper.load_case(case).fx == fx and pushed.loads.cases == paper.loads.cases  # the cases stay as written
    drive = build_diagram(pushed, Scenario(feed=1e-3, load_case=case))
    c = drive.diagram.CreateDefaultContext()
    np.testing.assert_allclose(drive.diagram.EvalTimeDerivatives(c).CopyToVector(), 0.0, atol=1e-9)
    assert drive.diagram.GetOutputPort("screw.axial_force").Eval(c)[0] == pytest.approx(fx - 25.0)


def test_named_ports_and_signals(paper):
    drive = build_diagram(paper, Scenario())
    names = {drive.diagram.get_output_port(i).get_name() for i in range(drive.diagram.num_output_ports())}
    for _, (system, port, _), _ in SIGNALS:
        assert f"{system}.{port}" in names
    # the ball nut's drag torque on the screw (the default) and the adder that puts it on the motor's load
    assert set(drive.systems) == {"reference", "controller", "motor", "screw", "table", "encoder", "scale",
                                  "nut_friction", "motor_load_sum"}
    assert drive.signal_names[-2] == "friction_state_0"  # LuGre has one bristle state
    assert drive.signal_names[-1] == "nut_friction_force"  # the nut's drag on the screw


def test_whole_diagram_converts_to_autodiff_and_symbolic(paper):
    drive = build_diagram(paper, Scenario(), continuous=True, ideal_sensors=True)
    ad = drive.diagram.ToAutoDiffXd()
    sym = drive.diagram.ToSymbolic()
    assert ad.num_output_ports() == sym.num_output_ports() == drive.diagram.num_output_ports()


def test_plant_has_the_torque_input(paper):
    plant = build_plant(paper, 3)
    assert plant.get_input_port(0).get_name() == "torque_command"
    assert plant.CreateDefaultContext().num_continuous_states() == 6
