"""Read the seed paper's tables (``shared/data/paper/*.csv``): ``#`` comment lines, then a header.

The tables live outside the package, beside the repository (``../shared/data/paper``). The directory
is found from, in order: the ``DRAKECREEP_PAPER_DATA`` environment variable, ``../shared/data/paper``
relative to the repository root, and the same relative to the current directory.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

from drakecreep.errors import InputError

__all__ = ["paper_data_dir", "read_paper_table"]

_REPO_ROOT = Path(__file__).resolve().parent.parent


def paper_data_dir() -> Path:
    """Directory holding the paper's CSV tables.

    Raises
    ------
    InputError
        If no candidate directory exists.
    """
    candidates = []
    env = os.environ.get("DRAKECREEP_PAPER_DATA")
    if env:
        candidates.append(Path(env))
    candidates += [_REPO_ROOT.parent / "shared" / "data" / "paper",
                   Path.cwd().parent / "shared" / "data" / "paper",
                   Path.cwd() / "shared" / "data" / "paper"]
    for path in candidates:
        if path.is_dir():
            return path
    raise InputError("DRAKECREEP_PAPER_DATA", env,
                     "a directory with the paper's CSV tables (default ../shared/data/paper)")


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
