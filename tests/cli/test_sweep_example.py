import json
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from drakecreep import cli
from drakecreep.sim.sweep import load_spec

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "sweep_stiffness.yaml"


def test_spec_numbers_like_5e6_are_floats(tmp_path):
    assert isinstance(yaml.safe_load("k: 5.0e6")["k"], str)  # why one loader: plain YAML 1.1 reads a string
    spec = tmp_path / "spec.yaml"
    spec.write_text("axes:\n  nut.axial_stiffness: [5.0e6, 1e8]\n  feed: {start: 1e-4, stop: 1.0e-3, num: 2}\n")
    points = load_spec(spec).points
    assert [p["nut.axial_stiffness"] for p in points[::2]] == [5.0e6, 1e8]
    assert {p["feed"] for p in points} == {1e-4, 1e-3}


def test_shipped_sweep_example_runs_and_its_table_reads_with_pandas(tmp_path, capsys):
    out = tmp_path / "sweep"
    assert cli.main(["sweep", str(EXAMPLE), "--out", str(out), "--workers", "1", "--no-progress"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["cases"] == 6 and summary["failed"] == 0
    table = pd.read_parquet(out / "results.parquet")
    assert table["nut.axial_stiffness"].dtype == float
    csv = pd.read_csv(out / "results.csv")
    assert list(csv.columns) == list(table.columns)
    np.testing.assert_allclose(csv["fluctuation_rate_percent"], table["fluctuation_rate_percent"], rtol=1e-12)
    slow, fast = table[table["feed"] == 0.05e-3], table[table["feed"] == 0.5e-3]
    assert len(slow) == len(fast) == 3
    assert slow["creep"].all() and not fast["creep"].any()  # the map has both regions
    assert Path(summary["map"]).stat().st_size > 10_000
