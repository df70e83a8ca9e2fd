"""Replay of ``kind: drakecreep`` runs: compiled fast path vs leaf systems, and a recovery example.

1. Speed-up: :func:`drakecreep.gap.drake_replay.replay_drakecreep` with ``backend="compiled"`` against
   ``backend="leaf"`` on the same measured run (an out-and-back reference with an external force), for the
   presets ``paper`` and ``rigid_axis`` and the test rig of ``tests/gap/test_drive_fit.py``. Both are
   timed in this process, CPU time (``time.process_time``: the machine is shared, wall time is not
   comparable between runs) and wall time; the agreement of the two is printed beside. Then the compiled
   diagram with every recorded signal in its output against the three a replay reads.
2. Recovery: runs simulated by the test rig with a known change (Coulomb level +30 %, a 2 um lead error,
   nothing), two training and two held-out runs, noise 2 N on ``u``: what ``diagnose_drive`` finds.

3. Coverage (``--coverage N``): the Coulomb case with N noise realisations (seeds 5000 + 10 k, never used by
   the tests): how often the 95 % interval of the fitted level contains the truth, and the error in units of
   the stated standard deviation (a calibrated interval: ~95 %, errors of spread ~1).

Run: ``python analysis/bench_drive_fit.py [--duration S] [--skip-speed] [--skip-recovery] [--coverage N]``
"""

import argparse
import itertools
import time

import numpy as np

from drakecreep.gap.drake_replay import quick_replay_params, replay_drakecreep, simulated_runs
from drakecreep.gap.drive_fit import diagnose_drive
from drakecreep.gap.measured import ControllerMeta, MeasuredMeta, MeasuredRun
from drakecreep.gap.truth import out_and_back
from drakecreep.model.nut_table import friction_levels
from drakecreep.params import LoadCase, preset, with_value


def test_rig():
    """The rig of tests/gap/test_drive_fit.py: the paper preset quick to replay."""
    return quick_replay_params(preset("paper"))


def blank_run(params, n, label="run", speed=0.02, f_ext=True):
    meta = MeasuredMeta(u_units="N", u_gain=1.0, params=params, controller=ControllerMeta(kind="drakecreep"))
    t = np.arange(n) * 1e-3
    half = n * 1e-3 / 2
    x_ref = out_and_back(speed, 0.0, n=n, dt=1e-3, leg=0.4 * half, starts=(0.05 * half, 1.05 * half))
    force = 30.0 * np.sin(2 * np.pi * 7.0 * t) if f_ext else None
    return MeasuredRun(t=t, x_ref=x_ref, x_motor=x_ref, u=np.zeros(n), meta=meta, f_ext=force, label=label)


def timed(fn):
    c, w = time.process_time(), time.perf_counter()
    out = fn()
    return out, time.process_time() - c, time.perf_counter() - w


def speed(duration):
    from drakecreep.sim.simulation import target_accuracy

    n = int(round(duration / 1e-3))
    print(f"replay of a {duration:g} s run (out-and-back at 20 mm/s, f_ext 30 N at 7 Hz), CPU s / wall s, after a "
          "warm-up replay of each backend; |dx|, |du|: compiled vs leaf at the params' accuracy, and the compiled "
          "replay vs itself at 1/100 of that accuracy (the integration error both carry):")
    print(f"{'params':12s} {'compiled':>16s} {'leaf':>16s} {'CPU ratio':>9s} {'|dx| m':>9s} {'|du| N':>7s} "
          f"{'int. |dx| m':>11s} {'int. |du| N':>11s}")
    for name, params in (("test rig", test_rig()), ("paper", preset("paper")), ("rigid_axis", preset("rigid_axis"))):
        for backend in ("compiled", "leaf"):
            replay_drakecreep(blank_run(params, 60), backend=backend)
        run = blank_run(params, n)
        fast, cf, wf = timed(lambda: replay_drakecreep(run))
        slow, cs, ws = timed(lambda: replay_drakecreep(run, backend="leaf"))
        tight = replay_drakecreep(run, with_value(params, "simulation.accuracy", target_accuracy(params) / 100))
        dx = max(np.max(np.abs(fast.x_motor - slow.x_motor)), np.max(np.abs(fast.x_table - slow.x_table)))
        du = np.max(np.abs(fast.u - slow.u))
        ix = max(np.max(np.abs(fast.x_motor - tight.x_motor)), np.max(np.abs(fast.x_table - tight.x_table)))
        iu = np.max(np.abs(fast.u - tight.u))
        print(f"{name:12s} {cf:6.2f} / {wf:6.2f} {cs:6.2f} / {ws:6.2f} {cs / cf:9.1f} {dx:9.2e} {du:7.3g} "
              f"{ix:11.2e} {iu:11.3g}", flush=True)


