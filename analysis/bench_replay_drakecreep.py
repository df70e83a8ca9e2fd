"""What one closed-loop replay of a paper-rig run costs, and which part of the model sets it.

The ``kind: drakecreep`` diagnosis (:func:`drakecreep.gap.drive_fit.diagnose_drive`) spends its time in
closed-loop replays of the compiled paper-preset diagram (:func:`drakecreep.gap.drake_replay.replay_drakecreep`);
``analysis/bench_diagnose.py --paper-rig`` counts them (561 in session 54). This script replays one of that
bench's runs (1.5 s at 2 mm/s, the preset's own model) with the preset and with one setting changed at a time,
each timed in this process after a first build as CPU time of this process (``time.process_time``: the replay
runs in it, and on a shared machine wall time also counts the others), and prints it with its ratio to the
preset's and the RMS change of the replayed force [N]: what a setting would save and what it would change.

The settings are physics (the nut's friction on the table instead of the screw; LuGre bristles ten times softer,
1e7 N/m against the preset's assumed 1e8 N/m; an ideal current loop) or numerics (the integrator). A physics
setting that saves time is not a free choice: it changes the model, by the force change printed.

Run from the repository root: ``PYTHONPATH=. python analysis/bench_replay_drakecreep.py [--repeat N]``
"""

import argparse
import time

import numpy as np

from drakecreep.gap.drake_replay import replay_drakecreep, simulated_runs
from drakecreep.params import preset, with_value

CASES = (
    ("paper preset (runge_kutta3, 1e-4)", {}),
    ("nut friction on the table", {"friction.nut_friction_on": "table"}),
    ("bristles 1e7 N/m", {"friction.bristle_stiffness": 1e7}),
    ("ideal current loop", {"motor.current_loop_time_constant": 0.0}),
    ("radau3", {"simulation.integrator": "radau3"}),
    ("implicit_euler", {"simulation.integrator": "implicit_euler"}),
    ("runge_kutta5", {"simulation.integrator": "runge_kutta5"}),
)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2, help="replays timed per case, after a first one (default 2)")
    args = ap.parse_args(argv)
    if args.repeat < 1:
        ap.error(f"--repeat: got {args.repeat}; allowed: an integer >= 1")
    declared = preset("paper")
    (run,) = simulated_runs(declared, (2e-3,), declared=declared, n=1500, noise=2.0, seed=42, leg=0.6,
                            starts=(0.05,))
    print(f"one paper-rig run, {run.n} samples of {run.dt * 1e3:g} ms; {args.repeat} replay(s) per case after a "
          "first one")
    print(f"{'case':36s} {'CPU s/replay':>12s} {'ratio':>7s} {'force change RMS [N]':>21s}")
    base_time = base_force = None
    for label, changes in CASES:
        params = declared
        for path, value in changes.items():
            params = with_value(params, path, value)
        replay_drakecreep(run, params)  # the first call: Drake's first-call costs
        start = time.process_time()
        for _ in range(args.repeat):
            result = replay_drakecreep(run, params)
        seconds = (time.process_time() - start) / args.repeat
        if base_time is None:
            base_time, base_force = seconds, result.force
        change = float(np.sqrt(np.mean((result.force - base_force) ** 2)))
        print(f"{label:36s} {seconds:12.3f} {seconds / base_time:6.2f}x {change:21.3f}", flush=True)


if __name__ == "__main__":
    main()
