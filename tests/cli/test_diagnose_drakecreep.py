"""``drakecreep diagnose`` on runs whose controller is the project's own cascade (kind: drakecreep)."""

import json

import numpy as np
import pytest

from drakecreep import cli
from drakecreep.gap.drake_replay import quick_replay_params, simulated_runs
from drakecreep.gap.measured import ControllerMeta, MeasuredData, MeasuredMeta, MeasuredRun, save_measured
from drakecreep.gap.truth import out_and_back
from drakecreep.params import load_params, preset, with_value

N = 1200


@pytest.fixture(scope="module")
def own_csv(tmp_path_factory):
    """Four out-and-back runs simulated by the project's diagram from their references, with a 2 um lead
    error the params file lacks, saved as CSV + metadata YAML (the params file beside them)."""
    folder = tmp_path_factory.mktemp("own")
    rig = quick_replay_params(preset("paper"))
    truth = with_value(rig, "disturbance.lead_error_amplitude", 2e-6)
    runs = simulated_runs(truth, (0.02, 0.03, 0.025, 0.035), declared=rig, n=500, noise=2.0, seed=7)
    meta = runs[0].meta
    path = folder / "own.csv"
    _, yaml_path = save_measured(MeasuredData(runs=tuple(runs), meta=meta), path)
    return path, yaml_path


@pytest.fixture(scope="module")
def blank_csv(tmp_path_factory):
    """Runs with the project's controller declared, not simulated (for checks that stop before any work; a u of
    zeros or of one value is refused at load, so any command that moves)."""
    folder = tmp_path_factory.mktemp("blank")
    meta = MeasuredMeta(u_units="N", u_gain=1.0, params=preset("rigid_axis"), controller=ControllerMeta(kind="drakecreep"))
    t = np.arange(N) * 1e-3
    runs = tuple(MeasuredRun(t=t, x_ref=out_and_back(v, 0.0, n=N, leg=0.45, starts=(0.05, 0.6)),
                             x_motor=out_and_back(v, 0.0, n=N, leg=0.45, starts=(0.05, 0.6)),
                             u=1.0 + 0.1 * np.sin(np.arange(N) * 0.01),
                             meta=meta, label=f"r{i}") for i, v in enumerate((0.02, 0.03, 0.025)))
    _, yaml_path = save_measured(MeasuredData(runs=runs, meta=meta), folder / "blank.csv")
    return folder / "blank.csv", yaml_path


