"""Sweeps: expansion, cache resume, atomic writes, executors agree, a killed Dask worker, the CLI."""

import json
import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from drakecreep.cli import main
from drakecreep.errors import InputError
from drakecreep.params import preset
from drakecreep.report.plots import plot_stability_map
from drakecreep.files import write_atomic
from drakecreep.sim.sweep import case_key, grid, make_cases, random_sample, run_sweep

SHORT = dict(duration=1.2, load_case=3)  # metrics window 1.0-1.2 s: cheap cases that still have metrics


@pytest.fixture(scope="module")
def base():
    return preset("paper")


def test_grid_is_the_cartesian_product_first_axis_slowest():
    points = grid({"nut.axial_stiffness": [1e7, 2e7], "feed": [1e-3, 2e-3, 3e-3]})
    assert len(points) == 6
    assert points[0] == {"nut.axial_stiffness": 1e7, "feed": 1e-3}
    assert points[1] == {"nut.axial_stiffness": 1e7, "feed": 2e-3}
    assert points[3] == {"nut.axial_stiffness": 2e7, "feed": 1e-3}
    assert grid({}) == [{}]
    with pytest.raises(InputError, match="axes.feed"):
        grid({"feed": []})


def test_a_grid_axis_with_a_value_twice_is_refused_naming_it():
    with pytest.raises(InputError, match=r"axes\.feed: .*distinct values \(0\.001 is there twice\)"):
        grid({"nut.axial_stiffness": [1e7], "feed": [1e-3, 2e-3, 1e-3]})
    with pytest.raises(InputError, match="axes.load_case"):
        grid({"load_case": [1, 1.0]})  # equal values in two types
    with pytest.raises(InputError, match=r"axes\.x: .*\[1\] is there twice"):
        grid({"x": [[1], [2], [1]]})  # unhashable values too
    assert len(grid({"x": [[1], [2]], "feed": [1e-3, 2e-3]})) == 4


def test_random_sample_is_seeded_and_within_bounds():
    axes = {"nut.axial_stiffness": {"low": 1e6, "high": 1e8, "scale": "log"},
            "load_case": {"low": 1, "high": 3}, "friction.law": ["lugre", "stribeck"]}
    a, b = random_sample(axes, 50, seed=3), random_sample(axes, 50, seed=3)
    assert a == b
    assert a != random_sample(axes, 50, seed=4)
    k = np.array([p["nut.axial_stiffness"] for p in a])
    assert k.min() >= 1e6 and k.max() <= 1e8
    # log-uniform: about half the points below the geometric mean 1e7
    assert 10 < (k < 1e7).sum() < 40
    assert {p["load_case"] for p in a} == {1, 2, 3}
    assert {p["friction.law"] for p in a} == {"lugre", "stribeck"}
    with pytest.raises(InputError, match="axes.x.low"):
        random_sample({"x": {"low": 0.0, "high": 1.0, "scale": "log"}}, 3)


@pytest.mark.parametrize("low, high", [(0, 10**23), (-10**23, 3), (0, 2**63), (-2**63 - 1, 0)])
def test_random_integer_bounds_beyond_64_bits_are_named(low, high):
    # 'internal error: ValueError: high is out of bounds for int64', exit 1 (found by the fifth fuzzing pass)
    with pytest.raises(InputError, match=r"^axes\.friction\.gms_elements: got .*; allowed: integer bounds low <= high "
                                         r"in \[-2\^63, 2\^63\)"):
        random_sample({"friction.gms_elements": {"low": low, "high": high}}, 2)
    assert {p["x"] for p in random_sample({"x": {"low": 2**63 - 2, "high": 2**63 - 1}}, 20)} == {2**63 - 2, 2**63 - 1}


