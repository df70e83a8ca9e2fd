"""drakecreep.scenario: what to run, validated on construction."""

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.scenario import Scenario


@pytest.mark.parametrize("field", ["feed", "duration"])
def test_an_integer_of_hundreds_of_digits_is_refused_by_name(field):
    # float() overflowed: a sweep spec's 'scenario: {duration: 999...9}' was 'internal error: OverflowError', exit 1
    with pytest.raises(InputError, match=f"^{field}: got 9"):
        Scenario(**{field: int("9" * 400)})


def test_numpy_scalars_are_numbers_and_stored_as_python_numbers():
    s = Scenario(feed=np.float32(1e-3), load_case=np.int64(2), duration=np.float32(2.0))
    assert (type(s.feed), type(s.load_case), type(s.duration)) == (float, int, float)
    assert s.load_case == 2 and s.duration == 2.0 and s.feed == pytest.approx(1e-3)


@pytest.mark.parametrize("kwargs", [dict(feed=True), dict(feed="1"), dict(load_case=True), dict(load_case=1.0),
                                    dict(duration=float("inf"))])
def test_bools_text_and_non_finite_values_are_refused(kwargs):
    with pytest.raises(InputError, match=f"^{next(iter(kwargs))}: "):
        Scenario(**kwargs)
