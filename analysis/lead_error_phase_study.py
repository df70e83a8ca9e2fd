"""A lead error fixed to the screw, on runs of the project's controller that start at other positions.

The ``drakecreep`` kind's ``lead_error`` candidate (:mod:`drakecreep.gap.drive_fit`) fits the error's amplitude
and phase (its two quadratures); before session 36 it fitted the amplitude only, with the error in phase with
each run's first sample. This script diagnoses the same runs both ways: the runs are simulated by the quick
rig's diagram (:func:`drakecreep.gap.drake_replay.simulated_runs`) with a 2 um lead error at the ball-passage
period (lead / 12) and phase ``PHASE`` at the screw's position 0, starting at ``ORIGINS``; two train, two are held
out; candidates lead error, force ripple and Stribeck, the seal force uncertain.

``amplitude only`` is the earlier fit (:func:`drakecreep.gap.drive_fit._amplitude_effect`, phase 0) run through
today's replay (the error fixed to the screw), so the two rows differ only in the fit.

Usage: ``PYTHONPATH=. python analysis/lead_error_phase_study.py [--phase RAD] [--origins MM,MM,MM,MM]
[--seed N]`` (defaults: 1.1 rad, 12.3,45.7,31.1,78.9 mm, noise seed 700: a development seed; the test uses
others).
"""

import argparse
import time

from drakecreep.gap import drive_fit
from drakecreep.gap.drake_replay import quick_replay_params, simulated_runs, rms_force_error
from drakecreep.params import preset, with_value

SPEEDS = (0.02, 0.03, 0.025, 0.035)
CANDIDATES = ("lead_error", "force_ripple", "stribeck")


def _amplitude_only(runs, base, grid, trial, replayer, base_sims, scale):
    return drive_fit._amplitude_effect(runs, base, "disturbance.lead_error_amplitude",
                                       "disturbance.lead_error_period", grid, trial, replayer, base_sims, scale)


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
    fits = {"amplitude and phase": drive_fit._lead_error_effect, "amplitude only": _amplitude_only}
    for label, fit in fits.items():
        saved = drive_fit._lead_error_effect
        drive_fit._lead_error_effect = fit
        try:
            t0 = time.perf_counter()
            res = drive_fit.diagnose_drive(runs[:2], runs[2:], uncertain=("table.seal_force",), effects=CANDIDATES)
            seconds = time.perf_counter() - t0
        finally:
            drive_fit._lead_error_effect = saved
        d = res.params.disturbance
        claimed = " + ".join(res.claimed) or "nothing"
        print(f"{label:20s} claimed {claimed:12s} lead error {1e6 * d.lead_error_amplitude:.3f} um "
              f"at {d.lead_error_phase:+.3f} rad; held-out force error nominal "
              f"{rms_force_error(res.nominal_test_errors):.2f} % -> {rms_force_error(res.test_errors):.2f} %; "
              f"{seconds:.1f} s")


if __name__ == "__main__":
    main()
