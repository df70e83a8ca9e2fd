import importlib.util
import json

import pytest

from drakecreep import cli
from drakecreep.data import example_path
from drakecreep.gap.measured import load_measured, save_measured

EXAMPLE = example_path("emps_segment.csv")  # t[ms], x[mm], u[V]


def _diagnose(capsys, *args):
    assert cli.main(["-q", "diagnose", *map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_csv_in_mm_and_ms_gives_the_si_result(tmp_path, capsys):
    header = [line for line in EXAMPLE.read_text().splitlines() if not line.startswith("#")][0]
    assert "[ms]" in header and "[mm]" in header
    si_csv, _ = save_measured(load_measured(EXAMPLE), tmp_path / "emps_segment.csv")
    assert si_csv.read_text().splitlines()[0].startswith("t[s],x_ref[m],x_motor[m]")
    opts = ("--train", "0", "--test", "1,2", "--effects", "thermal_drift")
    shop, si = _diagnose(capsys, EXAMPLE, *opts), _diagnose(capsys, si_csv, *opts)
    for key in ("claimed", "train_runs", "test_runs"):
        assert shop[key] == si[key]
    assert [r["effect"] for r in shop["ranking"]] == [r["effect"] for r in si["ranking"]]
    for name, value in shop["nominal"]["parameters"].items():
        assert value == pytest.approx(si["nominal"]["parameters"][name], rel=1e-9, abs=1e-9), name


def test_missing_metadata_names_the_option(tmp_path, capsys):
    (tmp_path / "run.csv").write_text("t,x_ref,x_motor,u\n0,0,0,0\n")
    assert cli.main(["diagnose", str(tmp_path / "run.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--meta" in err[0] and "meta_path" not in err[0]


def test_bad_run_selection_names_the_option(capsys):
    assert cli.main(["diagnose", str(EXAMPLE), "--test", "r9"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("drakecreep diagnose: error: --test: got 'r9'")


@pytest.mark.parametrize("rows", [300, 1500])
def test_a_run_too_short_to_split_says_how_many_parts_it_gives(tmp_path, rows, capsys):
    lines = EXAMPLE.read_text().splitlines()
    body = [line for line in lines if not line.startswith("#")]
    (tmp_path / "short.csv").write_text("\n".join(body[: rows + 1]) + "\n")
    (tmp_path / "short.yaml").write_text(EXAMPLE.with_suffix(".yaml").read_text())
    assert cli.main(["diagnose", str(tmp_path / "short.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("drakecreep diagnose: error: DATA short.csv: ")
    assert f"one run of {rows} samples" in err[0] and "at least 3 parts" in err[0]


@pytest.mark.parametrize("suffix, what", [(".parquet", "Parquet"), (".h5", "HDF5"), (".mat", "MATLAB")])
def test_a_corrupt_binary_file_is_one_line_exit_2(tmp_path, suffix, what, capsys):
    path = tmp_path / f"rig{suffix}"
    path.write_bytes({".h5": b"\x89HDF\r\n\x1a\n" + bytes(100)}.get(suffix, b"\x00\x01garbage" * 50))
    (tmp_path / "rig.yaml").write_text(EXAMPLE.with_suffix(".yaml").read_text())
    assert cli.main(["diagnose", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    if suffix == ".h5" and importlib.util.find_spec("tables") is None:  # HDF5 is optional: say what to install
        assert len(err) == 1 and "needs the 'tables' package" in err[0]
        return
    assert len(err) == 1 and f"not a readable {what} file" in err[0]


def test_one_training_run_has_no_null_so_the_level_test_alone_claims_nothing(capsys):
    """The example segment's default split has one training run, so no training-run null: the control delay,
    whose error with each run's own friction level shrinks significantly (+0.011 against a bar of 0.005) while
    the plain one barely moves (+0.005), is not claimed (``drift_robust`` needs the null as the plain mean's
    bar; it claimed this before the fix)."""
    out = _diagnose(capsys, EXAMPLE, "--effects", "control_delay")
    assert out["claimed"] == []
    (row,) = [r for r in out["ranking"] if r["effect"] == "control_delay"]
    loop = row["closed_loop"]
    assert loop["level_log_error_ratio"] > loop["threshold_level_log_error_ratio"]  # the level test passes
    assert not loop["level_test_alone"]
