import json

import pytest

from drakecreep.cli import main


def test_modes_json(capsys):
    assert main(["modes", "--segments", "4", "--modes", "6", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["rigid_body_modes"] == 1 and len(out["modes"]) == 6
    assert out["two_mass_axial_frequency_Hz"] == pytest.approx(73.515, abs=0.01)
    flagged = [m for m in out["modes"] if m["in_two_mass_model"]]
    assert len(flagged) == 1 and flagged[0]["label"] == "axial"
    freqs = [m["frequency_Hz"] for m in out["modes"]]
    assert freqs == sorted(freqs)


def test_modes_text_rigid(capsys):
    assert main(["modes", "--segments", "4", "--modes", "3", "--rigid-joints"]) == 0
    out = capsys.readouterr().out
    assert "rigid fixed joints" in out and "yes: 73.52 Hz" in out


@pytest.mark.parametrize("argv, fragment", [
    (["modes", "--segments", "1"], "--segments"),
    (["modes", "--modes", "0"], "--modes"),
    (["modes", "--table-position", "600"], "--table-position"),
    (["modes", "--table-position", "nan"], "--table-position"),
])
def test_modes_bad_arguments_one_line_exit_2(argv, fragment, capsys):
    try:
        code = main(argv)
    except SystemExit as exit_:  # argparse's own errors
        code = exit_.code
    err = capsys.readouterr().err
    assert code == 2 and fragment in err and len(err.strip().splitlines()) == 1


def test_modes_out_writes_the_figures(tmp_path, capsys):
    assert main(["modes", "--segments", "4", "--modes", "4", "--out", str(tmp_path)]) == 0
    assert "modes.png" in capsys.readouterr().out
    assert (tmp_path / "modes.png").stat().st_size > 10_000 and (tmp_path / "mechanism.png").exists()
