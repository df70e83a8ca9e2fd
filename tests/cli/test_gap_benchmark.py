import json

import pytest

from drakecreep import cli


def test_gap_benchmark_json(capsys):
    assert cli.main(["gap-benchmark", "--n", "1", "--seed", "4", "--no-replay", "--json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert data["scores"]["n_datasets"] == 1
    row = data["datasets"][0]
    assert row["seed"] == 4 and "hidden" in row and "claimed" in row
    assert "[gap-benchmark] 1/1" in captured.err


def test_gap_benchmark_rejects_zero(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["gap-benchmark", "--n", "0"])
    assert exc.value.code == 2
    assert "must be >= 1" in capsys.readouterr().err
