"""A long diagnosis's finished steps kept in a file, so that a run stopped or killed resumes where it was.

A ``drakecreep`` diagnosis of a benchmark dataset takes from minutes to hours (a saturated drive's nominal fit
alone took 80 min on one core; docs/gap_benchmark.md 3ct); a process killed in it lost all of it. A
:class:`Checkpoint` keeps each finished step's result (pickled, the file replaced atomically after each) under
a key of everything the result depends on: the diagnosis's inputs and the source of the package. A later
diagnosis with the same inputs on the same code reads the steps instead of computing them; with anything else
(other runs, options, a changed module) the file is not used and is overwritten. Each step's result is the one
computed before, bit for bit, so the diagnosis resumed is the one an uninterrupted call returns.

The file is a pickle: read only files this program wrote (as with any pickle).
"""

from __future__ import annotations

import hashlib
import pickle
from pathlib import Path

from drakecreep.errors import InputError
from drakecreep.files import write_atomic

__all__ = ["Checkpoint", "source_digest"]

_FORMAT = 1  # bump when what a step stores changes meaning
_DIGEST = None


def source_digest():
    """SHA-256 of every ``.py`` file of the installed ``drakecreep`` package (paths and contents, sorted): a
    checkpoint is valid for the code that wrote it only."""
    global _DIGEST
    if _DIGEST is None:
        root = Path(__file__).resolve().parents[1]
        h = hashlib.sha256()
        for path in sorted(root.rglob("*.py")):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
        _DIGEST = h.hexdigest()
    return _DIGEST


class Checkpoint:
    """The finished steps of one computation, kept in the file ``path``.

    Parameters
    ----------
    path : str or Path
        The checkpoint file (created when the first step ends; its folder too).
    inputs : object
        Everything the steps' results depend on besides the package's code (picklable): its hash and the
        code's are the key the file must carry to be used.

    Raises
    ------
    InputError
        ``path`` is a folder.
    """

    def __init__(self, path, inputs):
        self.path = Path(path)
        if self.path.is_dir():
            raise InputError("checkpoint", str(path), "a file (not a folder) for the diagnosis's finished steps")
        h = hashlib.sha256(pickle.dumps((_FORMAT, inputs), protocol=4))
        h.update(source_digest().encode())
        self.key = h.hexdigest()
        self.steps = {}
        #: the steps read from the file (empty when there was none, or one of other inputs or code)
        self.resumed = ()
        try:
            with open(self.path, "rb") as f:
                saved = pickle.load(f)
        except (OSError, EOFError, pickle.UnpicklingError, AttributeError, ImportError, TypeError, ValueError):
            return
        if isinstance(saved, dict) and saved.get("key") == self.key and isinstance(saved.get("steps"), dict):
            self.steps = saved["steps"]
            self.resumed = tuple(self.steps)

    def get(self, step, default=None):
        """The result kept for ``step``, or ``default``."""
        return self.steps.get(step, default)

    def __contains__(self, step):
        return step in self.steps

    def put(self, step, value):
        """Keep ``value`` as ``step``'s result and rewrite the file (atomically: a kill leaves the former one)."""
        self.steps[step] = value
        payload = pickle.dumps({"key": self.key, "steps": self.steps}, protocol=4)
        write_atomic(self.path, lambda tmp: Path(tmp).write_bytes(payload))

    def discard(self):
        """Remove the file (the computation it served is finished and kept elsewhere)."""
        self.path.unlink(missing_ok=True)
