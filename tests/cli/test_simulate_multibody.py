"""``drakecreep simulate --model multibody``."""

import json

import pytest

from drakecreep.cli import main
from drakecreep.params import save_params, with_value


def test_simulate_multibody_json(paper, tmp_path, capsys):
    params = with_value(with_value(paper, "simulation.steady_start", 0.15), "simulation.convergence_check", False)
    save_params(params, tmp_path / "short.yaml")
    out = tmp_path / "run"
    code = main(["simulate", "--params", str(tmp_path / "short.yaml"), "--model", "multibody", "--segments", "3",
                 "--rigid-joints", "--axial-screw", "--backend", "compiled", "--feed", "1", "--duration", "0.3", "--no-plot", "--json", "--out", str(out)])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["model"] == "multibody" and summary["n_segments"] == 3 and summary["rigid_joints"] is True
    assert summary["creep"] is False
    assert summary["mean_speed_mm_s"] == pytest.approx(1.0, rel=0.05)
    assert (out / "timeseries.csv").exists() and (out / "metrics.json").exists()


@pytest.mark.parametrize("argv, fragment", [
    (["simulate", "--model", "multibody", "--segments", "1"], "--segments"),
    (["simulate", "--segments", "4"], "--segments"),
    (["simulate", "--rigid-joints"], "--rigid-joints"),
    (["simulate", "--model", "multibody", "--axial-screw"], "--axial-screw"),
    (["simulate", "--axial-screw"], "--axial-screw"),
    (["simulate", "--model", "multibody", "--feed", "50", "--duration", "5"], "--duration: got 5.0; allowed: <= 2 s"),
    # no duration both holds the metrics window and keeps the nut on its segment: '<= 0.3 s' and '>= 1.005 s' sent
    # the user back and forth; it is the feed
    (["simulate", "--model", "multibody", "--segments", "2", "--feed", "1000", "--duration", "1.1"],
     "--feed: got 1000.0; allowed: <= 298.5 mm/s with 2 segments"),
    # the option given, not all three ('--segments/--rigid-joints/--axial-screw: got True'); 0 too
    (["simulate", "--segments", "0"], "--segments: got 0; allowed: only with --model multibody"),
    (["simulate", "--axial-screw", "--rigid-joints"], "--rigid-joints: got True; allowed: only with --model"),
    (["simulate", "--model", "four_mass"], "--model"),
])
def test_simulate_multibody_bad_arguments_one_line_exit_2(argv, fragment, capsys, tmp_path):
    try:
        code = main(argv + ["--out", str(tmp_path / "x")])
    except SystemExit as exit_:  # argparse's own errors
        code = exit_.code
    err = capsys.readouterr().err
    assert code == 2 and fragment in err and len(err.strip().splitlines()) == 1
