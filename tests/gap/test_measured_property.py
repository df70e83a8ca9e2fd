"""Property-based: the measured-file loader answers any CSV + metadata with data or an InputError, nothing else."""

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drakecreep.errors import InputError
from drakecreep.gap.measured import MeasuredData, load_emps, load_measured

SETTINGS = settings(max_examples=60, deadline=3000, suppress_health_check=[HealthCheck.function_scoped_fixture], database=None)

cells = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr), st.integers().map(str),
                  st.text(alphabet=",\"\n#x0123456789.e-", max_size=6), st.just(""))
headers = st.lists(st.sampled_from(["t", "x_ref", "x_motor", "u", "f_ext", "run", "t [ms]", "u [A]", "q", "x_table"]),
                   min_size=0, max_size=6)
metas = st.one_of(
    st.sampled_from(["u_units: N\nu_gain: 1\n", "u_units: A\n", "u_units: V\nu_gain: 2\n", "", "u_units: [1]\n",
                     "u_units: N\nu_gain: -1\n", "u_units: N\nparams: nothere.yaml\n", "u_units: N\nu_units: N\n",
                     "u_units: N\nsensors: {a: 1}\n", "u_units: N\ncontroller: {kind: pid}\n"]),
    st.text(max_size=60),
)


@st.composite
def csvs(draw):
    header = draw(headers)
    n = draw(st.integers(min_value=0, max_value=8))
    if draw(st.booleans()):  # mostly well-formed numbers on a uniform time grid
        rows = [",".join(str(i * 1e-3) if h.startswith("t") else draw(cells) for h in header) for i in range(n)]
    else:
        rows = [",".join(draw(cells) for _ in header) for _ in range(n)]
    return "\n".join([",".join(header)] + rows) + "\n"


@SETTINGS
@given(csv_text=csvs(), meta=metas)
def test_csv_and_metadata(csv_text, meta, tmp_path):
    (tmp_path / "run.csv").write_text(csv_text)
    (tmp_path / "run.yaml").write_text(meta)
    try:
        data = load_measured(tmp_path / "run.csv")
    except InputError as err:
        assert len(str(err)) < 1500
        return
    assert isinstance(data, MeasuredData)


@SETTINGS
@given(data=st.binary(max_size=400), prefix=st.sampled_from([b"", b"MATLAB 5.0 MAT-file" + b" " * 97 + b"\x00\x01IM"]))
def test_arbitrary_mat_bytes(data, prefix, tmp_path):
    (tmp_path / "x.mat").write_bytes(prefix + data)
    try:
        load_emps(tmp_path / "x.mat")
    except InputError:
        pass
