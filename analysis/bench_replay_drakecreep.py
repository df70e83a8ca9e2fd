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

With ``--speeds`` it replays instead one run of the paper-rig bench at each of its six speeds (0.5-3 mm/s, the
preset's own model) and prints the replay's CPU time, the integrator's steps per 4 kHz speed-loop tick, and the
relaxation rate of each LuGre bristle state while sliding, ``sigma0 |v| / Fc`` (the table's guides and seal, Fc
about 5.2 N, and the nut on the screw, about 113 N; ``sigma0`` the assumed 1e8 N/m), with the step at which
Runge-Kutta 3 stays stable on it, ``2.51 / rate`` (the real-axis limit of every three-stage, third-order
explicit Runge-Kutta method): where that step is below the tick's 250 us, the bristles, not the controller, set
the step, and the replay's cost grows with the speed. Beside it, the same replay with Radau 3 (implicit, stable on
the bristles, its step set by the tick; each step dearer, its Jacobian by differences of the compiled system).

Run from the repository root: ``PYTHONPATH=. python analysis/bench_replay_drakecreep.py [--repeat N] [--speeds]``
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
    ap.add_argument("--speeds", action="store_true", help="replay one run at each of the paper-rig bench's six "
                    "speeds instead, with steps per tick and the bristle states' stable steps")
    args = ap.parse_args(argv)
    if args.repeat < 1:
        ap.error(f"--repeat: got {args.repeat}; allowed: an integer >= 1")
    declared = preset("paper")
    if args.speeds:
        return speeds(declared, args.repeat)
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


#: real-axis stability limit of the three-stage, third-order explicit Runge-Kutta methods (|1 + z + z^2/2 + z^3/6| = 1)
RK3_LIMIT = 2.5127


def speeds(declared, repeat):
    """Per speed: CPU time of a replay, steps per speed-loop tick, each bristle state's rate and stable step."""
    from drakecreep.model.nut_friction import nut_friction_levels
    from drakecreep.model.nut_table import table_friction_levels

    sigma0 = declared.friction.bristle_stiffness
    load = declared.load_case(0)
    fc_table, fc_nut = table_friction_levels(declared, load)[0], nut_friction_levels(declared, load)[0]
    tick = declared.controller.velocity_period
    print(f"paper preset: sigma0 {sigma0:.3g} N/m (assumed); sliding levels Fc: table (guides, seal) {fc_table:.2f} N, "
          f"nut {fc_nut:.1f} N; speed-loop tick {tick * 1e6:.0f} us; {repeat} replay(s) per speed after a first one")
    print(f"{'speed [mm/s]':>12s} {'CPU s/replay':>12s} {'steps/tick':>10s} {'table rate [1/s]':>16s} "
          f"{'table stable step [us]':>22s} {'nut rate [1/s]':>14s} {'nut stable step [us]':>20s} "
          f"{'radau3 CPU s':>12s} {'radau3 steps/tick':>17s}")
    implicit = with_value(declared, "simulation.integrator", "radau3")
    for v in (0.5e-3, 0.7e-3, 1e-3, 1.5e-3, 2e-3, 3e-3):
        (run,) = simulated_runs(declared, (v,), declared=declared, n=1500, noise=2.0, seed=42, leg=0.6,
                                starts=(0.05, 0.8))
        replay_drakecreep(run, declared)
        start = time.process_time()
        for _ in range(repeat):
            result = replay_drakecreep(run, declared)
        seconds = (time.process_time() - start) / repeat
        replay_drakecreep(run, implicit)
        start = time.process_time()
        for _ in range(repeat):
            stiff = replay_drakecreep(run, implicit)
        stiff_seconds = (time.process_time() - start) / repeat
        ticks = (run.t[-1] - run.t[0]) / tick
        rates = [sigma0 * v / fc for fc in (fc_table, fc_nut)]
        print(f"{v * 1e3:12.2f} {seconds:12.3f} {result.integrator_steps / ticks:10.2f} {rates[0]:16.3g} "
              f"{RK3_LIMIT / rates[0] * 1e6:22.1f} {rates[1]:14.3g} {RK3_LIMIT / rates[1] * 1e6:20.1f} "
              f"{stiff_seconds:12.3f} {stiff.integrator_steps / ticks:17.2f}", flush=True)


if __name__ == "__main__":
    main()
