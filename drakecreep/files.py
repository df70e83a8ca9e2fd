"""Writing results: atomic files and one JSON form for every output (base layer: imports nothing of the package).

Every JSON the project writes or prints goes through :func:`to_jsonable`: NumPy scalars and arrays become
Python numbers and lists, NaN becomes ``null`` and an infinite value the string ``"inf"`` / ``"-inf"``
(JSON has neither; an infinite gain margin is a real answer, not a missing one).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import tempfile
from pathlib import Path

__all__ = ["to_jsonable", "write_atomic", "write_json", "write_text"]


def to_jsonable(obj):
    """``obj`` as plain JSON types (dicts, lists, str, int, float, bool, None), recursively.

    Dataclasses become dicts of their fields; NaN becomes None; +-inf becomes ``"inf"``/``"-inf"``.
    """
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        obj = dataclasses.asdict(obj)
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, set)):
        return [to_jsonable(v) for v in obj]
    if hasattr(obj, "tolist") and not isinstance(obj, (str, bytes)):
        return to_jsonable(obj.tolist())
    if isinstance(obj, bool) or obj is None or isinstance(obj, (str, int)):
        return obj
    if isinstance(obj, float):
        if math.isnan(obj):
            return None
        if math.isinf(obj):
            return "inf" if obj > 0 else "-inf"
        return obj
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    return obj


def write_atomic(path, write):
    """Write a file atomically: ``write(tmp_path)`` then ``os.replace(tmp_path, path)``.

    A reader (or a resumed sweep) sees the old file or the whole new one, never a partial one. The file is
    readable by the group and others (0644 less the umask), like any file a program writes.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def write_text(path, text):
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    def write(tmp):
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
    return write_atomic(path, write)


def write_json(path, obj, indent=None):
    """Write ``to_jsonable(obj)`` as JSON to ``path`` atomically."""
    return write_text(path, json.dumps(to_jsonable(obj), indent=indent) + ("\n" if indent else ""))
