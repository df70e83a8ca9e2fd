import json

import pytest

from drakecreep import cli
from drakecreep.data import example_path
from drakecreep.gap.measured import load_measured, save_measured


def _diagnose(capsys, *args):
    assert cli.main(["diagnose", *map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_csv_in_mm_and_ms_gives_the_si_result(tmp_path, capsys):
    si_csv, _ = save_measured(load_measured(example_path("measured_mm_ms.csv")), tmp_path / "si.csv")
    assert si_csv.read_text().splitlines()[0] == "t[s],x_ref[m],x_motor[m],u[V],run"
    mm = _diagnose(capsys, "example")
    si = _diagnose(capsys, si_csv)
    assert mm["claimed"][0] == "asymmetric_friction"  # the effect the example was synthesised with
    for key in ("claimed", "train_runs", "test_runs"):
        assert mm[key] == si[key]
    assert [r["effect"] for r in mm["ranking"]] == [r["effect"] for r in si["ranking"]]
    assert mm["unexplained_share"] == pytest.approx(si["unexplained_share"], rel=1e-9)


def test_help_points_to_the_format_doc(capsys):
    with pytest.raises(SystemExit):
        cli.main(["diagnose", "--help"])
    assert "docs/measured_format.md" in capsys.readouterr().out


def test_missing_metadata_names_the_option(tmp_path, capsys):
    (tmp_path / "run.csv").write_text("t,x_ref,x_motor,u\n0,0,0,0\n")
    assert cli.main(["diagnose", str(tmp_path / "run.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--meta" in err[0] and "meta_path" not in err[0]


def test_bad_run_selection_names_the_option(capsys):
    assert cli.main(["diagnose", "example", "--test", "r9"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("drakecreep diagnose: error: --test: got 'r9'")
