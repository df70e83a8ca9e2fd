"""Read the seed paper's tables (package data ``drakecreep/data/paper/*.csv``): ``#`` comment lines, then a header."""

from __future__ import annotations

import csv
import os
from pathlib import Path

from drakecreep.data import paper_data_dir
from drakecreep.errors import InputError

__all__ = ["paper_data_dir", "read_paper_table"]


def read_paper_table(name: str, data_dir: str | os.PathLike | None = None) -> list[dict]:
    """Rows of one paper table as dicts; numeric cells converted to float.

    Parameters
    ----------
    name : str
        File stem, e.g. ``"table1_bolted_fixed_joints"``.
    data_dir : path-like, optional
        Directory of the CSV files (default :func:`paper_data_dir`).

    Returns
    -------
    list of dict
    """
    path = Path(data_dir) if data_dir is not None else paper_data_dir()
    path = path / f"{name}.csv"
    if not path.is_file():
        raise InputError("table", name, f"a CSV file in {path.parent}")
    with path.open(newline="") as fh:
        lines = [line for line in fh if line.strip() and not line.lstrip().startswith("#")]
    rows = []
    for row in csv.DictReader(lines):
        out = {}
        for key, value in row.items():
            try:
                out[key] = float(value)
            except ValueError:
                out[key] = value
        rows.append(out)
    return rows
