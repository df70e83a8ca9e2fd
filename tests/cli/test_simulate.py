"""``drakecreep simulate``'s words for the convergence check (drakecreep.cli.simulate)."""

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