def test_cases_validate_and_keys_follow_the_full_parameters(base):
    cases = make_cases(base, [{"feed": 1e-3}, {"feed": 2e-3}, {"feed": 1e-3}], SHORT)
    assert cases[0].key == cases[2].key != cases[1].key
    assert cases[1].scenario.feed == 2e-3 and cases[1].scenario.duration == 1.2
    # a change anywhere in the parameters changes the key, even a field no axis names
    other = make_cases(base.__class__(**{**base.__dict__, "table": base.table.__class__(mass=41.0)}),
                       [{"feed": 1e-3}], SHORT)
    assert other[0].key != cases[0].key
    with pytest.raises(InputError, match="nut.axial_stiffness"):
        make_cases(base, [{"nut.axial_stiffness": -1.0}], SHORT)
    with pytest.raises(InputError, match="load_case"):
        make_cases(base, [{"load_case": 9}], SHORT)
    assert case_key(base, cases[0].scenario, "a") != case_key(base, cases[0].scenario, "b")


def test_write_atomic_leaves_the_old_file_when_the_writer_fails(tmp_path):
    target = tmp_path / "t.json"
    write_atomic(target, lambda tmp: Path(tmp).write_text('{"v": 1}'))

    def broken(tmp):
        with open(tmp, "w") as fh:
            fh.write('{"v": 2, "trunc')
        raise OSError("disk full")

    with pytest.raises(OSError):
        write_atomic(target, broken)
    assert json.loads(target.read_text()) == {"v": 1}
    assert [p.name for p in tmp_path.iterdir()] == ["t.json"]  # no temporary file left behind


def test_cache_resume_computes_only_the_missing_cases(base, tmp_path):
    points = grid({"feed": [0.3e-3, 1e-3, 3e-3]})
    first = run_sweep(base, points[:2], scenario=SHORT, executor="serial", out_dir=tmp_path, progress=False)
    assert (first.computed, first.cached) == (2, 0)
    # an interrupted sweep: two of three cases on disk; the rerun computes only the third
    second = run_sweep(base, points, scenario=SHORT, executor="serial", out_dir=tmp_path, progress=False)
    assert (second.computed, second.cached) == (1, 2)
    third = run_sweep(base, points, scenario=SHORT, executor="serial", out_dir=tmp_path, progress=False)
    assert (third.computed, third.cached) == (0, 3)
    assert third.table.equals(second.table)
    assert len(list((tmp_path / "cache").glob("*.json"))) == 3
    import pandas as pd

    parquet = pd.read_parquet(tmp_path / "results.parquet")
    assert list(parquet["feed"]) == [0.3e-3, 1e-3, 3e-3]
    assert (parquet["status"] == "ok").all()
    assert not list(tmp_path.glob(".*.tmp"))


def test_a_ctrl_c_during_a_cache_write_still_caches_the_finished_case(base, tmp_path, monkeypatch):
    """The Ctrl-C lands while a finished case's cache file is written: the case is in the table as ok, and its
    cache file is written before the sweep stops (a rerun does not compute it again)."""
    from drakecreep.sim import sweep

    real = sweep.write_json
    calls = []

    def interrupted_once(path, payload):
        calls.append(path)
        if len(calls) == 1:
            raise KeyboardInterrupt
        return real(path, payload)

    monkeypatch.setattr(sweep, "write_json", interrupted_once)
    points = grid({"feed": [0.3e-3, 1e-3]})
    with pytest.raises(KeyboardInterrupt):
        run_sweep(base, points, scenario=SHORT, executor="serial", out_dir=tmp_path, progress=False)
    import pandas as pd

    table = pd.read_csv(tmp_path / "results.csv")
    assert list(table.status) == ["ok", "not run (interrupted)"]
    assert len(list((tmp_path / "cache").glob("*.json"))) == 1
    monkeypatch.setattr(sweep, "write_json", real)
    again = run_sweep(base, points, scenario=SHORT, executor="serial", out_dir=tmp_path, progress=False)
    assert (again.computed, again.cached) == (1, 1)


def test_serial_and_processes_give_the_same_table(base):
    points = grid({"nut.axial_stiffness": [10e6, 50e6], "feed": [0.2e-3, 1e-3]})
    serial = run_sweep(base, points, scenario=SHORT, executor="serial", progress=False)
    procs = run_sweep(base, points, scenario=SHORT, executor="processes", workers=2, progress=False)
    drop = ["wall_time_s"]
    assert serial.table.drop(columns=drop).equals(procs.table.drop(columns=drop))
    assert serial.table["creep"].any() and not serial.table["creep"].all()  # the map has both regimes


