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
