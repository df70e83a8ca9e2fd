"""Property-based: the sweep-spec loader answers any file with a SweepSpec or an InputError, nothing else."""

import importlib

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drakecreep.errors import InputError
from drakecreep.sim.sweep import SweepSpec, load_spec

# load_spec imports pydrake (drakecreep.sim.simulation) on the first spec it accepts; imported here so that the
# one-off import, several seconds on a loaded CI machine, is not timed against the deadline of one example (it was:
# a deadline failure under a fuzzing helper's load, session 63); the deadline still catches a loader that hangs
importlib.import_module("drakecreep.sim.simulation")

SETTINGS = settings(max_examples=40, deadline=5000, suppress_health_check=[HealthCheck.function_scoped_fixture], database=None)

scalars = st.one_of(st.none(), st.booleans(), st.integers(min_value=-10, max_value=10), st.integers(),
                    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
                    st.sampled_from(["grid", "random", "log", "linear", "paper", "feed"]))
values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=3) | st.dictionaries(
    st.sampled_from(["start", "stop", "num", "scale", "low", "high", "x", "y", "color", "mode", "n", "seed", "preset",
                     "file", "set", "q"]), inner, max_size=4), max_leaves=8)
paths = st.one_of(st.sampled_from(["table.mass", "feed", "load_case", "duration", "loads.cases[0].fx",
                                   "loads.cases[9].fx", "loads.cases[x].fx", "nut.axial_stiffness", "zz.q"]),
                  st.text(max_size=15), st.integers())


@st.composite
def specs(draw):
    doc = {}
    if draw(st.booleans()):
        doc["axes"] = draw(st.dictionaries(paths, st.one_of(
            st.lists(st.floats(min_value=1.0, max_value=100.0), min_size=1, max_size=3), values), max_size=2))
    for key in draw(st.lists(st.sampled_from(["base", "scenario", "sample", "metrics", "plot", "other"]),
                             max_size=3, unique=True)):
        doc[key] = draw(values)
    return doc


def _check(path):
    try:
        spec = load_spec(path, max_cases=50)
    except InputError as err:
        assert len(str(err)) < 1500
        return
    assert isinstance(spec, SweepSpec) and 1 <= len(spec.points) <= 50


@SETTINGS
@given(doc=specs())
def test_structured_specs(doc, tmp_path):
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(doc, allow_unicode=True))
    _check(path)


@SETTINGS
@given(text=st.text(max_size=200))
def test_arbitrary_text(text, tmp_path):
    path = tmp_path / "spec.yaml"
    path.write_text(text, encoding="utf-8")
    _check(path)
