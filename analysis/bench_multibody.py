"""Benchmark: a 5 s creep run of the multibody model against the two-mass compiled path, same run.

Scenario: paper preset, load case 3, LuGre, 0.1 mm/s (stick-slip in the two-mass model), 5 s, the
convergence check off in both (it costs each model its own share; timed here is one run). Prints the
CPU time of this process for each run (the ratio is taken on it: on a shared machine wall time
measures the neighbours), its wall time, its integrator steps and derivative evaluations, the ratio to the
two-mass compiled run, and where one derivative evaluation of the multibody diagram spends its time
(the plant with its inputs, and each Python leaf system's output alone). Issue 17's target: 20x.

The multibody runs use the compiled loop (``simulate(..., backend="compiled")``: controller, sensors and
friction laws as ``SymbolicVectorSystem``s around Drake's MultibodyPlant) unless ``--backends`` also names
``leaf`` (the Python leaf systems: the same equations, the run before the loop was compiled).

    python analysis/bench_multibody.py [--feed 0.1] [--duration 5] [--configs rigid2_axial rigid3_axial full6 ...]
        [--backends compiled leaf] [--baseline-repeats 3]
"""

from __future__ import annotations

import argparse
import time

from drakecreep.multibody.diagram import MultibodyOptions, build_multibody_diagram
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.compiled import compile_diagram
from drakecreep.sim.simulation import simulate

__all__ = ["CONFIGS", "profile", "main"]

#: name -> multibody options
CONFIGS = {
    "full6": MultibodyOptions(n_segments=6),
    "full4": MultibodyOptions(n_segments=4),
    "rigid6": MultibodyOptions(n_segments=6, rigid_joints=True),
    "rigid4": MultibodyOptions(n_segments=4, rigid_joints=True),
    "rigid3": MultibodyOptions(n_segments=3, rigid_joints=True),
    "rigid4_rk3": MultibodyOptions(n_segments=4, rigid_joints=True, integrator="runge_kutta3"),
    "rigid3_rk3": MultibodyOptions(n_segments=3, rigid_joints=True, integrator="runge_kutta3"),
    "rigid2_axial": MultibodyOptions(n_segments=2, rigid_joints=True, screw_bending=False),
    "rigid3_axial": MultibodyOptions(n_segments=3, rigid_joints=True, screw_bending=False),
    "rigid6_axial": MultibodyOptions(n_segments=6, rigid_joints=True, screw_bending=False),
}


def timed(params, scenario, **kwargs):
    """``simulate`` and the CPU time of this process it took (s): the machine may be shared, wall time is not
    a fair ratio there."""
    start = time.process_time()
    result = simulate(params, scenario, **kwargs)
    return result, time.process_time() - start


def profile(params, scenario, options, repeats=500, backend="compiled"):
    """Microseconds per evaluation: the whole diagram's derivatives, the plant alone, then each leaf's output port alone."""
    fd = build_multibody_diagram(params, scenario, options,
                                 compiler=compile_diagram if backend == "compiled" else None)
    d = fd.diagram
    ctx = d.CreateDefaultContext()
    fd.set_initial_state(ctx)
    x = ctx.get_continuous_state_vector().CopyToVector()
    der = d.AllocateTimeDerivatives()
    out = {}
    start = time.perf_counter()
    for _ in range(repeats):
        ctx.SetContinuousState(x)  # invalidates every cache entry that depends on the state
        d.CalcTimeDerivatives(ctx, der)
    out["diagram derivatives"] = (time.perf_counter() - start) / repeats * 1e6
    plant = fd.drive.plant
    pc = plant.GetMyMutableContextFromRoot(ctx)
    xp = plant.GetPositionsAndVelocities(pc)
    pder = plant.AllocateTimeDerivatives()
    start = time.perf_counter()
    for _ in range(repeats):
        plant.SetPositionsAndVelocities(pc, xp)  # the plant's own state only: its inputs stay cached
        plant.CalcTimeDerivatives(pc, pder)
    out["plant alone"] = (time.perf_counter() - start) / repeats * 1e6
    for name in ("controls", "controller", "guide_friction", "nut_friction", "encoder", "scale", "reference"):
        if name not in fd.systems:
            continue
        system = fd.systems[name]
        sub = system.GetMyContextFromRoot(ctx)
        port = system.get_output_port(0)
        start = time.perf_counter()
        for _ in range(repeats):
            ctx.SetContinuousState(x)
            port.Eval(sub)
        out[f"{name} output (with its inputs)"] = (time.perf_counter() - start) / repeats * 1e6
    out["states"] = len(x)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--feed", type=float, default=0.1, help="mm/s (default 0.1)")
    ap.add_argument("--duration", type=float, default=5.0, help="s (default 5)")
    ap.add_argument("--configs", nargs="+", default=["rigid2_axial", "rigid3_axial", "full6"], choices=sorted(CONFIGS))
    ap.add_argument("--backends", nargs="+", default=["compiled"], choices=["compiled", "leaf"])
    ap.add_argument("--baseline-repeats", type=int, default=3, help="two-mass runs; the fastest is the baseline")
    args = ap.parse_args(argv)
    params = with_value(preset("paper"), "simulation.convergence_check", False)
    scenario = Scenario(feed=args.feed * 1e-3, load_case=3, duration=args.duration)
    # the baseline is short (~1.3 s) and its CPU time varies by 20 % between runs: the fastest of three
    # (timeit's convention) makes the ratio the conservative one
    times = [timed(params, scenario) for _ in range(max(args.baseline_repeats, 1))]
    base, base_cpu = min(times, key=lambda rt: rt[1])
    m = base.metrics
    print(f"two-mass compiled: {base_cpu:.2f} s CPU, fastest of {len(times)} "
          f"({', '.join(f'{c:.2f}' for _, c in times)} s; {base.wall_time:.2f} s wall), {base.stats['steps']} steps, "
          f"{base.stats['derivative_evaluations']} derivative evaluations; creep {m.creep}, "
          f"fluctuation {m.max_fluctuation * 1e3:.4f} mm/s", flush=True)
    print("| configuration | states | CPU (s) | wall (s) | ratio (CPU) | steps | derivative evals | us / eval | creep "
          "| fluctuation (mm/s) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, backend in ((n, b) for n in args.configs for b in args.backends):
        options = CONFIGS[name]
        r, cpu = timed(params, scenario, model="multibody", multibody=options, backend=backend)
        prof = profile(params, scenario, options, repeats=200, backend=backend)
        creep = r.metrics.creep if r.metrics else None
        fluct = f"{r.metrics.max_fluctuation * 1e3:.4f}" if r.metrics else "-"
        evals = r.stats["derivative_evaluations"]
        print(f"| {name} ({options.integrator}, {backend}) | {prof['states']} | {cpu:.1f} | {r.wall_time:.1f} | {cpu / base_cpu:.0f}x "
              f"| {r.stats['steps']} | {evals} | {prof['diagram derivatives']:.0f} | {creep} | {fluct} |", flush=True)
        print("    per evaluation (us): " + ", ".join(f"{k} {v:.0f}" for k, v in prof.items() if k != "states"),
              flush=True)
        if not r.ok:
            print(f"    status: {r.status}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
