"""drakecreep.gap.runs: cutting a measured run at the reversals of its reference."""

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.gap.measured import EMPS_CONTROLLER, MeasuredMeta, MeasuredRun
from drakecreep.gap.runs import load_runs, split_cycles, split_half_cycles
from drakecreep.gap.truth import out_and_back

META = MeasuredMeta(u_units="V", u_gain=35.15, controller=EMPS_CONTROLLER)


def _three_cycles():
    x = np.concatenate([out_and_back(0.05, 0.0)] * 3)
    t = np.arange(x.size) * 1e-3
    return MeasuredRun(t=t, x_ref=x, x_motor=x, u=np.zeros(x.size), meta=META, label="three")


def test_split_cycles_cuts_every_second_reversal():
    run = _three_cycles()
    parts = split_cycles(run)
    assert len(parts) == 3
    assert [p.label for p in parts] == ["three#0", "three#1", "three#2"]
    assert sum(p.n for p in parts) == run.n


def test_split_half_cycles_cuts_every_reversal():
    run = _three_cycles()
    parts = split_half_cycles(run)
    assert [p.label for p in parts] == [f"three@{i}" for i in range(6)]
    assert sum(p.n for p in parts) == run.n
    for p in parts:  # each part moves one way (up to the creeping start of the next leg, below 1 % of the speed)
        dx = np.diff(p.x_ref)
        forward, backward = dx[dx > 0].sum(), -dx[dx < 0].sum()
        assert min(forward, backward) < 0.01 * max(forward, backward)


@pytest.mark.parametrize("split", [split_cycles, split_half_cycles])
def test_the_shortest_part_is_a_duration_not_a_count_of_samples(split):
    """A run logged every 4 ms is cut where the same run logged every 1 ms is (until session 86 the shortest part
    was 500 or 200 samples, 2 s or 0.8 s at 4 ms: a 4 ms log of EMPS's first 8 s gave 2 parts, the 1 ms log 6)."""
    run = _three_cycles()
    slow = MeasuredRun(t=run.t[::4], x_ref=run.x_ref[::4], x_motor=run.x_motor[::4], u=run.u[::4], meta=META,
                       label="three")
    fast_parts, slow_parts = split(run), split(slow)
    assert len(slow_parts) == len(fast_parts) > 0
    for a, b in zip(fast_parts, slow_parts):
        assert abs(a.n * a.dt - b.n * b.dt) <= 4 * slow.dt
    # a part shorter than the duration is dropped at either rate
    longest = max(p.n * p.dt for p in fast_parts)
    assert split(run, min_time=1.01 * longest) == [] and split(slow, min_time=1.01 * longest) == []


def test_default_train_test_split_keeps_two_held_out_runs():
    from types import SimpleNamespace

    from drakecreep.gap.runs import train_test

    runs = [SimpleNamespace(label=f"r{i}") for i in range(5)]
    assert [[r.label for r in part] for part in train_test(runs[:3])] == [["r0"], ["r1", "r2"]]
    assert [[r.label for r in part] for part in train_test(runs[:4])] == [["r0", "r2"], ["r1", "r3"]]
    assert [[r.label for r in part] for part in train_test(runs)] == [["r0", "r2", "r4"], ["r1", "r3"]]
    assert [[r.label for r in part] for part in train_test(runs[:3], "r2", "0,1")] == [["r2"], ["r0", "r1"]]
    assert [[r.label for r in part] for part in train_test(runs[:3], pairs=True)] == [["r0"], ["r1", "r2"]]
    assert [[r.label for r in part] for part in train_test(runs[:4], pairs=True)] == [["r0", "r1"], ["r2", "r3"]]


def test_one_selection_leaves_the_other_runs_to_the_other_set():
    from types import SimpleNamespace

    from drakecreep.gap.runs import train_test

    runs = [SimpleNamespace(label=f"r{i}") for i in range(5)]
    labels = lambda parts: [[r.label for r in part] for part in parts]  # noqa: E731
    assert labels(train_test(runs[:3], test_spec="1")) == [["r0", "r2"], ["r1"]]
    assert labels(train_test(runs, train_spec="0,1")) == [["r0", "r1"], ["r2", "r3", "r4"]]
    assert labels(train_test(runs, test_spec="r4,r0", pairs=True)) == [["r1", "r2", "r3"], ["r4", "r0"]]


def test_a_label_with_a_comma_is_named_by_its_index():
    """``--train`` splits at commas, so a run labelled ``"a,b"`` cannot be named: the error says its index, and the
    index selects it."""
    from types import SimpleNamespace

    import pytest

    from drakecreep.errors import InputError
    from drakecreep.gap.runs import pick

    runs = [SimpleNamespace(label=lab) for lab in ("x", "a,b", "y")]
    with pytest.raises(InputError) as err:
        pick(runs, "a,b", 0, "--test")
    assert err.value.field == "--test" and "by its index: 1 for 'a,b'" in str(err.value)
    assert [r.label for r in pick(runs, "1,y", 0, "--test")] == ["a,b", "y"]
    with pytest.raises(InputError) as err:
        pick(runs[::2], "z", 0)
    assert "comma" not in str(err.value)


def test_a_measured_mat_with_its_metadata_beside_it_is_told_of_meta(tmp_path):
    """A .mat without --meta is read as an EMPS file: a measured run's .mat with its metadata beside it was told
    'the EMPS variables t, qm, qg, vir, gtau, kp, kv' alone."""
    import pytest
    import scipy.io

    from drakecreep.errors import InputError
    from drakecreep.gap.runs import load_runs

    t = np.arange(50) * 1e-3
    scipy.io.savemat(tmp_path / "run.mat", {"t": t, "x_ref": t, "x_motor": t, "u": np.sin(t)})
    with pytest.raises(InputError, match="EMPS variables") as err:
        load_runs(tmp_path / "run.mat")
    assert "--meta" not in err.value.allowed  # no metadata: an EMPS file that lacks its variables
    (tmp_path / "run.yaml").write_text("u_units: N\nu_gain: 1.0\n")
    with pytest.raises(InputError, match=r"EMPS variables .*; or a measured run's signals, with its metadata named "
                                         r"\(diagnose --meta .*run.yaml: without it a .mat is read as an EMPS file\)"):
        load_runs(tmp_path / "run.mat")
    assert len(load_runs(tmp_path / "run.mat", tmp_path / "run.yaml", split=False)) == 1


@pytest.mark.parametrize("data", ["estimation", "validation"])
def test_a_metadata_file_beside_an_emps_benchmark_name_is_refused(data, tmp_path):
    """The benchmark's files carry their own controller and units: a meta file given with them was ignored without a
    word (found by the fuzzing pass)."""
    (tmp_path / "m.yaml").write_text("u_units: N\n")
    with pytest.raises(InputError) as err:
        load_runs(data, tmp_path / "m.yaml")
    assert err.value.field == "meta" and err.value.value == str(tmp_path / "m.yaml")
    assert err.value.allowed.startswith(f"no metadata with the EMPS benchmark's {data} file")
