"""A lead error fixed to the screw, on runs of the project's controller that start at other positions.

The ``drakecreep`` kind's ``lead_error`` candidate (:mod:`drakecreep.gap.drive_fit`) fits the error's amplitude
and phase (its two quadratures, :func:`drakecreep.gap.drive_fit._quadrature_effect`); before session 36 it fitted
the amplitude only, with the error in phase with each run's first sample. This script diagnoses the same runs
both ways: the runs are simulated by the quick rig's diagram (:func:`drakecreep.gap.drake_replay.simulated_runs`)
with a 2 um lead error at the ball-passage period (lead / 12) and phase ``PHASE`` at the screw's position 0,
starting at ``ORIGINS``; two train, two are held out; candidates lead error, force ripple and Stribeck, the seal
force uncertain.

``amplitude only`` is the earlier fit (:func:`amplitude_only`, kept here as the baseline: one replay per
harmonic at a trial amplitude, the first-order optimum of the amplitude, a secant step; phase 0) run through
today's replay (the error fixed to the screw), so the two rows differ only in the fit.

Usage: ``PYTHONPATH=. python analysis/lead_error_phase_study.py [--phase RAD] [--origins MM,MM,MM,MM]
[--seed N]`` (defaults: 1.1 rad, 12.3,45.7,31.1,78.9 mm, noise seed 700: a development seed; the test uses
others).
"""

import argparse
import time

import numpy as np

from drakecreep.gap import drive_fit
from drakecreep.gap.drake_replay import quick_replay_params, rms_force_error, simulated_runs
from drakecreep.params import preset, with_value

SPEEDS = (0.02, 0.03, 0.025, 0.035)
CANDIDATES = ("lead_error", "force_ripple", "stribeck")


def amplitude_only(runs, base, paths, grid, trial, replayer, base_sims, scale):
    """The lead-error fit before session 36: the amplitude at phase 0 (``paths``: amplitude, period, phase)."""
    amp, period, _ = paths
    res = lambda params: drive_fit._residual(runs, replayer(runs, params), scale)  # noqa: E731
    r0 = drive_fit._residual(runs, base_sims, scale)
    best = None
    for g in grid:
        at = drive_fit._with(base, {period: g})
        r_t = res(drive_fit._with(at, {amp: trial}))
        d = (r0 - r_t) / trial
        if not float(d @ d):
            continue
        a = float(np.clip((r0 @ d) / float(d @ d), 0.0, 50 * trial))
        lin = r0 - a * d
        if best is None or float(lin @ lin) < best[0]:
            best = (float(lin @ lin), at, a, r_t)
    if best is None or best[2] == 0.0:
        return {}, float(r0 @ r0)
    _, at, a, r_t = best
    r_a = res(drive_fit._with(at, {amp: a}))
    out = (a, float(r_a @ r_a))
    if abs(a - trial) > 1e-3 * trial:  # one secant step through the trial and the screened amplitude
        d = (r_t - r_a) / (a - trial)
        if float(d @ d) > 0:
            a2 = float(np.clip(a + (r_a @ d) / float(d @ d), 0.0, 50 * trial))
            r_2 = res(drive_fit._with(at, {amp: a2}))
            if float(r_2 @ r_2) < out[1]:
                out = (a2, float(r_2 @ r_2))
    return {period: at.disturbance.lead_error_period, amp: out[0]}, out[1]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--phase", type=float, default=1.1, help="lead-error phase at the screw's position 0 [rad]")
    ap.add_argument("--origins", default="12.3,45.7,31.1,78.9", help="start position of each run [mm]")
    ap.add_argument("--seed", type=int, default=700, help="noise seed")
    args = ap.parse_args(argv)
    origins = [1e-3 * float(x) for x in args.origins.split(",")]
    if len(origins) != len(SPEEDS):
        ap.error(f"--origins: got {len(origins)} positions; allowed: {len(SPEEDS)}, one per run")
    rig = quick_replay_params(preset("paper"))
    truth = with_value(with_value(rig, "disturbance.lead_error_amplitude", 2e-6), "disturbance.lead_error_phase",
                       args.phase)
    runs = simulated_runs(truth, SPEEDS, declared=rig, n=500, noise=2.0, seed=args.seed, origins=origins)
    print(f"truth: 2.000 um at {args.phase:+.3f} rad, period {1e3 * truth.disturbance.lead_error_period:.4f} mm; "
          f"runs start at {args.origins} mm")
    product = drive_fit._quadrature_effect
    lead = drive_fit._PERIODIC["lead_error"]
    for label, fit in (("amplitude and phase", product), ("amplitude only", amplitude_only)):
        def chosen(runs_, base, paths, *rest, _fit=fit):
            return (_fit if paths == lead else product)(runs_, base, paths, *rest)

        drive_fit._quadrature_effect = chosen
        try:
            t0 = time.perf_counter()
            res = drive_fit.diagnose_drive(runs[:2], runs[2:], uncertain=("table.seal_force",), effects=CANDIDATES)
            seconds = time.perf_counter() - t0
        finally:
            drive_fit._quadrature_effect = product
        d = res.params.disturbance
        claimed = " + ".join(res.claimed) or "nothing"
        print(f"{label:20s} claimed {claimed:12s} lead error {1e6 * d.lead_error_amplitude:.3f} um "
              f"at {d.lead_error_phase:+.3f} rad; held-out force error nominal "
              f"{rms_force_error(res.nominal_test_errors):.2f} % -> {rms_force_error(res.test_errors):.2f} %; "
              f"{seconds:.1f} s")


if __name__ == "__main__":
    main()
