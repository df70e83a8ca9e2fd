"""drakecreep.errors: the one-line user errors."""

import pickle

import pytest

from drakecreep.errors import InputError, name_list


def test_input_error_survives_pickling_whole():
    # a worker process's InputError is pickled to the parent: it must arrive with its field, value and allowed
    # (it was rebuilt from its message alone, a TypeError that broke the pool: 'BrokenProcessPool', exit 1)
    err = pickle.loads(pickle.dumps(InputError("simulation.log_period", 1e-9, ">= 2.5e-06 s")))
    assert isinstance(err, InputError)
    assert (err.field, err.value, err.allowed) == ("simulation.log_period", 1e-9, ">= 2.5e-06 s")
    assert str(err) == "simulation.log_period: got 1e-09; allowed: >= 2.5e-06 s"


def test_input_error_with_an_unpicklable_value_pickles_its_repr():
    err = pickle.loads(pickle.dumps(InputError("callback", lambda: None, "a number")))
    assert err.field == "callback" and err.allowed == "a number"
    assert str(err).startswith("callback: got '<function")


@pytest.mark.parametrize("value, allowed", [
    ("stribeck", "a list of names (one name goes in a list: ['stribeck'])"),  # its letters were the names
    (("stribeck", "lead_error", "stribeck"), "each name once (stribeck given twice)"),
    (3, "a list of names")])
def test_name_list_refuses_one_string_and_a_name_twice(value, allowed):
    with pytest.raises(InputError) as err:
        name_list(value, "effects")
    assert err.value.field == "effects" and err.value.allowed == allowed
    assert name_list(["a", "b"], "effects") == ("a", "b") and name_list((), "effects") == ()
