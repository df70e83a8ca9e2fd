"""Speed of drakecreep's simulation against plain SciPy on the same equations (issue: core model).

Reference case: paper preset, load case 3, 1 mm/s, 5 s simulated, LuGre friction, sampled cascade
controller. Both sides are timed in this process, so the printed ratio is robust to a busy machine.

* drakecreep: the whole ``simulate()`` call (build the diagram, compile it to SymbolicVectorSystems,
  simulate with Drake's RK3 at the preset's accuracy, compute metrics).
* SciPy: ``solve_ivp(method="LSODA")`` on the same equations written in plain Python
  (:mod:`drakecreep.sim.baseline`), integrated between controller samples as the zero-order hold requires.
* "Same accuracy": both are scored against a tight reference (drakecreep at accuracy 1e-9, checked
  against SciPy at rtol 1e-9); SciPy gets the loosest rtol (atol = rtol x state scale) whose
  table-speed error is no larger than drakecreep's.

Also printed, for context: the same with the continuous controller (one ``solve_ivp`` call, LSODA's
best case), and the Python leaf-system backend against the compiled one.

Run: ``python analysis/bench_simulation.py [--duration S] [--repeats N]``
"""

import argparse
import time

import numpy as np

from drakecreep.sim.simulation import target_accuracy
from drakecreep.sim.baseline import simulate_baseline
from drakecreep.params import preset, with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate

#: typical magnitude of each state (sampled controller): theta, omega, tau, x, v, w
SCALES_SAMPLED = np.array([1.0, 1.0, 1.0, 1e-3, 1e-3, 1.0])
SCALES_CONTINUOUS = np.concatenate([[100.0], SCALES_SAMPLED])


def best_of(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return min(times), out


def speed_error(v, v_ref, feed):
    return float(np.max(np.abs(np.asarray(v) - v_ref)) / abs(feed))


def compare(params, scenario, scales, repeats, label):
    tight = simulate(with_value(params, "simulation.accuracy", 1e-9), scenario)
    v_ref = tight.signals["table_speed"]
    check = simulate_baseline(params, scenario, rtol=1e-9, atol=1e-9 * scales)
    agree = speed_error(check["table_speed"], v_ref, scenario.feed)
    t_drake, result = best_of(lambda: simulate(params, scenario), repeats)
    err_drake = speed_error(result.signals["table_speed"], v_ref, scenario.feed)
    chosen = None
    for rtol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        trial = simulate_baseline(params, scenario, rtol=rtol, atol=rtol * scales)
        err = speed_error(trial["table_speed"], v_ref, scenario.feed)
        if err <= err_drake:
            chosen = (rtol, err)
            break
    if chosen is None:
        raise SystemExit(f"{label}: SciPy did not reach drakecreep's accuracy ({err_drake:.2e}) down to rtol 1e-8")
    rtol, err_scipy = chosen
    t_scipy, base = best_of(lambda: simulate_baseline(params, scenario, rtol=rtol, atol=rtol * scales), repeats)
    print(f"\n{label}")
    print(f"  trajectories agree: drakecreep(1e-9) vs SciPy(rtol 1e-9) max |dv| = {agree:.2e} x feed")
    print(f"  drakecreep compiled, accuracy {target_accuracy(params):g}: {t_drake:.3f} s, "
          f"max |dv| = {err_drake:.2e} x feed, {result.stats['derivative_evaluations']} derivative evaluations")
    print(f"  SciPy LSODA rtol {rtol:g}: {t_scipy:.3f} s, max |dv| = {err_scipy:.2e} x feed, "
          f"{base['nfev']} evaluations in {base['calls']} solve_ivp calls")
    ratio = t_drake / t_scipy
    print(f"  ratio = drakecreep_time / scipy_time = {ratio:.3f}")
    return ratio, t_drake, result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=5.0)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    params = preset("paper")
    scenario = Scenario(feed=1e-3, load_case=3, duration=args.duration)
    ratio, t_fast, _ = compare(params, scenario, SCALES_SAMPLED, args.repeats,
                               "reference case: paper preset, load case 3, 1 mm/s, LuGre, sampled cascade")
    compare(with_value(params, "controller.sampled", False), scenario, SCALES_CONTINUOUS, args.repeats,
            "context: same with the continuous cascade (one solve_ivp call)")
    t_leaf, _ = best_of(lambda: simulate(params, scenario, backend="leaf"), 1)
    print(f"\ncontext: Python leaf systems {t_leaf:.3f} s vs compiled {t_fast:.3f} s "
          f"(compiled is {t_leaf / t_fast:.1f}x faster)")
    print(f"\nratio = {ratio:.3f} (target <= 0.5): {'met' if ratio <= 0.5 else 'NOT met'}")


if __name__ == "__main__":
    main()
