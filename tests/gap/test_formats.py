"""drakecreep.gap.formats: measured files read into SI arrays."""

import numpy as np
import pandas as pd
import pytest

from drakecreep.errors import InputError
from drakecreep.gap.formats import read_signals


def _frame(n=50):
    t = np.arange(n) * 1e-3
    return pd.DataFrame({"t": t, "x_ref": 1e-3 * t, "x_motor": 1e-3 * t, "u": np.sin(t)})


@pytest.mark.parametrize("column, values, got", [
    ("t", lambda t: pd.to_datetime(t, unit="s"), "dates and times"),  # read as nanoseconds since 1970
    ("t", lambda t: pd.to_timedelta(t, unit="s"), "time spans"),
    ("u", lambda u: u > 0, "true/false"),  # read as 0 and 1
])
def test_columns_that_are_not_real_numbers_are_refused_by_name(tmp_path, column, values, got):
    pytest.importorskip("pyarrow")
    frame = _frame()
    frame[column] = values(frame[column])
    path = tmp_path / "run.parquet"
    frame.to_parquet(path)
    with pytest.raises(InputError, match=f"run.parquet: column {column}: got '{got} "):
        read_signals(path, "N")


def test_real_columns_of_any_width_are_read(tmp_path):
    pytest.importorskip("pyarrow")
    frame = _frame()
    frame["u"] = frame["u"].astype("float32")
    frame.to_parquet(tmp_path / "run.parquet")
    signals = read_signals(tmp_path / "run.parquet", "N")
    assert signals["u"].dtype == float and np.allclose(signals["u"], np.sin(frame["t"]), atol=1e-6)


def _mat(tmp_path, **variables):
    import scipy.io

    path = tmp_path / "run.mat"
    scipy.io.savemat(path, variables)
    return path


@pytest.mark.parametrize("change, field, got", [
    (lambda f: {"u": f["u"].to_numpy() + 1j}, "u", "complex numbers (complex128)"),
    (lambda f: {"x_ref": f["x_ref"].to_numpy()[:-1]}, "x_ref", "length 49"),  # one sample short
    (lambda f: {"x_ref": np.tile(f["x_ref"].to_numpy(), (2, 1))}, "x_ref", "shape (2, 50)"),
    (lambda f: {"t": np.array([[1, 2], [3, 4]], dtype=object)}, "t", "a MATLAB cell or text array"),
    (lambda f: {"u": 2.5}, "u", "1 value"),  # a scalar where a signal is named
    (lambda f: {"x_motor": np.zeros((0, 1))}, "x_motor", "0 values"),
])
def test_a_mat_variable_of_a_signal_that_is_no_real_vector_of_the_runs_length_is_named(tmp_path, change, field, got):
    """Such a variable was dropped without a word, and the file then said 'header: got 't,x_ref,x_motor'; allowed:
    the columns u as well' of a u that is there (complex), or of an x_ref one sample short or a matrix."""
    frame = _frame()
    variables = {k: frame[k].to_numpy() for k in frame} | change(frame)
    with pytest.raises(InputError) as err:
        read_signals(_mat(tmp_path, **variables), "N")
    assert err.value.field == f"{tmp_path / 'run.mat'}: {field}" and err.value.value == got


def test_a_mat_file_keeps_its_scalars_and_other_variables_out_of_the_columns(tmp_path):
    frame = _frame()
    variables = {k: frame[k].to_numpy() for k in frame} | {"gain": 3.0, "notes": "text", "m": np.ones((3, 3))}
    assert sorted(read_signals(_mat(tmp_path, **variables), "N")) == ["t", "u", "x_motor", "x_ref"]


def test_a_mat_file_whose_run_is_a_struct_says_so(tmp_path):
    frame = _frame()
    run = {k: frame[k].to_numpy() for k in frame}
    with pytest.raises(InputError, match=r"run.mat: got 'no numeric vector variable \(run: a MATLAB struct array\)'; "
                                         r"allowed: the run's signals as numeric vectors"):
        read_signals(_mat(tmp_path, run=run), "N")  # it said 'no data; allowed: a header line and data rows'


def test_a_parquet_column_named_twice_is_named(tmp_path):
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    frame = _frame()
    arrays = [pa.array(frame[k]) for k in ("t", "x_ref", "x_motor", "u")] + [pa.array(frame["x_motor"])]
    table = pa.Table.from_arrays(arrays, names=["t", "x_ref", "x_motor", "u", "x_motor"])
    pq.write_table(table, tmp_path / "r.parquet")
    with pytest.raises(InputError, match="r.parquet: header: got 'x_motor'; allowed: each column once"):
        read_signals(tmp_path / "r.parquet", "N")  # it said 'not a readable Parquet file (ArrowInvalid)'


@pytest.mark.parametrize("suffix", [".parquet", ".h5"])
def test_a_table_indexed_by_time_reads_its_index_as_the_column(tmp_path, suffix):
    """df.set_index('t').to_parquet(...) keeps t as the index: it was reported missing ('the columns t as well')."""
    pytest.importorskip("pyarrow" if suffix == ".parquet" else "tables")
    frame = _frame().set_index("t")
    path = tmp_path / f"run{suffix}"
    frame.to_parquet(path) if suffix == ".parquet" else frame.to_hdf(path, key="/run")
    signals = read_signals(path, "N")
    assert np.array_equal(signals["t"], frame.index.to_numpy()) and list(signals) == ["t", "x_ref", "x_motor", "u"]


