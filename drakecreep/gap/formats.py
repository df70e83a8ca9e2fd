"""Readers of measured-run files: CSV, Parquet, HDF5 and MATLAB ``.mat`` into one table of SI columns.

Every reader returns a :class:`pandas.DataFrame` whose columns are the measured-run names of
:data:`drakecreep.gap.measured.COLUMNS` (``t``, ``x_ref``, ``x_motor``, ``x_table``, ``u``, ``f_ext``,
``run``) with values in SI (``u`` in the ``u_units`` of the metadata). A column name may carry its unit
in brackets or parentheses, ``x_motor[mm]``, ``t (ms)``, ``u[mV]``; the values are converted:

============================ =========================================================
columns                      units accepted (factor to SI)
============================ =========================================================
``t``                        ``s``, ``ms``, ``us`` (``µs``), ``min``
``x_ref x_motor x_table``    ``m``, ``mm``, ``um`` (``µm``), ``nm``
``f_ext``                    ``N``, ``kN``
``u``                        ``u_units`` of the metadata, or its milli (``mV``, ``mA``) or ``kN``
============================ =========================================================

A file whose columns (or variables) have other names is read through a mapping in the metadata YAML,
``columns: {t[s]: time, x_motor[mm]: qm, u[V]: vir}``: the key is the measured-run name with its unit,
the value the name in the file (a CSV/Parquet column, an HDF5 dataset path, a MATLAB variable).
The full format is described in ``docs/measured_format.md``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from drakecreep.errors import InputError

__all__ = ["UNITS", "COLUMN_QUANTITY", "SUFFIXES", "parse_name", "read_table"]

#: Physical quantity -> unit -> factor to SI.
UNITS = {
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "μs": 1e-6, "min": 60.0},
    "length": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9},
    "force": {"N": 1.0, "kN": 1e3},
}
#: Measured-run column -> quantity (``u`` depends on the metadata, ``run`` is a label).
COLUMN_QUANTITY = {"t": "time", "x_ref": "length", "x_motor": "length", "x_table": "length", "f_ext": "force"}
_U_UNITS = {"N": {"N": 1.0, "kN": 1e3}, "V": {"V": 1.0, "mV": 1e-3}, "A": {"A": 1.0, "mA": 1e-3}}
_COLUMNS = ("t", "x_ref", "x_motor", "x_table", "u", "f_ext", "run")
_REQUIRED = ("t", "x_ref", "x_motor", "u")
#: File suffix -> format.
SUFFIXES = {".csv": "csv", ".txt": "csv", ".gz": "csv", ".parquet": "parquet", ".pq": "parquet",
            ".h5": "hdf5", ".hdf5": "hdf5", ".hdf": "hdf5", ".mat": "mat"}

_NAME = re.compile(r"^\s*([A-Za-z_]\w*)\s*(?:[\[(]\s*([^\])]*?)\s*[\])])?\s*$")


def parse_name(text, where, u_units):
    """Split ``"x_motor[mm]"`` into the column name and its factor to SI.

    Parameters
    ----------
    text : str
        A column header or a key of the ``columns`` mapping.
    where : str
        Prefix of the error field (the file).
    u_units : str
        Unit of ``u`` from the metadata (``N``, ``A`` or ``V``).

    Returns
    -------
    tuple of (str, float)
        The measured-run column name and the factor that converts its values to SI (1 for ``run``).

    Raises
    ------
    InputError
        Unknown column, or a unit not allowed for it (the error names the column, the unit and the
        allowed units).
    """
    m = _NAME.match(str(text))
    if not m:
        raise InputError(f"{where}: header", text, "a column name, optionally with [unit]")
    name, unit = m.group(1), m.group(2)
    if name not in _COLUMNS:
        raise InputError(f"{where}: header", name, "columns among " + ", ".join(_COLUMNS))
    if unit is None or unit == "":
        return name, 1.0
    if name == "run":
        raise InputError(f"{where}: column run unit", unit, "no unit (run is a label)")
    table = _U_UNITS[u_units] if name == "u" else UNITS[COLUMN_QUANTITY[name]]
    if unit not in table:
        note = f" (u_units of the metadata is {u_units})" if name == "u" else ""
        raise InputError(f"{where}: column {name} unit", unit, "one of " + ", ".join(table) + note)
    return name, table[unit]


def _format(path):
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise InputError(f"{path}: format", suffix or "(no suffix)",
                         "a suffix among " + ", ".join(SUFFIXES))
    return SUFFIXES[suffix]


def _read_csv(path):
    try:
        return pd.read_csv(path, comment="#", skipinitialspace=True, skip_blank_lines=True)
    except pd.errors.EmptyDataError:
        raise InputError(str(path), "empty", "a header line and data rows") from None
    except pd.errors.ParserError as err:
        m = re.search(r"Expected (\d+) fields in line (\d+), saw (\d+)", str(err))
        if m:
            raise InputError(f"{path}: line {m.group(2)}", f"{m.group(3)} fields",
                             f"{m.group(1)} fields like the header") from None
        raise InputError(str(path), "unreadable CSV", "a comma-separated table with a header line") from None


def _read_hdf5(path, names):
    import h5py

    out = {}
    with h5py.File(path, "r") as fh:
        if names is None:
            names = [k for k, v in fh.items() if isinstance(v, h5py.Dataset)]
        for name in names:
            if name not in fh or not isinstance(fh[name], h5py.Dataset):
                have = []
                fh.visititems(lambda k, v: have.append(k) if isinstance(v, h5py.Dataset) else None)
                raise InputError(f"{path}: dataset", name, "one of " + ", ".join(have))
            data = fh[name][()]
            if data.dtype.kind in "SO":
                data = np.array([x.decode() if isinstance(x, bytes) else str(x) for x in np.ravel(data)], dtype=object)
            out[name] = np.ravel(data)
    return out


def _read_mat(path):
    import scipy.io

    try:
        mat = scipy.io.loadmat(str(path))
    except NotImplementedError:  # MATLAB v7.3 files are HDF5
        return _read_hdf5(path, None)
    except (ValueError, OSError) as err:
        raise InputError(str(path), f"unreadable .mat ({err})", "a MATLAB .mat file") from None
    return {k: v for k, v in mat.items() if not k.startswith("__")}


def _column(raw, source, n_expected, path):
    a = np.asarray(raw)
    if a.dtype.kind in "US" or a.dtype == object:
        a = a.ravel()
    elif a.ndim == 2 and 1 in a.shape:
        a = a.ravel()
    if a.ndim != 1:
        raise InputError(f"{path}: {source}", f"shape {a.shape}", "a vector (1-D, or N x 1)")
    if n_expected is not None and a.size != n_expected:
        raise InputError(f"{path}: {source}", f"length {a.size}", f"length {n_expected} like the other columns")
    return a


def read_table(path, u_units, columns=None):
    """Read a measured-run file into a table of SI columns.

    Parameters
    ----------
    path : str or pathlib.Path
        ``.csv`` (``.txt``, ``.csv.gz``; ``#`` comment lines ignored), ``.parquet``, ``.h5``/``.hdf5``
        (one dataset per column) or ``.mat``.
    u_units : str
        Unit of ``u`` from the metadata (``N``, ``A`` or ``V``).
    columns : dict, optional
        ``{measured name[unit]: name in the file}``, the ``columns`` key of the metadata YAML. Without
        it the file's own column names (HDF5 datasets at the root, MATLAB variables) must be the
        measured-run names, with an optional unit.

    Returns
    -------
    pandas.DataFrame
        Columns among ``t, x_ref, x_motor, x_table, u, f_ext`` (float, SI) and ``run`` (str), in the
        file's row order.

    Raises
    ------
    InputError
        Unknown column or unit, missing required column, a column listed twice, a non-number, a
        mapping naming something the file does not have, a row with the wrong number of fields.
    FileNotFoundError
        If the file does not exist.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(2, "No such file or directory", str(path))
    fmt = _format(path)
    if columns is not None and (not isinstance(columns, dict) or not columns
                                or not all(isinstance(v, str) for v in columns.values())):
        raise InputError("columns", columns, "a mapping {measured name[unit]: name in the file}")

    if fmt == "csv":
        source = _read_csv(path)
    elif fmt == "parquet":
        try:
            source = pd.read_parquet(path)
        except Exception as err:  # pyarrow raises several types for a bad file
            raise InputError(str(path), f"unreadable Parquet ({type(err).__name__})", "a Parquet table") from None
    elif fmt == "hdf5":
        try:
            source = _read_hdf5(path, None if columns is None else list(columns.values()))
        except OSError as err:
            raise InputError(str(path), f"unreadable HDF5 ({err})", "an HDF5 file with one dataset per column") from None
    else:
        source = _read_mat(path)
    have = list(source.columns) if isinstance(source, pd.DataFrame) else list(source)

    if columns is None:
        if fmt == "mat":
            # a .mat file holds scalars and other variables beside the columns: keep those named like one
            mapping = {k: k for k in have if _NAME.match(k) and _NAME.match(k).group(1) in _COLUMNS}
        else:
            mapping = {str(k): k for k in have}
    else:
        for key, name in columns.items():
            if name not in have:
                raise InputError(f"columns: {key}", name, "a column of the file, one of " + ", ".join(map(str, have)))
        mapping = dict(columns)

    out, seen, n = {}, {}, None
    for key, name in mapping.items():
        col, factor = parse_name(key, str(path), u_units)
        if col in seen:
            raise InputError(f"{path}: header", key, f"each column once ({col} is also {seen[col]})")
        seen[col] = key
        a = _column(source[name], name, n, path)
        n = a.size
        if col == "run":
            out[col] = pd.Series(a).astype(str).to_numpy()
            continue
        if a.dtype.kind not in "fiub":
            num = pd.to_numeric(pd.Series(a), errors="coerce")
            bad = np.flatnonzero(num.isna().to_numpy() & ~pd.isna(pd.Series(a)).to_numpy())
            if bad.size:
                raise InputError(f"{path}: column {col}", str(a[bad[0]]), "numbers") from None
            a = num.to_numpy()
        a = a.astype(float)
        nan = np.flatnonzero(np.isnan(a))
        if nan.size:
            raise InputError(f"{path}: column {col}", f"NaN at data row {nan[0] + 1} ({nan.size} NaN)",
                             "finite numbers")
        out[col] = a * factor if factor != 1.0 else a
    missing = [c for c in _REQUIRED if c not in out]
    if missing:
        raise InputError(f"{path}: header", ",".join(map(str, mapping)),
                         "the columns " + ", ".join(missing) + " as well")
    if n is None or n == 0:
        raise InputError(str(path), "no data rows", "at least 3 rows")
    return pd.DataFrame({c: out[c] for c in _COLUMNS if c in out})
