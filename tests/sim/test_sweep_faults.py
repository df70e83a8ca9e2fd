"""Sweeps under faults: Ctrl-C keeps finished cases and does not wait for the queue; a killed sweep leaves no
orphan workers; a corrupt cache entry is recomputed, not trusted."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pandas as pd

_ROOT = Path(__file__).resolve().parents[2]

# 8 cases of ~1-2 s on 2 workers; the child prints the pids of its workers' parent (itself)
_SCRIPT = textwrap.dedent("""
    import sys
    from drakecreep.params import preset, with_value
    from drakecreep.sim.sweep import grid, run_sweep
    base = with_value(preset("paper"), "simulation.steady_start", 0.2)
    points = grid({"table.mass": [30.0, 32.0, 34.0, 36.0, 38.0, 40.0, 42.0, 44.0]})
    print("START", flush=True)
    try:
        run_sweep(base, points, scenario={"feed": 1e-3, "load_case": 3, "duration": 3.0}, executor="processes",
                  workers=2, out_dir=sys.argv[1], progress=False)
    except KeyboardInterrupt:
        print("INTERRUPTED", flush=True)
        sys.exit(130)
    print("DONE", flush=True)
""")


def _children(pid):
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def _alive(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _cached(cache):
    """Finished cache entries (not the hidden temporary files of a write under way)."""
    return [p for p in cache.glob("*.json") if not p.name.startswith(".")] if cache.is_dir() else []


def _sigint_as_at_a_terminal():
    # a shell starts a background job (``cmd &`` without job control, ``nohup``) with SIGINT ignored, and the
    # child would inherit that: the sweep is started as from a terminal, where Ctrl-C is delivered
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(tmp_path):
    proc = subprocess.Popen([sys.executable, "-c", _SCRIPT, str(tmp_path / "out")], cwd=_ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_sigint_as_at_a_terminal)
    assert proc.stdout.readline().strip() == "START"
    cache = tmp_path / "out" / "cache"
    deadline = time.time() + 120
    while time.time() < deadline and not _cached(cache):
        time.sleep(0.2)
    assert _cached(cache), "no case finished in time"
    return proc, cache


def test_ctrl_c_cancels_the_queue_and_keeps_finished_cases(tmp_path):
    proc, cache = _start(tmp_path)
    start = time.time()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert time.time() - start < 20, "Ctrl-C waited for the queued cases"
    assert proc.returncode == 130 and "INTERRUPTED" in out, err
    table = pd.read_csv(tmp_path / "out" / "results.csv")
    finished = table[table.status == "ok"]
    assert len(table) == 8 and 1 <= len(finished) < 8
    assert set(table.status) <= {"ok", "not run (interrupted)"}
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert manifest["interrupted"] is True and "results.csv" in manifest["files"]
    assert len(_cached(cache)) >= len(finished)


def test_sigkill_of_the_sweep_does_not_orphan_its_workers(tmp_path):
    proc, _ = _start(tmp_path)
    workers = [p for p in _children(proc.pid) if _alive(p)]
    assert workers
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=10)
    deadline = time.time() + 15
    while time.time() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.2)
    left = [p for p in workers if _alive(p)]
    for pid in left:  # do not leave them running if the test fails
        os.kill(pid, signal.SIGKILL)
    assert not left, f"orphaned workers: {left}"


def test_corrupt_cache_entries_are_recomputed(tmp_path, paper):
    from drakecreep.params import with_value
    from drakecreep.sim.sweep import make_cases, run_sweep

    base = with_value(paper, "simulation.steady_start", 0.2)
    points = [{"table.mass": 40.0}]
    scen = {"feed": 2e-3, "load_case": 3, "duration": 0.5}
    key = make_cases(base, points, scen)[0].key
    cache = tmp_path / "cache"
    cache.mkdir()
    for body in ("{not json", json.dumps({"key": key, "row": "x" * 10}),
                 json.dumps({"key": key, "row": {"status": "ok", "fluctuation_rate_percent": [1, 2]}}),
                 json.dumps({"key": "other", "row": {"status": "ok"}})):
        (cache / f"{key}.json").write_text(body)
        r = run_sweep(base, points, scenario=scen, executor="serial", out_dir=tmp_path, progress=False)
        assert r.computed == 1 and r.cached == 0
        assert r.table.status.iloc[0] == "ok"


def test_a_batched_row_is_reused_only_for_the_same_batch(tmp_path, paper):
    from drakecreep.params import with_value
    from drakecreep.sim.sweep import run_sweep

    base = with_value(paper, "simulation.steady_start", 0.2)
    points = [{"table.mass": 40.0}, {"table.mass": 44.0}]
    scen = {"feed": 2e-3, "load_case": 3, "duration": 0.4}

    def run(batch):
        return run_sweep(base, points, scenario=scen, executor="serial", out_dir=tmp_path, progress=False,
                         batch_size=batch)

    first = run(2)
    assert first.computed == 2 and (first.table.status == "ok").all()
    assert json.loads(next(p for p in (tmp_path / "cache").glob("*.json")).read_text())["batch"]
    assert run(2).cached == 2  # the same batch: reused
    single = run(None)  # one case at a time steps differently: not the same result, so not reused
    assert single.cached == 0 and single.computed == 2
    assert run(None).cached == 2
