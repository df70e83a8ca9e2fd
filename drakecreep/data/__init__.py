"""Data shipped with the package, found without environment variables.

- ``paper/``: the seed paper's Tables 1-9 as CSV (``#`` comment lines, then a header).
- ``emps/``: the EMPS benchmark's two measured files (Janot, Gautier, Brunot, 2019; see ``emps/README.md``
  for the citation, the signals and the rule that ``DATA_EMPS_PULSES.mat`` is a held-out test set).
- ``examples/``: small example inputs (a measured run in ms, mm and V with its metadata YAML).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["data_dir", "paper_data_dir", "emps_data_dir", "examples_dir", "example_path"]


def data_dir() -> Path:
    """The package's data folder (a real directory: the package is installed from files, not a zip)."""
    return Path(str(resources.files(__name__)))


def paper_data_dir() -> Path:
    """Folder of the paper's CSV tables."""
    return data_dir() / "paper"


def emps_data_dir() -> Path:
    """Folder of the EMPS ``.mat`` files and their README."""
    return data_dir() / "emps"


def examples_dir() -> Path:
    """Folder of the example inputs (``docs/measured_format.md``, ``docs/tutorial.md``)."""
    return data_dir() / "examples"


def example_path(name: str) -> Path:
    """Path of a shipped example file, e.g. ``example_path("emps_segment.csv")``."""
    path = examples_dir() / name
    if not path.exists():
        from drakecreep.errors import InputError

        raise InputError("example", name, "one of " + ", ".join(sorted(p.name for p in examples_dir().iterdir())))
    return path