def signals(duration):
    """The compiled diagram outputting every recorded signal against the three a replay reads (session 66):
    the plant's output is evaluated at every sample tick and every log, so the signals it carries cost time."""
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import LogVectorOutput

    from drakecreep.model.diagram import build_diagram
    from drakecreep.scenario import Scenario
    from drakecreep.sim.compiled import compile_diagram
    from drakecreep.sim.simulation import make_simulator, target_accuracy

    three = ("motor_angle", "table_position", "force_command")
    print(f"\ncompiled diagram, a {duration:g} s ramp, least CPU s of four with every signal in its output / with the "
          "three a replay reads (the same integrator and accuracy; the three agree to the bit):")
    rigs = (("test rig", test_rig()), ("paper", preset("paper")), ("rigid_axis", preset("rigid_axis")))
    for (name, params), feed in itertools.product(rigs, (0.5e-3, 3e-3)):
        drive = build_diagram(params, Scenario(feed=feed, duration=duration))
        cpu, logged = {}, {}
        for names in (None, three) * 4:  # alternately, four times each: the least CPU time of each
            compiled = compile_diagram(drive, signals=names)
            b = DiagramBuilder()
            system = b.AddSystem(compiled.diagram)
            log = LogVectorOutput(system.GetOutputPort("signals"), b, params.controller.velocity_period)
            root = b.Build()
            context = root.CreateDefaultContext()
            compiled.set_initial_state(root.GetMutableSubsystemContext(system, context))
            simulator = make_simulator(root, context, params.simulation, target_accuracy(params))
            _, took, _ = timed(lambda: simulator.AdvanceTo(duration))
            cpu[names] = min(took, cpu.get(names, took))
            data = log.FindLog(context).data()
            logged[names] = np.array([data[compiled.signal_names.index(n)] for n in three])
        same = np.array_equal(logged[None], logged[three])
        print(f"{name:12s} {1e3 * feed:3.1f} mm/s {len(drive.signal_names):2d} signals {cpu[None]:6.2f} / 3 signals "
              f"{cpu[three]:6.2f}: {cpu[None] / cpu[three]:.2f} x; {'to the bit' if same else 'DIFFERENT'}", flush=True)


def coulomb_truth(rig):
    """``rig`` with the guides' Coulomb level raised by 30 % of the rig's whole Coulomb force."""
    return with_value(rig, "table.seal_force", rig.table.seal_force + 0.3 * friction_levels(rig, LoadCase())[0])


def recovery():
    rig = test_rig()
    cases = {
        "Coulomb +30 %": coulomb_truth(rig),
        "lead error 2 um": with_value(rig, "disturbance.lead_error_amplitude", 2e-6),
        "null": rig,
    }
    for seed, (label, truth) in enumerate(cases.items()):
        runs = simulated_runs(truth, (0.02, 0.03, 0.025, 0.035), declared=rig, n=500, noise=2.0, seed=1000 + 10 * seed)
        result, cpu, wall = timed(lambda: diagnose_drive(runs[:2], runs[2:], uncertain=("table.seal_force",),
                                                         effects=("lead_error", "force_ripple", "stribeck")))
        print(f"\n== truth: {label} (seal_force {truth.table.seal_force:.4g} N, lead error "
              f"{truth.disturbance.lead_error_amplitude * 1e6:g} um); {result.simulations} replays, "
              f"{cpu:.1f} s CPU, {wall:.1f} s wall")
        print("\n".join(result.summary()))


def coverage(count):
    rig = test_rig()
    truth = coulomb_truth(rig)
    true = truth.table.seal_force
    inside, z = 0, []
    for k in range(count):
        runs = simulated_runs(truth, (0.02, 0.03, 0.025, 0.035), declared=rig, n=500, noise=2.0, seed=5000 + 10 * k)
        result = diagnose_drive(runs[:2], runs[2:], uncertain=("table.seal_force",), effects=())
        (seal,) = result.fitted
        half = (seal.upper - seal.lower) / 2
        inside += seal.contains(true)
        z.append((seal.value - true) / (half / 1.96))
        print(f"seed {5000 + 10 * k}: {seal.value:.4f} N [{seal.lower:.4f}, {seal.upper:.4f}], truth {true:.4f} N, "
              f"error {z[-1]:+.2f} sd", flush=True)
    print(f"coverage of the 95 % interval: {inside}/{count}; error / stated sd: mean {np.mean(z):+.2f}, "
          f"spread {np.std(z, ddof=1):.2f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=0.5, help="simulated seconds of the speed run (default 0.5)")
    ap.add_argument("--skip-speed", action="store_true")
    ap.add_argument("--skip-recovery", action="store_true")
    ap.add_argument("--coverage", type=int, default=0, help="noise realisations of the interval coverage check")
    args = ap.parse_args()
    if args.coverage:
        coverage(args.coverage)
        return
    if not args.skip_speed:
        speed(args.duration)
        signals(1.5)
    if not args.skip_recovery:
        recovery()


if __name__ == "__main__":
    main()
