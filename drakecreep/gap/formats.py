"""Reading measured runs from files: CSV (pandas), Parquet, HDF5 and MATLAB ``.mat``, with units converted to SI.

A file holds one column per signal. The column names are the project's (``t``, ``x_ref``, ``x_motor``,
``x_table``, ``u``, ``f_ext``, ``run``), optionally with a unit in brackets (``t[ms]``, ``x_motor[mm]``,
``u[V]``), or the file's own names mapped to the project's by the metadata's ``file.columns``. Units come from
the header or from ``file.units``; a column without a unit is in SI (``u``: in the metadata's ``u_units``).
See ``docs/measured_format.md``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from drakecreep.errors import InputError

__all__ = ["DECIMALS", "FORMATS", "SEPARATORS", "UNITS", "read_signals", "unit_factor", "parse_column"]

#: file suffix -> format name
FORMATS = {".csv": "csv", ".txt": "csv", ".parquet": "parquet", ".pq": "parquet", ".h5": "hdf5",
           ".hdf5": "hdf5", ".hdf": "hdf5", ".mat": "mat"}

#: quantity -> unit -> factor to SI
UNITS = {
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6},
    "length": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "nm": 1e-9},
    "force": {"N": 1.0, "kN": 1e3, "mN": 1e-3},
    # the controller output keeps the metadata's u_units; only a scale prefix is converted
    "N": {"N": 1.0, "kN": 1e3, "mN": 1e-3},
    "V": {"V": 1.0, "mV": 1e-3},
    "A": {"A": 1.0, "mA": 1e-3},
}

#: signal -> quantity (u: the metadata's u_units)
QUANTITY = {"t": "time", "x_ref": "length", "x_motor": "length", "x_table": "length", "f_ext": "force"}

_HEADER = re.compile(r"^\s*([^\[\]()]*?)\s*(?:[\[(]\s*([^\])]*?)\s*[\])])?\s*$")


def parse_column(cell):
    """``"x_motor [mm]"`` -> ``("x_motor", "mm")``; ``"t"`` -> ``("t", None)``; ``"t[]"`` -> ``("t", "")`` (brackets
    without a unit are no unit, which :func:`unit_factor` refuses: they were read as SI)."""
    m = _HEADER.match(str(cell))
    if not m or not m.group(1):
        return str(cell).strip(), None
    return m.group(1), m.group(2)


#: the micro prefix as it is typed: the micro sign U+00B5 (the tables' spelling) and the Greek small mu U+03BC, which
#: Unicode normalization makes of it and many programs write; they look alike, so 'μs' was refused with 'allowed:
#: one of s, ms, us, µs'
_MICRO = str.maketrans({"\u03bc": "\u00b5"})


def unit_factor(signal, unit, u_units, where):
    """Factor from ``unit`` to SI for ``signal`` (``u``: to ``u_units``), or an InputError naming the column."""
    quantity = u_units if signal == "u" else QUANTITY.get(signal)
    if quantity is None or unit is None:
        return 1.0
    table = UNITS[quantity]
    key = unit.translate(_MICRO) if isinstance(unit, str) else unit
    if key not in table:
        raise InputError(f"{where}: column {signal} unit", unit,
                         "one of " + ", ".join(table) + (" (u is in the metadata's u_units)" if signal == "u" else "")
                         + (f" in the brackets (or no brackets: {signal} in {'u_units' if signal == 'u' else 'SI'})"
                            if not str(unit).strip() else ""))
    return table[key]


#: CSV field separators a file may use (``file.separator``; without it, the header line decides)
SEPARATORS = {",": ",", ";": ";", "tab": "\t", "\t": "\t"}
#: decimal marks (``file.decimal``; without it, ``,`` when the separator is not a comma and the first data row
#: writes numbers with a comma, as spreadsheets in many locales export)
DECIMALS = (".", ",")


def _mat_frame(path, mat, wanted):
    """The vector variables of a loaded ``.mat`` as columns of one length. A variable that names a signal
    (``wanted``) and is no real vector of that length is refused by name: dropped, it was reported as missing ('the
    columns u as well' for a complex u, an x_ref one sample short, a matrix or a single value)."""
    import pandas as pd

    columns, refused = {}, {}
    for name, value in mat.items():
        if name.startswith("__"):
            continue
        a = np.asarray(value)
        if a.dtype.kind == "c":
            refused[name] = (f"complex numbers ({a.dtype})", "real numbers")
        elif a.dtype.kind not in "fiu":
            refused[name] = (f"a MATLAB {'struct' if a.dtype.names else 'cell or text'} array", "a numeric vector")
        elif not (a.ndim <= 2 and 1 in (a.shape + (1,))[:2]):
            refused[name] = (f"shape {a.shape}", "a vector (one row or one column)")
        elif a.size > 1:
            columns[name] = a.astype(float).ravel()
        else:  # a scalar (a gain, a setting) stays out of the columns; named only if it is a signal's name
            refused[name] = (f"{a.size} value{'s' if a.size != 1 else ''}", "a vector of the run's samples")
    if not columns and refused:  # a struct or cells holding the run: 'no data; allowed: a header line' was CSV's word
        got = ", ".join(f"{name}: {what}" for name, (what, _) in list(refused.items())[:5])
        raise InputError(str(path), f"no numeric vector variable ({got})",
                         "the run's signals as numeric vectors t, x_ref, x_motor, u, ... (structs and cells are not "
                         "read: save their fields as variables, scipy.io.savemat or MATLAB's save -struct)")
    lengths = {a.size for a in columns.values()}
    longest = max(lengths, default=0)
    for name, a in columns.items():
        if a.size != longest:
            refused[name] = (f"length {a.size}", f"the length of the longest vector, {longest}")
    for name, (got, allowed) in refused.items():
        if name in wanted or parse_column(name)[0] in wanted:
            raise InputError(f"{path}: {name}", got, allowed)
    return pd.DataFrame({k: v for k, v in columns.items() if v.size == longest})


def _frame(path, fmt, key, separator=None, decimal=None, run_column="run", wanted=()):
    import pandas as pd

    if fmt == "csv":
        from drakecreep.files import csv_dialect, read_csv_frame

        if decimal is not None and separator is None:  # the metadata's decimal against the header's separator
            with open(path, encoding="utf-8", errors="replace") as fh:
                separator = csv_dialect(fh)[0]  # (given on to the reader, which would detect it again)
            if separator == decimal:
                raise InputError(f"{path}: file.decimal", decimal, f"a mark other than the file's separator "
                                 f"{separator!r} (a decimal comma goes with ';' or tab separators; file.separator "
                                 "names another)")
        return read_csv_frame(path, str(path), "a CSV with a header line and data rows", separator, decimal,
                              text_columns=(run_column,))  # run labels as written: 1 and 1.0 are two runs
    if fmt == "parquet":
        try:
            import pyarrow.parquet as pq

            names = pq.read_schema(path).names
        except Exception:  # noqa: BLE001 - not a Parquet file: read_parquet below says so
            names = []
        twice = next((name for i, name in enumerate(names) if name in names[:i]), None)
        if twice is not None:  # pyarrow refuses the table as 'ArrowInvalid' (a CSV's repeated column is named)
            raise InputError(f"{path}: header", twice, "each column once")
        try:
            return _with_index(pd.read_parquet(path))
        except Exception as err:  # noqa: BLE001 - pyarrow raises many types for a corrupt file
            raise InputError(str(path), f"not a readable Parquet file ({type(err).__name__})",
                             "a Parquet table") from None
    if fmt == "hdf5":
        try:
            frame = pd.read_hdf(path, key=key)
            if not isinstance(frame, pd.DataFrame):  # a Series ended in 'internal error: IndexError'
                raise InputError(f"{path}: file.key", key, f"the key of a table (DataFrame.to_hdf); this one holds "
                                 f"a {type(frame).__name__}")
            return _with_index(frame)
        except InputError:
            raise
        except ImportError:
            raise InputError(str(path), "HDF5", "CSV, Parquet or .mat (HDF5 needs the 'tables' package: "
                             "pip install tables)") from None
        except (KeyError, ValueError, TypeError) as err:
            raise InputError(f"{path}: file.key", key, f"the key of one pandas table in the file ({err})"[:200]) from None
        except Exception as err:  # noqa: BLE001 - a corrupt or truncated file: OSError, tables' HDF5ExtError, ...
            raise InputError(str(path), f"not a readable HDF5 file ({type(err).__name__})",
                             "an HDF5 file written by pandas (DataFrame.to_hdf)") from None
    import scipy.io

    try:
        mat = scipy.io.loadmat(str(path))
    except Exception as err:  # noqa: BLE001 - empty, truncated, corrupt: OSError, IndexError, MatReadError, zlib.error
        raise InputError(str(path), f"not a readable MATLAB file ({type(err).__name__})",
                         "a MATLAB .mat file (v4-v7.2)") from None
    return _mat_frame(path, mat, wanted)


def _with_index(frame):
    """A table with its named index as a column: a Parquet or HDF5 file written from a frame indexed by time
    (``df.set_index('t[ms]').to_parquet(...)``) keeps t as the index, and t was then reported missing."""
    if any(name is not None for name in frame.index.names) and not set(frame.index.names) & set(frame.columns):
        frame = frame.reset_index()
    return frame


def _unit_of(path, signal, header_unit, units):
    """The unit of ``signal``'s column: the header's, or the metadata's ``file.units`` for a name without one. Both,
    and different, are refused: ``t[ms]`` with ``file.units: {t: s}`` was read in seconds without a word."""
    unit = units.get(signal, header_unit)
    if header_unit is not None and signal in units and str(unit).translate(_MICRO) != header_unit.translate(_MICRO):
        raise InputError(f"{path}: file.units.{signal}", unit, f"the unit the file's header gives the column, "
                         f"{header_unit} (file.units is for names without a unit: leave {signal} out)")
    return unit


def read_signals(path, u_units, columns=None, units=None, key=None, separator=None, decimal=None):
    """Read a measured file into SI arrays of the project's signal names.

    Parameters
    ----------
    path : path-like
        ``.csv``/``.txt``, ``.parquet``/``.pq``, ``.h5``/``.hdf5`` or ``.mat``.
    u_units : str
        The metadata's unit of ``u`` (``N``, ``V`` or ``A``); ``u`` is scaled to it, not converted.
    columns : dict, optional
        Project signal name -> the file's column (or MATLAB variable) name.
    units : dict, optional
        Project signal name -> unit, for columns whose name carries none.
    key : str, optional
        The HDF5 key of the table.
    separator, decimal : str, optional
        A CSV's field separator (``,``, ``;`` or a tab) and decimal mark (``.`` or ``,``); default: from the
        header line and the first data row (:func:`drakecreep.files.csv_dialect`).

    Returns
    -------
    dict
        Signal name -> ``numpy`` array (``run`` -> array of labels as str); the file's column order.
    """
    path = Path(path)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise InputError(str(path), path.suffix or "(no suffix)", "a file ending in " + ", ".join(FORMATS))
    # an option of another format was ignored without a word ('file: {key: /x}' beside a CSV)
    for name, value, only in (("key", key, "hdf5"), ("separator", separator, "csv"), ("decimal", decimal, "csv")):
        if value is not None and fmt != only:
            raise InputError(f"{path}: file.{name}", value, f"only for {'an HDF5' if only == 'hdf5' else 'a CSV'} file "
                             f"(this one is read as {fmt}: leave file.{name} out)")
    wanted = set(map(str, (columns or {}).values())) if columns else set(QUANTITY) | {"u", "run"}
    frame = _frame(path, fmt, key, separator, decimal, run_column=str((columns or {}).get("run", "run")), wanted=wanted)
    if frame.shape[1] == 0 or frame.shape[0] == 0:
        raise InputError(str(path), "no data", "a header line and data rows")
    mapping = dict(columns or {})
    units = dict(units or {})
    for signal in list(mapping) + list(units):
        if signal not in QUANTITY and signal not in ("u", "run"):
            raise InputError(f"{path}: file.columns/units", signal,
                             "signals among t, x_ref, x_motor, x_table, u, f_ext, run")
    by_file = {str(c): c for c in frame.columns}
    out = {}
    if mapping:
        taken = {}
        for signal, column in mapping.items():
            if str(column) not in by_file:
                raise InputError(f"{path}: file.columns.{signal}", column,
                                 "a column of the file: " + ", ".join(list(by_file)[:20]))
            if str(column) in taken:  # x_motor read from x_ref's column replayed a motor that followed exactly
                raise InputError(f"{path}: file.columns.{signal}", column,
                                 f"a column not already mapped (it is {taken[str(column)]}'s): one column per signal")
            taken[str(column)] = signal
            _, unit = parse_column(column)
            out[signal] = (by_file[str(column)], _unit_of(path, signal, unit, units))
    else:
        for name, column in by_file.items():
            signal, unit = parse_column(name)
            first = re.match(r"^(.*)\.\d+$", name)
            if fmt == "csv" and first and first.group(1) in by_file:  # pandas renames a repeated name 'x' to 'x.1'
                signal = parse_column(first.group(1))[0]
            if signal in out:
                raise InputError(f"{path}: header", signal, "each column once")
            out[signal] = (column, _unit_of(path, signal, unit, units))
    signals = {}
    for signal, (column, unit) in out.items():
        values = frame[column]
        if signal == "run":
            signals["run"] = values.astype(str).to_numpy()
            continue
        if signal not in QUANTITY and signal != "u":
            signals[signal] = values  # unknown: the caller names it
            continue
        if values.dtype.kind in "bmMc":  # read as floats they were 0/1, nanoseconds since 1970, or the real part
            kind = {"b": "true/false", "m": "time spans", "M": "dates and times", "c": "complex numbers"}
            raise InputError(f"{path}: column {signal}", f"{kind[values.dtype.kind]} ({values.dtype})",
                             "real numbers" + (" (seconds from the run's start, or a unit in the header: t[ms])"
                                               if signal == "t" else ""))
        from pandas.api.types import is_numeric_dtype

        from drakecreep.files import first_non_number

        data = None
        try:
            bad = None if is_numeric_dtype(values) else first_non_number(values)  # text cells: each one read
            data = values.to_numpy(dtype=float) if bad is None else None
        except (TypeError, ValueError):
            bad = first_non_number(values)
            bad = values.iloc[0] if bad is None else bad
        if data is None:
            raise InputError(f"{path}: column {signal}", str(bad)[:40], "numbers")
        signals[signal] = data * unit_factor(signal, unit, u_units, str(path))
    return signals

