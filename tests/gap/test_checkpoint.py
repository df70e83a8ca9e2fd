"""drakecreep.gap.checkpoint: finished steps kept in a file for the same inputs and code only (a diagnosis resumed
from them: tests/gap/test_drive_fit.py)."""

import pickle

import pytest

from drakecreep.errors import InputError
from drakecreep.gap.checkpoint import Checkpoint, source_digest


def test_steps_are_kept_for_the_same_inputs_only(tmp_path):
    path = tmp_path / "sub" / "c.pkl"
    c = Checkpoint(path, ("runs", 1))
    assert c.resumed == () and "a" not in c
    c.put("a", [1.5, 2])
    c.put(("candidate", "b"), None)
    again = Checkpoint(path, ("runs", 1))
    assert again.resumed == ("a", ("candidate", "b")) and again.get("a") == [1.5, 2]
    # other inputs: the file is not read, and the first step written replaces it
    other = Checkpoint(path, ("runs", 2))
    assert other.resumed == () and other.get("a", "none") == "none"
    other.put("c", 3)
    assert Checkpoint(path, ("runs", 1)).resumed == ()
    # a file of other code (its key differs) or not a checkpoint at all is not read
    path.write_bytes(pickle.dumps({"key": "0" * 64, "steps": {"a": 1}}))
    assert Checkpoint(path, ("runs", 1)).resumed == ()
    path.write_bytes(b"not a pickle")
    assert Checkpoint(path, ("runs", 1)).resumed == ()
    Checkpoint(path, ("runs", 1)).discard()
    assert not path.exists()
    with pytest.raises(InputError, match="checkpoint"):
        Checkpoint(tmp_path, ())
    assert len(source_digest()) == 64
