"""The claim test shared by the diagnoses: does an effect shrink the held-out closed-loop replay?

An effect is claimed only when the replay of the held-out runs (parameters fixed from the training runs)
improves by more than run-to-run variation explains: the pooled force-error energy shrinks by more than a
threshold the caller derives from its training runs (``drakecreep.gap.drive_fit`` refits the uncertain fields
with each training run left out and takes the largest change of the held-out replay), and a majority of the
held-out runs get better (:func:`replay_test`). ``diagnose_drake`` asks for a mean per-run held-out log error
ratio (:func:`mean_log_ratio`) that is significant, by ``t_(1-ALPHA, n-1)`` standard errors or by the sign-flip
permutation null (:func:`sign_flip_p`), and above its own training-run null
(:func:`drakecreep.gap.drake_diagnosis.training_run_null`).
"""

from __future__ import annotations

import numpy as np
from scipy import stats

__all__ = ["ALPHA", "POOLED_FACTOR", "replay_test", "mean_and_standard_error", "mean_log_ratio", "log_ratios",
           "sign_flip_p"]

#: One-sided level of the tests of a claim.
ALPHA = 0.05
#: ``diagnose_drive``'s other way past the Student bar on the per-run gains: a pooled held-out shrink above this
#: many run-to-run nulls. A real effect's per-run gains can differ by two orders of magnitude (a lead error's force
#: grows with the square of the speed), so their spread keeps the bar above a gain every run shares. 20 is the
#: round number near the geometric middle of 6.0, the largest shrink / null of a candidate that is no effect of the
#: truth on the development rows then written, and 80, the smallest of a true effect; declared before and decided on
#: development rows written after it (docs/gap_benchmark.md, study 3bs: 4 of 6 right first claims at SNR >= 3
#: against the bar's 2 of 6, no claim on 4 nulls, no wrong first claim).
POOLED_FACTOR = 20.0


def replay_test(e_nom, e_eff, threshold=0.0):
    """Held-out replay: pooled shrink above ``threshold`` and a majority of the runs better.

    Parameters
    ----------
    e_nom, e_eff : array_like
        Per held-out run, the replay residual energy of the current model and of the model with the effect.
    threshold : float
        Shrink of the pooled energy the effect must exceed (0..1).

    Returns
    -------
    dict
        ``log_ratios`` (per run), ``shrink`` (pooled), ``threshold``, ``runs_better`` and ``passes``.
    """
    e_nom, e_eff = np.asarray(e_nom, dtype=float), np.asarray(e_eff, dtype=float)
    lr = np.log(np.maximum(e_eff, 1e-300) / np.maximum(e_nom, 1e-300))
    total = float(np.sum(e_nom))
    # a model that replays the held-out runs exactly (noise-free synthetic runs) leaves nothing to shrink
    shrink = float(1.0 - np.sum(e_eff) / total) if total > 0 else (0.0 if np.sum(e_eff) == 0 else -np.inf)
    better = int(np.sum(lr < 0))
    return {"log_ratios": lr.tolist(), "shrink": shrink, "threshold": float(threshold),
            "runs_better": better, "passes": bool(shrink > threshold and 2 * better > lr.size)}


def mean_and_standard_error(d):
    """Mean and standard error of per-run paired differences ``d`` (``inf`` for fewer than two runs)."""
    d = np.asarray(d, dtype=float)
    se = float(d.std(ddof=1) / np.sqrt(d.size)) if d.size > 1 else float("inf")
    return float(d.mean()), se


def log_ratios(reference, candidate, floor=1e-12):
    """Per-run ``ln(reference / candidate)`` of two error arrays (the factor by which a candidate shrinks each
    run's error; errors below ``floor`` count as ``floor``)."""
    reference, candidate = np.asarray(reference, dtype=float), np.asarray(candidate, dtype=float)
    return np.log(np.maximum(reference, floor) / np.maximum(candidate, floor))


def mean_log_ratio(reference, candidate, floor=1e-12):
    """Mean and standard error of :func:`log_ratios`."""
    return mean_and_standard_error(log_ratios(reference, candidate, floor))


def sign_flip_p(values):
    """One-sided p value of the mean of per-run paired ``values`` under the sign-flip permutation null.

    Under "the candidate is useless" each run's value is as likely negative as positive; the p value is the
    share of the ``2^n`` sign patterns whose mean is at least the observed one (``scipy.stats.permutation_test``,
    exact up to 16 runs, 19 999 random patterns with a fixed seed beyond). Unlike Student's t it does not assume
    normal values: a real effect's per-run gains are often all positive and skewed (the runs carry it in
    different shares),
    and their spread keeps t under its bar. With five runs its smallest value is 1/32 (every run better); with
    four or fewer it cannot go below 0.05. 1 for fewer than two runs."""
    x = np.asarray(values, dtype=float)
    if x.size < 2:
        return 1.0
    kw = {"n_resamples": np.inf} if x.size <= 16 else {"n_resamples": 19999, "random_state": 0}
    return float(stats.permutation_test((x,), np.mean, permutation_type="samples", alternative="greater",
                                        **kw).pvalue)
