"""``drakecreep emps`` through drakecreep.cli.main."""

import importlib.util
import json

import pytest

import drakecreep.cli as cli
from drakecreep.gap.measured import emps_data_dir

EMPS = emps_data_dir()


@pytest.fixture(autouse=True)
def _only_importable_commands(monkeypatch):
    # other subcommands are being written concurrently; register the ones that exist
    present = [c for c in cli.COMMANDS if importlib.util.find_spec(f"drakecreep.cli.{c}")]
    monkeypatch.setattr(cli, "COMMANDS", present)


def test_missing_data_folder_is_a_one_line_error(capsys, tmp_path):
    assert cli.main(["emps", "--data", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "DATA_EMPS.mat and DATA_EMPS_PULSES.mat" in err


def test_json(capsys):
    assert cli.main(["emps", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["idim"]["params"]["M"] == pytest.approx(95.1089, rel=0.01)
    assert out["replay"]["validation"]["published"]["force"] == 8.94
