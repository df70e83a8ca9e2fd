import json

import numpy as np
import pytest

from drakecreep import cli
from drakecreep.gap.effects import EffectContext, get_effect, synthesize_run
from drakecreep.gap.benchmark import out_and_back
from drakecreep.gap.measured import EMPS_CONTROLLER, MeasuredData, MeasuredMeta, SensorMeta, save_measured
from drakecreep.gap.replay import RigidModel

META = MeasuredMeta(u_units="V", u_gain=35.15, controller=EMPS_CONTROLLER, sensors=SensorMeta(encoder_resolution=5e-8))
T = np.arange(3000) * 1e-3


@pytest.fixture(scope="module")
def csv_file(tmp_path_factory):
    model = RigidModel(M=90.0, Fv=200.0, Fc=20.0, offset=0.0)
    term = get_effect("asymmetric_friction").replay_term([-50.0], None, EffectContext(), {})
    rng = np.random.default_rng(2)
    runs = tuple(synthesize_run(T, out_and_back(v, 0.01), META, model, [term], force_noise=rng.normal(0, 0.5, T.size),
                                label=f"r{i}") for i, v in enumerate((0.02, 0.03, 0.06, 0.08)))
    path = tmp_path_factory.mktemp("csv") / "runs.csv"
    save_measured(MeasuredData(runs=runs, meta=META), path)
    return path


def test_diagnose_csv_writes_report_and_json(csv_file, tmp_path, capsys):
    out = tmp_path / "rep"
    assert cli.main(["diagnose", str(csv_file), "--train", "r0,r2", "--test", "r1,r3", "--screw-lead", "5",
                     "--out", str(out), "--json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert data["claimed"][0] == "asymmetric_friction"
    assert data["train_runs"] == ["r0", "r2"] and data["test_runs"] == ["r1", "r3"]
    assert {"where", "ranking", "unexplained_share"} <= set(data)
    assert "[diagnose]" in captured.err  # progress on stderr
    assert (out / "diagnosis.html").read_text().count("data:image/png;base64,") >= 5
    assert json.loads((out / "diagnosis.json").read_text())["claimed"] == data["claimed"]


def test_diagnose_text_and_score(csv_file, capsys):
    assert cli.main(["diagnose", str(csv_file), "--score", str(csv_file)]) == 0
    out = capsys.readouterr().out
    assert "Best explanation: asymmetric_friction" in out
    assert "Scored on" in out


def test_bad_run_label_is_a_one_line_error(csv_file, capsys):
    assert cli.main(["diagnose", str(csv_file), "--train", "nope"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nope" in err[0]


def test_overlapping_sets_are_refused(csv_file, capsys):
    assert cli.main(["diagnose", str(csv_file), "--train", "r0,r1", "--test", "r1"]) == 2


def test_missing_file(tmp_path, capsys):
    assert cli.main(["diagnose", str(tmp_path / "absent.csv")]) == 2
