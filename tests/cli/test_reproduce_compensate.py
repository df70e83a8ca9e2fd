import json

from drakecreep.cli import main


def test_reproduce_paper_json_gives_the_six_rows(tmp_path, capsys):
    assert main(["reproduce-paper", "--out", str(tmp_path), "--json", "--no-critical", "--no-plots"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["rows"]) == 6
    for row in out["rows"]:
        assert {"load_case", "feed_mm_s", "experiment_mm_s", "paper_sim_mm_s", "ours_mm_s", "calibrated"} <= set(row)
    assert [r["row"] for r in out["rows"] if r["calibrated"]] == [4, 6]
    assert (tmp_path / "table8_9.md").exists() and (tmp_path / "table8_9.csv").exists()


def test_reproduce_paper_bad_calibration_rows_exit_2(tmp_path, capsys):
    assert main(["reproduce-paper", "--out", str(tmp_path), "--calibrate", "3,5"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    # one line naming the option (the library's parameter, calibration_rows, was named before 21dcdc5)
    assert len(err) == 1 and "--calibrate: got '3,5'; allowed: two rows of [1, 2, 3, 4, 5, 6] from different experiments" in err[0]


def test_reproduce_paper_sensitivity_needs_validate_exit_2_before_work(tmp_path, capsys):
    assert main(["reproduce-paper", "--out", str(tmp_path / "o"), "--sensitivity"]) == 2
    err = capsys.readouterr().err
    assert "--sensitivity" in err and "--validate" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_compensate_json(tmp_path, capsys):
    argv = ["compensate", "--method", "lugre", "--feeds", "1", "--load-cases", "3", "--duration", "0.8",
            "--workers", "1", "--out", str(tmp_path), "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert [r["method"] for r in out["rows"]] == ["none", "lugre"]
    assert (tmp_path / "summary.md").exists() and (tmp_path / "comparison.png").exists()


def test_compensate_bad_arguments_exit_2(tmp_path, capsys):
    assert main(["compensate", "--feeds", "abc", "--out", str(tmp_path)]) == 2
    assert main(["compensate", "--load-cases", "9", "--out", str(tmp_path)]) == 2
    assert "--load-cases" in capsys.readouterr().err


def test_reproduce_paper_checks_out_before_the_calibration(tmp_path, capsys, monkeypatch):
    """--out on an existing file said 'File exists: afile' after the calibration (48 s); a missing --params file
    'No such file or directory: nothere.yaml'. Both name their option now, before any work."""
    from drakecreep.studies import paper_reproduction

    def started(*args, **kwargs):
        raise AssertionError("the calibration started")

    monkeypatch.setattr(paper_reproduction, "calibrate", started)
    (tmp_path / "afile").write_text("")
    assert main(["reproduce-paper", "--out", str(tmp_path / "afile"), "--calibrate", "4,6"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--out: got " in err[0] and "a folder (this is an existing file)" in err[0]
    assert main(["reproduce-paper", "--out", str(tmp_path / "o"), "--params", str(tmp_path / "nothere.yaml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--params: got " in err[0]


def test_reproduce_paper_names_a_params_file_without_the_papers_load_cases(tmp_path, capsys, monkeypatch):
    """A params file with two load cases said 'load_case: got 3; allowed: an integer in 0..2' (a library field)."""
    import dataclasses

    from drakecreep.params import preset, save_params
    from drakecreep.studies import paper_reproduction

    def started(*args, **kwargs):
        raise AssertionError("the rows started")

    monkeypatch.setattr(paper_reproduction, "write_report", started)
    p = preset("paper")
    path = tmp_path / "two.yaml"
    save_params(dataclasses.replace(p, loads=dataclasses.replace(p.loads, cases=p.loads.cases[:2])), path)
    assert main(["reproduce-paper", "--out", str(tmp_path / "o"), "--params", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--params: got " in err[0] and "the paper's load cases 1-3 (loads.cases; it has 2)" in err[0]


def test_a_params_file_is_scored_on_every_row_as_a_prediction(tmp_path, capsys):
    """Rows 4 and 6 of a params file were marked 'calibrated', and left out of the worst predicted error, on a
    model fitted to none of them; with --preset paper the JSON said 'predicted' where the written table said
    'calibrated'. The rows a model was fitted to are known for the paper_calibrated preset and --calibrate only."""
    from drakecreep.params import preset, save_params

    save_params(preset("paper_calibrated"), tmp_path / "p.yaml")
    assert main(["reproduce-paper", "--params", str(tmp_path / "p.yaml"), "--no-critical", "--no-plots", "--json",
                 "--out", str(tmp_path / "o")]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [r["calibrated"] for r in out["rows"]] == [False] * 6
    table = (tmp_path / "o" / "table8_9.md").read_text()
    assert "| calibrated |" not in table and table.count("| predicted |") == 6
    import pandas as pd

    assert not pd.read_csv(tmp_path / "o" / "table8_9.csv")["calibrated"].any()
