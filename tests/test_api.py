"""The front door: every documented name resolves, and a user's first lines work."""

import pytest

import drakecreep as dc


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
