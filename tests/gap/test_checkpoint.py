"""drakecreep.gap.checkpoint: a diagnosis's finished steps kept in a file, and a diagnosis resumed from them."""

import pickle

import pytest

from drakecreep.errors import InputError
from drakecreep.gap import drive_fit
from drakecreep.gap.checkpoint import Checkpoint, source_digest
from drakecreep.gap.drake_replay import quick_replay_params, simulated_runs
from drakecreep.gap.drive_fit import diagnose_drive
from drakecreep.params import preset


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


def test_a_diagnosis_stopped_after_a_candidate_resumes_there_and_returns_the_same_result(tmp_path, monkeypatch):
    rig = quick_replay_params(preset("paper"))
    runs = simulated_runs(rig, (0.02, 0.03, 0.025, 0.035), declared=rig, n=500, noise=2.0, seed=300)
    kwargs = dict(uncertain=("table.seal_force",), effects=("law_coulomb", "nut_friction_side"), max_nfev=2)
    whole = diagnose_drive(runs[:2], runs[2:], **kwargs)

    class Stop(Exception):
        pass

    def stop_after_a_candidate(stage, partial):
        if stage == "candidate":
            raise Stop(partial.simulations)

    path = tmp_path / "diagnosis.pkl"
    with pytest.raises(Stop) as stopped:
        diagnose_drive(runs[:2], runs[2:], on_stage=stop_after_a_candidate, checkpoint=path, **kwargs)
    done_before = stopped.value.args[0]  # the nominal fit, its null and one candidate
    assert 0 < done_before < whole.simulations

    replays, original = [], drive_fit.replay_drakecreep
    monkeypatch.setattr(drive_fit, "replay_drakecreep", lambda *a, **k: replays.append(1) or original(*a, **k))
    lines = []
    resumed = diagnose_drive(runs[:2], runs[2:], checkpoint=path, progress=lines.append, **kwargs)
    assert lines[0].startswith(f"resumed from {path}: nominal, ")
    # only what was left is replayed; the result is the uninterrupted one, replay count included
    assert len(replays) == whole.simulations - done_before
    assert resumed.simulations == whole.simulations
    assert resumed.fitted == whole.fitted and resumed.claimed == whole.claimed and resumed.params == whole.params
    assert [(c.name, c.gain, c.threshold, c.values) for c in resumed.candidates] == [
        (c.name, c.gain, c.threshold, c.values) for c in whole.candidates]
    assert resumed.warnings == whole.warnings and resumed.replay_null == whole.replay_null
    assert resumed.nominal_test_errors == whole.nominal_test_errors and resumed.test_errors == whole.test_errors
    # finished: a third call reads the result without a replay; other options do not read the file
    replays.clear()
    assert diagnose_drive(runs[:2], runs[2:], checkpoint=path, **kwargs).to_json() == resumed.to_json()
    assert replays == []
    assert Checkpoint(path, (runs[:2], runs[2:])).resumed == ()
