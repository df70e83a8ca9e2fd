"""What the compiled fast path's layout costs: the discrete update in the plant's output against a system of its own.

:func:`drakecreep.sim.compiled.compile_diagram` turns a feed drive into a ``SymbolicVectorSystem`` plant whose
output carries the controller's periodic update, sampled by a ``ZeroOrderHold``. Until session 78 that update was
a second, memoryless ``SymbolicVectorSystem`` fed by a multiplexer of the plant's output, the hold and the inputs;
``SymbolicVectorSystem`` wants a state, so it carried a constant continuous one, and every derivative evaluation of
the diagram evaluated that system's input (the plant's whole output) for a zero derivative. This script builds that
former layout here, as the baseline (wiring only: both are built from the same
:func:`~drakecreep.sim.compiled.symbolic_equations`), simulates both from the same state with the same integrator
settings, checks that the logged signals are the same bits, and prints the CPU time of each (``time.process_time``,
the least of ``--repeat``) and their ratio.

Run from the repository root: ``PYTHONPATH=. python analysis/bench_compiled.py [--duration S] [--repeat N]``
"""

import argparse
import time

import numpy as np
from pydrake.symbolic import Expression, MakeVectorVariable, Variable
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, Multiplexer, SymbolicVectorSystem, ZeroOrderHold

from drakecreep.gap.drake_replay import quick_replay_params
from drakecreep.model.diagram import build_diagram
from drakecreep.params import preset
from drakecreep.scenario import Scenario
from drakecreep.sim.compiled import compile_diagram, symbolic_equations
from drakecreep.sim.simulation import make_simulator, target_accuracy

__all__ = ["main"]


def former_layout(eq):
    """The session-77 compiled diagram of ``eq`` (no inputs): the plant, the update as a memoryless system with one
    constant continuous state, a multiplexer and the hold. Returns ``(diagram, plant, sampler)``."""
    b = DiagramBuilder()
    out = np.concatenate([eq.signals, [Expression(v) for v in eq.xc]])
    plant = b.AddSystem(SymbolicVectorSystem(time=eq.time, state=eq.xc, input=eq.xd, dynamics=eq.derivatives,
                                             output=out))
    dummy = MakeVectorVariable(len(eq.signals), "signal")
    update = b.AddSystem(SymbolicVectorSystem(time=eq.time, state=[Variable("unused_constant_state")],
                                              input=np.concatenate([dummy, eq.xc, eq.xd]),
                                              dynamics=[Expression(0.0)], output=eq.update))
    sampler = b.AddSystem(ZeroOrderHold(eq.period, len(eq.xd)))
    mux = b.AddSystem(Multiplexer([len(eq.signals) + len(eq.xc), len(eq.xd)]))
    b.Connect(plant.get_output_port(0), mux.get_input_port(0))
    b.Connect(sampler.get_output_port(), mux.get_input_port(1))
    b.Connect(mux.get_output_port(0), update.get_input_port(0))
    b.Connect(update.get_output_port(0), sampler.get_input_port())
    b.Connect(sampler.get_output_port(), plant.get_input_port(0))
    b.ExportOutput(plant.get_output_port(0), "signals")
    return b.Build(), plant, sampler


def _simulate(params, scenario, layout):
    """CPU seconds and logged signals of one simulation of ``layout`` ("current" or "former")."""
    feed_drive = build_diagram(params, scenario)
    b = DiagramBuilder()
    if layout == "current":
        compiled = compile_diagram(feed_drive)
        system = b.AddSystem(compiled.diagram)
    else:
        eq = symbolic_equations(feed_drive)
        diagram, plant, sampler = former_layout(eq)
        system = b.AddSystem(diagram)
    log = LogVectorOutput(system.GetOutputPort("signals"), b, params.simulation.log_period)
    root = b.Build()
    context = root.CreateDefaultContext()
    sub = root.GetMutableSubsystemContext(system, context)
    if layout == "current":
        compiled.set_initial_state(sub)
    else:
        diagram.GetMutableSubsystemContext(plant, sub).SetContinuousState(eq.xc0)
        sampler.SetVectorState(diagram.GetMutableSubsystemContext(sampler, sub), eq.xd0)
    simulator = make_simulator(root, context, params.simulation, target_accuracy(params))
    t0 = time.process_time()
    simulator.AdvanceTo(scenario.duration)
    return time.process_time() - t0, log.FindLog(context).data(), simulator.get_integrator().get_num_steps_taken()


CASES = (("paper preset, LuGre, load case 3, 0.1 mm/s", lambda: preset("paper"), 1e-4, 3),
         ("quick replay rig (Stribeck), 20 mm/s", lambda: quick_replay_params(preset("paper")), 0.02, 0))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=1.0, help="simulated seconds per run (default %(default)s)")
    ap.add_argument("--repeat", type=int, default=3,
                    help="simulations per case and layout, the least CPU time kept (default %(default)s)")
    args = ap.parse_args(argv)
    if not 0.01 <= args.duration <= 60:
        ap.error(f"--duration: got {args.duration}; allowed: seconds in [0.01, 60]")
    if not 1 <= args.repeat <= 20:
        ap.error(f"--repeat: got {args.repeat}; allowed: an integer in [1, 20]")
    print(f"{args.duration:g} s simulated per run; least CPU time of {args.repeat}")
    print(f"{'case':46s} {'steps':>6s} {'former [s]':>11s} {'current [s]':>12s} {'ratio':>6s} {'same bits':>10s}")
    for label, params, feed, load in CASES:
        p = params()
        scenario = Scenario(feed=feed, load_case=load, duration=args.duration)
        best = {}
        for layout in ("former", "current"):
            runs = [_simulate(p, scenario, layout) for _ in range(args.repeat)]
            best[layout] = (min(r[0] for r in runs), runs[0][1], runs[0][2])
        same = np.array_equal(best["former"][1], best["current"][1])
        print(f"{label:46s} {best['current'][2]:6d} {best['former'][0]:11.3f} {best['current'][0]:12.3f} "
              f"{best['former'][0] / best['current'][0]:6.2f} {str(same):>10s}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