def test_diagnose_with_the_projects_controller_runs_to_the_end(own_csv, tmp_path, capsys):
    path, _ = own_csv
    out = tmp_path / "diag"
    code = cli.main(["-q", "diagnose", str(path), "--train", "r0,r1", "--test", "r2,r3",
                     "--uncertain", "table.seal_force", "--effects", "lead_error,law_coulomb",
                     "--out", str(out), "--json", "--score", str(path)])
    assert code == 0
    result = json.loads(capsys.readouterr().out)
    assert result["kind"] == "drakecreep.drive_diagnosis"
    assert result["train_runs"] == ["r0", "r1"] and result["test_runs"] == ["r2", "r3"]
    assert result["claimed"] == ["lead_error"]  # the withheld effect, and nothing else
    note = [line for line in (out / "summary.txt").read_text().splitlines() if "two held-out runs" in line]
    assert len(note) == 1 and "6.31 standard errors" in note[0]  # the width of Student's bar on two runs, said
    augmented = load_params(out / "augmented_params.yaml")
    assert augmented.disturbance.lead_error_amplitude == pytest.approx(2e-6, rel=0.1)
    manifest = json.loads((out / "manifest.json").read_text())
    assert set(manifest["files"]) == {"augmented_params.yaml", "diagnosis.html", "diagnosis.json", "summary.txt",
                                      "nominal_params.yaml", "ranking.json"}
    # the report leads with the answer: the claim and the held-out force error params file -> fitted -> augmented
    html = (out / "diagnosis.html").read_text()
    answer = html[html.index("<h2>Answer</h2>"):html.index("<h2>Fitted params file fields")]
    errs = [f"{e:.3f} %" for e in (result["prior_test_errors"], result["nominal_test_errors"], result["test_errors"])
            for e in [float(np.sqrt(np.mean([v["force"] ** 2 for v in e.values()])))]]
    assert "Claimed: lead_error." in answer and all(e in answer for e in errs), answer
    assert "note: two held-out runs" in answer
    assert "table.seal_force" in html and "N</td>" in html  # the fitted field with its unit
    assert "disturbance.lead_error_amplitude = " in html and " um" in html  # a lead error in um at the edge
    assert html.count("<img") == 3 and "Unexplained: where" in html  # gains, errors by run, one run's residual
    # the candidates fitted only when named that did not run, with why they are not defaults
    assert list(result["not_run"]) == ["asymmetric_friction", "cogging", "position_friction", "drive_saturation",
                                       "backlash", "structural_mode", "friction_drift"]
    assert "<h2>Not run: candidates fitted only when named (--effects)</h2>" in html
    assert "<td>drive_saturation</td><td class=\"text\">not measured on the benchmark" in html
    # each candidate's pooled shrink also as a multiple of its run-to-run null (above 20 stands for the bar)
    (lead,) = [c for c in result["candidates"] if c["name"] == "lead_error"]
    nulls = lead["replay"]["shrink"] / result["replay_null"]
    assert f"({nulls:.1f} × null, " in html
    scored = result["scored"]["errors_percent"]  # the augmented params replayed, fixed, on the four runs
    assert set(scored) == {"r0", "r1", "r2", "r3"} and "(the augmented params, fixed)" in html
    assert f"<td>r1</td><td>{scored['r1']['position']:.4g}</td><td>{scored['r1']['force']:.4g}</td>" in html
    # the fitted params file before any claim: its seal force carries the missing lead error's bias (3.1 N), the
    # refit with the lead error comes back to the truth's (the params file's, 4.0 N)
    nominal, truth = load_params(out / "nominal_params.yaml"), quick_replay_params(preset("paper")).table.seal_force
    assert nominal.disturbance.lead_error_amplitude == 0.0
    assert abs(augmented.table.seal_force - truth) < 0.5 * abs(nominal.table.seal_force - truth)
    ranking = json.loads((out / "ranking.json").read_text())
    assert ranking["stage"] == "final" and ranking["complete"] is True and ranking["claimed"] == ["lead_error"]
    assert [c["name"] for c in ranking["candidates"]] == [c["name"] for c in result["candidates"]]


def test_a_late_failure_keeps_the_fitted_params_and_the_ranking_so_far(own_csv, tmp_path, capsys, monkeypatch):
    """A step after the candidates that fails (here the location of what is left, made to raise): the run exits 1
    with one line, no manifest claims a complete run, and the folder keeps the fitted params file and the ranking
    of the candidates (the issue: a failure late in the pipeline keeps what was computed). A candidate that fails
    (here the delay search) no longer ends the run: it is listed as failed, the others are ranked. The same command
    run again, the failure mended, resumes from the finished steps: it replays nothing more (no claim, so the
    nominal's held-out replays are the final model's) and writes the whole folder."""
    from drakecreep.gap import drive_fit

    def broken(*args, **kwargs):
        raise RuntimeError("the delay search broke")

    def lost(*args, **kwargs):
        raise RuntimeError("the location broke")

    locate = drive_fit.locate
    monkeypatch.setattr(drive_fit, "_delay_effect", broken)
    monkeypatch.setattr(drive_fit, "locate", lost)
    path, _ = own_csv
    out = tmp_path / "diag"
    command = ["diagnose", str(path), "--train", "r0,r1", "--test", "r2,r3", "--uncertain", "table.seal_force",
               "--effects", "nut_friction_side,control_delay", "--out", str(out)]
    code = cli.main(command)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and "the location broke" in err[-1] and "Traceback" not in "\n".join(err)
    assert any("nominal_params.yaml" in line for line in err)  # the progress says where it is kept
    assert "kept nominal_params.yaml and ranking.json in" in err[-3]
    assert err[-2].endswith(f"the finished steps are kept in {out / 'checkpoint.pkl'}: the same command resumes "
                            "from them")
    assert not (out / "manifest.json").exists()
    assert load_params(out / "nominal_params.yaml").table.seal_force > 0
    ranking = json.loads((out / "ranking.json").read_text())
    assert ranking["stage"] == "claims" and ranking["complete"] is False and ranking["claimed"] == []
    assert sorted(c["name"] for c in ranking["candidates"]) == ["control_delay", "nut_friction_side"]
    (delay,) = [c for c in ranking["candidates"] if c["name"] == "control_delay"]
    assert delay["reason"] == "failed (RuntimeError: the delay search broke)"
    assert any("control_delay failed (RuntimeError: the delay search broke)" in w for w in ranking["warnings"])
    assert ranking["replay_null"] is not None and ranking["train_runs"] == ["r0", "r1"]

    monkeypatch.setattr(drive_fit, "locate", locate)
    replays, original = [], drive_fit.replay_drakecreep
    monkeypatch.setattr(drive_fit, "replay_drakecreep", lambda *a, **k: replays.append(1) or original(*a, **k))
    assert cli.main(command) == 0
    err = capsys.readouterr().err
    assert "resumed from " in err and replays == []
    assert (out / "manifest.json").exists() and not (out / "checkpoint.pkl").exists()
    final = json.loads((out / "ranking.json").read_text())
    assert final["complete"] is True and final["replay_null"] == ranking["replay_null"]
    assert [c["name"] for c in final["candidates"]] == [c["name"] for c in ranking["candidates"]]