def test_an_hdf5_key_that_holds_a_series_is_named(tmp_path):
    """'internal error: IndexError: tuple index out of range', exit 1."""
    pytest.importorskip("tables")
    _frame()["u"].to_hdf(tmp_path / "run.h5", key="/u")
    with pytest.raises(InputError, match=r"run.h5: file.key: got None; allowed: the key of a table .* holds a Series"):
        read_signals(tmp_path / "run.h5", "N")


@pytest.mark.parametrize("option, value, suffix", [("key", "/run", ".csv"), ("separator", ";", ".mat"),
                                                   ("decimal", ",", ".h5")])
def test_an_option_of_another_format_is_refused(tmp_path, option, value, suffix):
    """The metadata's file.key beside a CSV (or a separator beside a .mat) was ignored without a word, though every
    other unknown or misplaced key of the metadata is refused."""
    path = tmp_path / f"run{suffix}"
    path.write_text("t,x_ref,x_motor,u\n")
    with pytest.raises(InputError, match=rf"run{suffix}: file.{option}: got '{value}'; allowed: only for an? "):
        read_signals(path, "N", **{option: value})


@pytest.mark.parametrize("mu", ["\u00b5", "\u03bc"])  # the micro sign, and the Greek mu many programs write
def test_the_micro_prefix_is_read_as_either_mu(tmp_path, mu):
    """'t[μs]' (Greek mu) was refused with 'allowed: one of s, ms, us, µs', a list that looks to hold it (found by the
    fuzzing pass)."""
    path = tmp_path / "run.csv"
    _frame().rename(columns={"t": f"t[{mu}s]", "x_motor": f"x_motor ({mu}m)"}).to_csv(path, index=False)
    signals = read_signals(path, "N", units={"x_ref": f"{mu}m"})
    frame = _frame()
    assert np.allclose(signals["t"], 1e-6 * frame["t"]) and np.allclose(signals["x_motor"], 1e-6 * frame["x_motor"])
    assert np.allclose(signals["x_ref"], 1e-6 * frame["x_ref"])
    _frame().rename(columns={"t": f"t[{mu}ss]"}).to_csv(path, index=False)
    with pytest.raises(InputError, match=f"column t unit: got '{mu}ss'; allowed: one of s, ms, us, µs"):
        read_signals(path, "N")


def test_a_unit_of_file_units_that_contradicts_the_header_is_refused(tmp_path):
    """'t[ms]' with 'file: {units: {t: s}}' was read in seconds without a word (a P-P run was then refused for its
    gains, a drakecreep one not at all; found by the fuzzing pass). The same unit twice is let be."""
    path = tmp_path / "run.csv"
    _frame().rename(columns={"t": "t[ms]", "x_motor": "x_motor[µm]"}).to_csv(path, index=False)
    with pytest.raises(InputError) as err:
        read_signals(path, "N", units={"t": "s"})
    assert str(err.value) == (f"{path}: file.units.t: got 's'; allowed: the unit the file's header gives the column, "
                              "ms (file.units is for names without a unit: leave t out)")
    with pytest.raises(InputError, match="file.units.x_motor: got 'mm'"):
        read_signals(path, "N", columns={"t": "t[ms]", "x_ref": "x_ref", "x_motor": "x_motor[µm]", "u": "u"},
                     units={"x_motor": "mm"})
    signals = read_signals(path, "N", units={"t": "ms", "x_motor": "μm", "x_ref": "mm"})
    assert np.allclose(signals["t"], 1e-3 * _frame()["t"]) and np.allclose(signals["x_ref"], 1e-3 * _frame()["x_ref"])


@pytest.mark.parametrize("header, field", [("t[]", "t"), ("x_motor [ ]", "x_motor"), ("u()", "u")])
def test_brackets_without_a_unit_are_refused(tmp_path, header, field):
    """'t[]' was read as SI, a unit nobody wrote (a spreadsheet's empty unit cell; found by the fuzzing pass)."""
    path = tmp_path / "run.csv"
    _frame().rename(columns={field: header}).to_csv(path, index=False)
    with pytest.raises(InputError) as err:
        read_signals(path, "N")
    assert err.value.field == f"{path}: column {field} unit" and err.value.value == ""
    assert err.value.allowed.endswith(f"in the brackets (or no brackets: {field} in {'u_units' if field == 'u' else 'SI'})")


def test_a_unit_that_is_no_string_is_refused_by_its_column():
    """read_signals(units={'t': 5}) from a script ended in AttributeError ('int' has no 'strip')."""
    from drakecreep.gap.formats import unit_factor

    with pytest.raises(InputError, match=r"^f.csv: column t unit: got 5; allowed: one of s, ms"):
        unit_factor("t", 5, "N", "f.csv")


def test_one_file_column_mapped_to_two_signals_is_refused(tmp_path):
    """file.columns naming x_ref's column for x_motor too (found by fuzzing): the motor followed its reference
    exactly and the diagnosis ran, exit 0, at twice the force error."""
    frame = _frame()
    frame.to_csv(tmp_path / "run.csv", index=False)
    mapping = {"t": "t", "x_ref": "x_ref", "x_motor": "x_ref", "u": "u"}
    units = {"t": "s", "x_ref": "m", "x_motor": "m", "u": "N"}
    with pytest.raises(InputError) as err:
        read_signals(tmp_path / "run.csv", "N", columns=mapping, units=units)
    assert err.value.field.endswith("file.columns.x_motor") and err.value.value == "x_ref"
    assert "it is x_ref's" in err.value.allowed
    signals = read_signals(tmp_path / "run.csv", "N", columns=dict(mapping, x_motor="x_motor"), units=units)
    assert np.array_equal(signals["x_motor"], frame["x_motor"].to_numpy())
