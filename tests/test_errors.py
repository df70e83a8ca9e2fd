"""drakecreep.errors: the one-line user errors."""

import pickle

from drakecreep.errors import InputError


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
