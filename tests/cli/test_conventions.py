"""CLI conventions: --version, help without reStructuredText markup, the shipped measured example."""

import json
import re

import numpy as np
import pytest

from drakecreep import __version__, cli
from drakecreep.data import data_dir
from drakecreep.gap.measured import load_emps, load_measured

EXAMPLE = data_dir() / "examples" / "emps_segment.csv"


def test_version(capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["--version"])
    assert exit_.value.code == 0 and capsys.readouterr().out.strip() == f"drakecreep {__version__}"


@pytest.mark.parametrize("command", cli.COMMANDS)
def test_help_has_no_restructuredtext_markup(command, capsys):
    with pytest.raises(SystemExit):
        cli.main([command.replace("_", "-"), "--help"])
    text = capsys.readouterr().out
    assert text.startswith("usage:")
    assert "``" not in text and not re.search(r":(func|class|mod|data|attr):", text)


def test_diagnose_help_lists_every_ranked_effect(capsys):
    from drakecreep.gap.drake_effects import DRAKE_EFFECTS

    with pytest.raises(SystemExit):
        cli.main(["diagnose", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for name in tuple(DRAKE_EFFECTS) + ("control_delay",):
        assert name in text, name


def test_the_shipped_example_is_the_emps_estimation_file_in_shop_units():
    example = load_measured(EXAMPLE).runs[0]
    emps = load_emps("estimation").runs[0]
    n = example.t.size
    assert n == 8000
    np.testing.assert_allclose(example.t, emps.t[:n], atol=1e-6)              # written to the us
    np.testing.assert_allclose(example.x_motor, emps.x_motor[:n], atol=1e-10)  # to 0.1 nm
    np.testing.assert_allclose(example.u, emps.u[:n], rtol=1e-5, atol=1e-5)


def test_diagnose_takes_a_csv_in_mm_and_ms(capsys):
    # the example's three half cycles: one trains, two are held out (the claim threshold needs two)
    assert cli.main(["diagnose", str(EXAMPLE), "--train", "0", "--test", "1,2", "--effects", "thermal_drift",
                     "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    # the nominal model fitted on shop units is the EMPS axis (published M = 95.1 kg, Fc = 20.4 N)
    p = out["nominal"]["parameters"]
    assert 90 < p["mass"] < 100 and 15 < p["coulomb"] < 25
