"""``drakecreep simulate``'s words for its verdicts: the convergence check, and a drive that cannot hold the feed."""

import math

from drakecreep.cli.simulate import _converged_text


def test_a_converged_run_says_where_it_was_checked():
    assert _converged_text(dict(converged=True, accuracy=1e-5)) == "yes at accuracy 1e-05, checked at 10x tighter"
    assert _converged_text(dict(converged=None)) == "not checked"


def test_a_run_whose_verdict_held_says_only_its_amplitude_moved():
    text = _converged_text(dict(converged=False, accuracy=1e-5, creep=True, convergence_verdict_agrees=True,
                                convergence_fluctuation_change_mm_s=0.017, convergence_tolerance_mm_s=0.01))
    assert text.startswith("NO at accuracy 1e-05: a 10x tighter run gives the same verdict (creeps)")
    assert "0.017 mm/s apart (tolerance 0.01 mm/s)" in text and "amplitudes as indicative" in text


def test_a_run_whose_verdict_flipped_says_so():
    text = _converged_text(dict(converged=False, accuracy=1e-4, creep=False, convergence_verdict_agrees=False,
                                convergence_fluctuation_change_mm_s=0.3, convergence_tolerance_mm_s=0.05))
    assert "the other verdict" in text and "not converged" in text
    failed = _converged_text(dict(converged=False, accuracy=1e-4, convergence_verdict_agrees=None,
                                  convergence_fluctuation_change_mm_s=None))
    assert "failed" in failed


def test_a_drive_that_cannot_hold_the_feed_is_refused_before_its_run(tmp_path, capsys, monkeypatch):
    """A 1 mN m drive against the paper rig's 119 N at load case 0 never slides: no stick-slip to give a verdict on
    (it was reported 'creep yes', 100 % stuck without a cycle; then, after a 79 s run, 'no verdict'). One line,
    exit 2, naming the feed, before any simulation or output; a load no feed can slide at names the load case."""
    from drakecreep import cli
    from drakecreep.params import preset, save_params, with_value
    import drakecreep.sim.simulation as simulation

    def no_run(*args, **kwargs):  # pragma: no cover - the refusal comes first
        raise AssertionError("simulated")

    monkeypatch.setattr(simulation, "simulate", no_run)
    path = tmp_path / "weak.yaml"
    save_params(with_value(preset("paper"), "motor.peak_torque", 1e-3), path)
    args = ["simulate", "--params", str(path), "--load-case", "0", "--no-plot", "--out", str(tmp_path / "a")]
    assert cli.main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("drakecreep simulate: error: --load-case: got 0; allowed: a load case "
                                               "the drive can hold at some feed")
    assert f"beyond the drive's limit {2 * math.pi * 1e-3 / 5e-3:.4g} N" in err[0]
    assert not (tmp_path / "a").exists()
    # a drive that holds the slow feeds but not a fast one (the motor's viscous drag): the feed is named
    save_params(with_value(preset("paper"), "motor.viscous_damping", 1.0), path)
    assert cli.main(args[:-2] + ["--feed", "500", "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("drakecreep simulate: error: --feed: got 500.0; allowed: a feed in mm/s the drive can slide "
                          "at: at load case 0 it takes ")
    ratio = 5e-3 / (2 * math.pi)  # the lead over a radian
    assert f"motor drag {1.0 * 0.5 / ratio / ratio:.4g} N" in err  # 1 N m s/rad at 0.5 m/s, through the lead