def test_uncertain_is_refused_for_p_p_cascade_runs(capsys):
    assert cli.main(["diagnose", "estimation", "--uncertain", "table.seal_force"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--uncertain" in err[0]


def test_unknown_uncertain_field_is_one_line_exit_2(own_csv, capsys):
    path, _ = own_csv
    assert cli.main(["diagnose", str(path), "--train", "r0,r1", "--test", "r2,r3",
                     "--uncertain", "table.colour"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--uncertain: got 'table.colour'" in err[0]  # the option, not the library's parameter
    # the line lists every field that can be fitted, the last one too (it was cut at 400 characters)
    from drakecreep.gap.drive_fit import FITTABLE

    assert all(f in err[0] for f in FITTABLE) and not err[0].endswith("...")


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


@pytest.fixture
def no_diagnosis(monkeypatch):
    """diagnose_drive made to fail: a refusal must come before it."""
    from drakecreep.gap import drive_fit

    def started(*args, **kwargs):
        raise AssertionError("the diagnosis started")

    monkeypatch.setattr(drive_fit, "diagnose_drive", started)


def test_a_score_file_of_the_p_p_cascade_kind_is_refused_before_the_diagnosis(blank_csv, no_diagnosis, capsys):
    """The EMPS example scored through the params file: it was replayed at the end, exit 0, force errors of 1e4 %."""
    from drakecreep.data import example_path

    path, _ = blank_csv
    code = cli.main(["diagnose", str(path), "--workers", "1", "--score", str(example_path("emps_segment.csv"))])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert "--score: got " in err[0] and "runs of controller kind drakecreep" in err[0]


def test_a_score_file_the_replay_refuses_is_refused_before_the_diagnosis(blank_csv, no_diagnosis, tmp_path, capsys):
    """A declared encoder count that is no whole fraction of the lead: the replay of the scored runs refused it
    after the whole diagnosis (its files written, exit 2); now before it, naming --score and the field."""
    import yaml

    path, yaml_path = blank_csv
    meta = yaml.safe_load(yaml_path.read_text())
    lead = preset("rigid_axis").screw.lead
    meta["sensors"] = {"encoder_resolution": lead / 300000.5, "scale_resolution": 0.0}
    score = tmp_path / "score.csv"
    score.write_text(path.read_text())
    score.with_suffix(".yaml").write_text(yaml.safe_dump(meta))
    out = tmp_path / "out"
    code = cli.main(["diagnose", str(path), "--workers", "1", "--score", str(score), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert f"--score {score}: sensors.encoder_resolution: got " in err[0] and "whole fraction of the lead" in err[0]
    assert not out.exists() or not any(out.iterdir())


def test_one_held_out_run_names_the_option(blank_csv, no_diagnosis, capsys):
    """One run held out: the library's 'test: got 1' named no option; now --test, as for p_p_cascade."""
    path, _ = blank_csv
    assert cli.main(["diagnose", str(path), "--workers", "1", "--train", "r0,r1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--test: got '1 run(s) of r0, r1, r2'" in err[0] and "at least two held-out runs" in err[0]
    assert cli.main(["diagnose", str(path), "--workers", "1", "--test", "r1"]) == 2
    assert "--test: got 'r1'" in capsys.readouterr().err


def test_nominal_friction_is_refused_for_drakecreep_runs(own_csv, capsys):
    path, _ = own_csv
    assert cli.main(["diagnose", str(path), "--nominal-friction", "lugre"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--nominal-friction" in err[0]


def test_help_describes_the_drakecreep_kind_and_what_it_writes(capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["diagnose", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert stop.value.code == 0
    assert "Runs of controller kind drakecreep" in out and "augmented_params.yaml (for simulate, margins" in out


def _refusal(frame, yaml_path, tmp_path, capsys):
    """Diagnose ``frame`` saved beside a copy of ``yaml_path``: the one line of a refusal (exit 2)."""
    bad = tmp_path / "bad.csv"
    frame.to_csv(bad, index=False)
    bad.with_suffix(".yaml").write_text(yaml_path.read_text())
    code = cli.main(["diagnose", str(bad), "--workers", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    return err[0]


@pytest.mark.parametrize("column, factor, says", [
    ("u", 1000.0, "at most 2 x the drive's force limit"),  # N data headed kN
    ("u", 1e-3, "at least 0.01 x the params file's Coulomb friction"),  # N data headed mN
    ("t", 1000.0, "at most 10 x the params file's position-loop period"),  # ms headed s: a replay 1000 x as long
])
def test_a_unit_slip_of_a_drakecreep_run_is_one_line_exit_2(blank_csv, tmp_path, capsys, column, factor, says):
    """The fuzzing helper's cases: N data headed kN hung, headed mN diagnosed to a 99075 % force error (exit 0),
    milliseconds headed seconds hung; now each is refused before any replay (diagnose_drive's checks), naming the
    column and the run. The blank file's references with a 50 N drive force (the rigid_axis preset: Coulomb
    friction 17.8 N, force limit 10.6 kN)."""
    import pandas as pd

    path, yaml_path = blank_csv
    frame = pd.read_csv(path)
    head = next(c for c in frame.columns if c.split("[")[0] == column)
    frame[head] = frame[head] * (50.0 if column == "u" else 1.0) * factor  # blank u: 1 N; a 50 N drive
    err = _refusal(frame, yaml_path, tmp_path, capsys)
    # named by the file too, as every other check ('u (run r0): got ...' alone did not say which file)
    assert f"error: {tmp_path / 'bad.csv'}: {column} (run r0): got " in err and says in err


def test_a_run_that_puts_the_nut_off_the_screw_is_one_line_exit_2(blank_csv, tmp_path, capsys):
    """A run's positions are the params file's table coordinates and the replay puts the nut where the run was
    (docs 3cb): positions 2 m along the rigid_axis preset's shaft are refused before any replay, with the range."""
    import pandas as pd

    path, yaml_path = blank_csv
    frame = pd.read_csv(path)
    frame["u[N]"] = frame["u[N]"] * 50.0  # a 50 N drive (blank u: 1 N)
    for column in ("x_ref[m]", "x_motor[m]"):
        frame[column] = frame[column] + 2.0
    err = _refusal(frame, yaml_path, tmp_path, capsys)
    screw = preset("rigid_axis").screw
    assert f"error: {tmp_path / 'bad.csv'}: x_motor (run r0): got 'positions from 2 to " in err, err
    assert f"between {-screw.nut_start_distance:g} and {screw.length - screw.nut_start_distance:g} m" in err, err


def test_positions_in_the_wrong_unit_are_refused_by_their_inverse_dynamics_mass(own_csv, tmp_path, capsys):
    """Positions in m headed mm (found by fuzzing: exit 0 after 74 s, a 101 % force error, a viscous coefficient of
    1.1e4 N s/m and a force ripple claimed for a lead error): the travel checks pass, every position being 1000 x
    short, but the drive force then accelerates a mass 1000 x the params file's. The file as simulated reads its
    own mass within 30 %."""
    import math

    import pandas as pd

    from drakecreep.gap.drive_fit import inverse_dynamics_mass
    from drakecreep.gap.measured import load_measured
    from drakecreep.model.compensators import rigid_inertia

    path, yaml_path = own_csv
    data = load_measured(path)
    params = data.meta.params
    rigid = rigid_inertia(params) * (2.0 * math.pi / params.screw.lead) ** 2
    masses = [inverse_dynamics_mass(r) for r in data.runs]
    assert all(m is not None and abs(m / rigid - 1.0) < 0.3 for m in masses), (masses, rigid)
    frame = pd.read_csv(path)
    for column in frame.columns:
        if column.split("[")[0] in ("x_ref", "x_motor", "x_table"):
            frame[column] = frame[column] * 1e-3
    err = _refusal(frame, yaml_path, tmp_path, capsys)
    assert "bad.csv: x_motor (run " in err and "an inverse-dynamics mass of " in err and "within a factor of 10" in err
