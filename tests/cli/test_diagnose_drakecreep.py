"""``drakecreep diagnose`` on runs whose controller is the project's own cascade (kind: drakecreep)."""

import dataclasses
import os

import numpy as np
import pytest

from drakecreep import cli
from drakecreep.gap.benchmark import out_and_back
from drakecreep.gap.drake_replay import replay_drakecreep
from drakecreep.gap.measured import ControllerMeta, MeasuredData, MeasuredMeta, MeasuredRun, save_measured
from drakecreep.params import preset, save_params  # noqa: F401

N = 1200


@pytest.fixture(scope="module")
def own_csv(tmp_path_factory):
    """Four out-and-back runs simulated by the project's diagram (rigid_axis preset) from their references."""
    folder = tmp_path_factory.mktemp("own")
    p = preset("rigid_axis")
    save_params(p, folder / "rig.yaml")
    meta = MeasuredMeta(u_units="N", u_gain=1.0, params=p, controller=ControllerMeta(kind="drakecreep"))
    t = np.arange(N) * 1e-3
    runs = []
    for i, v in enumerate((0.02, 0.03, 0.025, 0.035)):
        x_ref = out_and_back(v, 0.0, n=N, leg=0.45, starts=(0.05, 0.6))
        blank = MeasuredRun(t=t, x_ref=x_ref, x_motor=x_ref, u=np.zeros(N), meta=meta, label=f"r{i}")
        sim = replay_drakecreep(blank)
        noise = np.random.default_rng(i).normal(0.0, 2.0, N)
        runs.append(dataclasses.replace(blank, x_motor=sim.x_motor, u=sim.u + noise, x_table=sim.x_table))
    path = folder / "own.csv"
    _, yaml_path = save_measured(MeasuredData(runs=tuple(runs), meta=meta), path)
    return path, yaml_path


@pytest.fixture(scope="module")
def blank_csv(tmp_path_factory):
    """Runs with the project's controller declared, not simulated (for checks that stop before any work)."""
    folder = tmp_path_factory.mktemp("blank")
    meta = MeasuredMeta(u_units="N", u_gain=1.0, params=preset("rigid_axis"), controller=ControllerMeta(kind="drakecreep"))
    t = np.arange(N) * 1e-3
    runs = tuple(MeasuredRun(t=t, x_ref=out_and_back(v, 0.0, n=N, leg=0.45, starts=(0.05, 0.6)),
                             x_motor=out_and_back(v, 0.0, n=N, leg=0.45, starts=(0.05, 0.6)), u=np.zeros(N),
                             meta=meta, label=f"r{i}") for i, v in enumerate((0.02, 0.03)))
    _, yaml_path = save_measured(MeasuredData(runs=runs, meta=meta), folder / "blank.csv")
    return folder / "blank.csv", yaml_path


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("DRAKECREEP_SLOW"),
                    reason="about 5 minutes on 2 shared cores (leaf-system replays); set DRAKECREEP_SLOW=1")
def test_diagnose_with_the_projects_controller_runs_to_the_end(own_csv, capsys):
    path, _ = own_csv
    assert cli.main(["diagnose", str(path)]) == 0
    out = capsys.readouterr().out
    assert "drakecreep diagram" in out


def test_diagnose_without_params_for_kind_drakecreep_is_one_line_exit_2(blank_csv, tmp_path, capsys):
    path, yaml_path = blank_csv
    import yaml

    meta = yaml.safe_load(yaml_path.read_text())
    meta.pop("params")
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(meta))
    assert cli.main(["diagnose", str(path), "--meta", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "params" in err[0]
