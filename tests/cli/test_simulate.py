"""``drakecreep simulate``'s words for its verdicts: the convergence check, and a drive that cannot hold the feed."""

import math

import pytest

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


def test_a_drive_that_cannot_hold_the_feed_gets_no_creep_verdict(tmp_path, capsys):
    """A 1 mN m drive against the paper rig's 119 N at load case 0: the table never slides, which is no stick-slip
    (it was reported 'creep yes', 100 % stuck without a cycle). The text, the JSON and metrics.json say why."""
    import json

    from drakecreep import cli
    from drakecreep.params import preset, save_params, with_value

    path = tmp_path / "weak.yaml"
    save_params(with_value(with_value(preset("paper"), "motor.peak_torque", 1e-3), "simulation.steady_start", 0.2), path)
    args = ["simulate", "--params", str(path), "--load-case", "0", "--duration", "0.3", "--no-plot"]
    assert cli.main(args + ["--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert "creep (stick-slip)      no verdict: the drive cannot hold this feed (it takes 118.6 N, beyond its force " \
           "limit 1.257 N" in out and "stick fraction          100.00 %" in out
    assert cli.main(args + ["--out", str(tmp_path / "b"), "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    kept = json.loads((tmp_path / "b" / "metrics.json").read_text())["summary"]
    for s in (said, kept):
        assert s["creep"] is None and s["overload"]["limit_N"] == pytest.approx(2 * math.pi * 1e-3 / 5e-3)
    # a drive that can hold it keeps its verdict and has no overload
    save_params(with_value(preset("paper"), "simulation.steady_start", 0.2), path)
    assert cli.main(args + ["--out", str(tmp_path / "c"), "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert isinstance(said["creep"], bool) and "overload" not in said


def test_an_overloaded_drive_that_lags_without_sticking_gets_no_verdict_either(tmp_path, capsys, monkeypatch):
    """3e9 N of guide friction (a load case's fz of -1e12 N, refused since) was reported 'creep no' at 28 % of the
    feed: the overload is asked for when the table lags the feed, not only when it sticks."""
    import dataclasses
    import json

    import drakecreep.servo.linearize as linearize
    import drakecreep.sim.simulation as simulation
    from drakecreep import cli

    real = simulation.simulate

    def lagging(*args, **kwargs):  # the run as such a drive gives it: sliding, no stick, far below the feed
        r = real(*args, **kwargs)
        r.metrics = dataclasses.replace(r.metrics, stick_slip_cycles=0, stick_fraction=0.0, mean_speed=0.28e-3)
        return r

    monkeypatch.setattr(simulation, "simulate", lagging)
    monkeypatch.setattr(linearize, "sliding_overload", lambda params, scenario: (3e9, 8.9e3))
    assert cli.main(["simulate", "--duration", "1.1", "--no-plot", "--json", "--out", str(tmp_path / "o")]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["creep"] is None and said["overload"] == {"force_N": 3e9, "limit_N": 8.9e3}