def _worker_pids(client):
    return set(client.run(os.getpid).values())


def test_dask_sweep_survives_a_killed_worker(base, tmp_path):
    distributed = pytest.importorskip("distributed")
    points = grid({"feed": list(np.geomspace(0.2e-3, 2e-3, 12))})
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=50) as cluster, distributed.Client(cluster) as client:
        pids = client.run(os.getpid)  # worker address -> pid
        before = set(pids.values())
        victim_address, victim = sorted(pids.items())[0]
        box = {}
        thread = threading.Thread(target=lambda: box.update(result=run_sweep(
            base, points, scenario=dict(duration=1.5, load_case=3), executor="dask", scheduler=client,
            out_dir=tmp_path, progress=False)))
        thread.start()
        deadline = time.time() + 60
        in_flight = []
        while time.time() < deadline:  # wait until a case is done and the victim is running another
            in_flight = list(client.processing().get(victim_address, ()))
            if in_flight and list((tmp_path / "cache").glob("*.json")):
                break
            time.sleep(0.02)
        done_before_kill = len(list((tmp_path / "cache").glob("*.json")))
        os.kill(victim, signal.SIGKILL)  # mid-sweep, with a case of its own in flight
        thread.join(120)
        assert not thread.is_alive()
        result = box["result"]
        assert 1 <= done_before_kill < len(points) and in_flight
        assert victim in before and victim not in _worker_pids(client)  # the worker really died (the nanny started a new one)
    table = result.table
    assert len(table) == len(points) and (table["status"] == "ok").all()
    assert result.failed == 0 and result.computed == len(points)
    assert len(list((tmp_path / "cache").glob("*.json"))) == len(points)


def test_cli_sweep_smoke_and_bad_spec(tmp_path, capsys):
    spec = tmp_path / "spec.yaml"
    spec.write_text(
        "base: {preset: paper}\n"
        "scenario: {load_case: 3, duration: 1.2}\n"
        "axes:\n"
        "  feed: [0.5e-3, 2.0e-3]\n"
        "metrics: [fluctuation_rate_percent, creep]\n"
    )
    out = tmp_path / "out"
    assert main(["sweep", str(spec), "--workers", "1", "--out", str(out), "--no-progress"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["cases"] == 2 and summary["computed"] == 2
    import pandas as pd

    table = pd.read_csv(out / "results.csv")
    assert list(table.columns[-3:]) == ["status", "fluctuation_rate_percent", "creep"]

    bad = tmp_path / "bad.yaml"
    bad.write_text("base: {preset: paper}\naxes:\n  nut.no_such_field: [1, 2]\n")
    assert main(["sweep", str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nut.no_such_field" in err[0]
    # a misspelt axis that the plot names correctly is reported as the unknown path, not as a plot mismatch
    bad.write_text("base: {preset: paper}\naxes:\n  nut.axial_stifness: [5e7, 1e8]\n"
                   "plot: {x: nut.axial_stiffness}\n")
    assert main(["sweep", str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nut.axial_stifness: got" in err[0] and "plot" not in err[0]
    bad.write_text("base: {preset: paper}\naxes: {feed: [1e-3]}\nmetrics: [no_metric]\n")
    assert main(["sweep", str(bad), "--out", str(out)]) == 2
    assert "metrics" in capsys.readouterr().err


def test_stability_map_draws_the_analytic_curve(base, tmp_path):
    import pandas as pd

    table = pd.DataFrame(dict(**{"nut.axial_stiffness": [1e7, 1e7, 5e7, 5e7]}, feed=[1e-4, 1e-3, 1e-4, 1e-3],
                              load_case=3, fluctuation_rate_percent=[80.0, 0.1, 90.0, 0.1],
                              creep=[True, False, True, False]))
    path = plot_stability_map(table, "nut.axial_stiffness", tmp_path / "map.png", base=base)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(InputError, match="column"):
        plot_stability_map(table, "nope", tmp_path / "x.png")
