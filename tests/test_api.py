"""The front door: every documented name resolves, and a user's first lines work."""

import pytest

import drakecreep as dc
from drakecreep.errors import InputError


@pytest.mark.parametrize("name", sorted(set(dc.__all__) - {"__version__"}))
def test_every_public_name_resolves(name):
    assert getattr(dc, name) is not None


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no_such_thing"):
        dc.no_such_thing  # noqa: B018


def test_first_lines_of_a_user(paper):
    drive = dc.lumped(dc.preset("paper"), 3)
    assert 1e6 < drive.stiffness < 1e9 and drive.mass > 40
    assert dc.Scenario(feed=1e-4, load_case=3, duration=0.5).feed == 1e-4


def test_diagnose_is_the_drake_model_diagnosis():
    """One name per thing: the front door's ``diagnose`` is what ``drakecreep diagnose`` runs."""
    from drakecreep.gap.drake_diagnosis import diagnose_drake

    assert dc.diagnose is diagnose_drake


def _front_door_calls():
    p, sc = dc.preset("paper"), dc.Scenario(feed=1e-3, load_case=3)
    return [
        (lambda: dc.build_diagram("paper", sc), "params: got 'paper'; allowed: a DriveParams"),
        (lambda: dc.build_diagram(p, 1e-3), "scenario: got 0.001; allowed: a Scenario"),
        (lambda: dc.lumped({"motor": {}}, 3), "params: got {'motor': {}}; allowed: a DriveParams"),
        (lambda: dc.analyze_loops(p, None), "scenario: got None; allowed: a Scenario"),
        (lambda: dc.run_sweep("paper", [{"feed": 1e-3}]), "base: got 'paper'; allowed: a DriveParams"),
        (lambda: dc.run_sweep(p, "feed"), "points: got 'feed'; allowed: a list of {path: value} mappings"),
        (lambda: dc.run_sweep(p, [{"feed": 1e-3}, 1]), "points[1]: got 1; allowed: a {path: value} mapping"),
        (lambda: dc.save_params("paper", "x.yaml"), "params: got 'paper'"),
        (lambda: dc.save_params(p, None), "path: got None; allowed: a file path"),
        (lambda: dc.load_measured(None), "csv_path: got None; allowed: a file path"),
        (lambda: dc.with_value("paper", "motor.rotor_inertia", 1e-4), "params: got 'paper'; allowed: a DriveParams"),
    ]


@pytest.mark.parametrize("case", range(11))
def test_a_front_door_call_with_the_wrong_kind_of_argument_names_it(case):
    """A preset's name, a feed or None where the objects go ended in AttributeError or TypeError deep inside
    ('str' object has no attribute 'controller'); found by the fuzzing pass."""
    call, said = _front_door_calls()[case]
    with pytest.raises(InputError) as err:
        call()
    assert str(err.value).startswith(said)
