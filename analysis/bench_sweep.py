"""Sweep speed (issue 7): a 400-case map, and throughput against a numba RK3 of the same equations.

Two measurements, both in this run, printed as ratios:

1. **Map wall time**: a 20 x 20 grid (feed x screw-nut stiffness) of 2 s runs of the paper preset
   (load case 3, LuGre, sampled cascade) through :func:`drakecreep.sim.sweep.run_sweep` on local processes
   (all cores), no cache. Target: <= 60 s on 2 cores; printed as ``wall / 60 s``.
2. **Throughput per simulated case-second**, single core each: drakecreep (``simulate()`` per case,
   i.e. build + symbolic compile + Drake RK3 + metrics, as the sweep runs it) against the same
   equations (:mod:`drakecreep.sim.baseline`, ported here to numba) integrated by a compiled adaptive
   Bogacki-Shampine RK3(2) with the preset's accuracy and max step, stepping to every controller
   sample like Drake's zero-order hold. Target: drakecreep within 10x. The numba port is checked
   against drakecreep on two cases (one steady, one creeping) so the ratio compares like with like.

The throughput compares like with like on the same cases: numba case by case, drakecreep's batched
path (:mod:`drakecreep.sim.batch`, all cases in one Drake system: what ``run_sweep(batch_size=...)`` uses),
and ``simulate()`` one case at a time.

Run: ``python analysis/bench_sweep.py [--cases N] [--grid N] [--duration S] [--skip-map]``
(needs the ``bench`` extra: ``pip install -e ".[bench]"`` for numba)
"""

import argparse
import math
import os
import sys
import time

import numpy as np

try:
    from numba import njit
except ImportError:  # one line, not a traceback: the comparison needs the bench extra
    print('numba: not installed; allowed: install the bench extra, pip install -e ".[bench]"', file=sys.stderr)
    sys.exit(2)

from drakecreep.sim.simulation import target_accuracy
from drakecreep.sim.baseline import BaselineModel
from drakecreep.params import preset
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
from drakecreep.sim.sweep import grid, run_sweep

LAWS = {"coulomb": 0, "stribeck": 1, "lugre": 2}


# --------------------------------------------------------------------------- numba port of baseline.py

def pack(params, scenario):
    """Flat float64 array of everything the numba right-hand side and update need."""
    m = BaselineModel(params, scenario)
    p, sc, nut, f, g = params, params.screw, params.nut, params.friction, params.controller
    if not m.sampled:
        raise ValueError("the numba port covers the sampled controller only")
    return np.array([
        m.ratio, m.ea, m.inertia, m.mass, m.fc, m.fs, m.limit, m.tracking, m.enc, m.lag,  # 0-9
        LAWS[f.law], f.stribeck_velocity, f.stribeck_exponent, f.viscous, f.bristle_stiffness,  # 10-14
        f.bristle_damping, f.regularization_velocity, m.fx, sc.mounting == "fixed-fixed", sc.length,  # 15-19
        sc.nut_start_distance, sc.bearing_stiffness, sc.bearing_damping, nut.axial_stiffness, nut.axial_damping,  # 20-24
        p.motor.viscous_damping, p.motor.peak_torque, g.position_gain, g.velocity_feedforward, g.velocity_gain,  # 25-29
        g.velocity_integral_gain, g.velocity_period, g.position_divider, g.position_feedback == "table",  # 30-33
        p.sensors.scale_resolution, scenario.feed, p.simulation.acceleration_time, m.ic["x_ref0"],  # 34-37
    ], dtype=np.float64)


@njit(cache=True)
def _g(P, v):
    return P[4] + (P[5] - P[4]) * math.exp(-abs(v / P[11]) ** P[12])


@njit(cache=True)
def rhs(P, s, force_cmd, out):
    ratio, inertia, mass, fc = P[0], P[2], P[3], P[4]
    lag = P[9] > 0.0
    theta, omega = s[0], s[1]
    j = 3 if lag else 2
    x, v = s[j], s[j + 1]
    tau_cmd = min(max(force_cmd * ratio, -P[26]), P[26])
    tau = s[2] if lag else tau_cmd
    a = P[20] + x
    ks = P[1] * P[19] / (a * (P[19] - a)) if P[18] > 0.5 else P[1] / a
    k = 1.0 / (1.0 / P[21] + 1.0 / ks + 1.0 / P[23])
    c = k * k * (P[22] / P[21] ** 2 + P[24] / P[23] ** 2)
    spring = k * (theta * ratio - x) + c * (omega * ratio - v)
    law = int(P[10])
    if law == 0:
        friction = fc * math.tanh(v / P[16]) + P[13] * v
    elif law == 1:
        friction = _g(P, v) * math.tanh(v / P[16]) + P[13] * v
    else:
        z = s[j + 2]
        rate = v - abs(v) * z * fc / _g(P, v)
        friction = fc * z + P[15] * rate + P[13] * v
        out[j + 2] = P[14] / fc * rate
    out[0] = omega
    out[1] = (tau - spring * ratio - P[25] * omega) / inertia
    if lag:
        out[2] = (tau_cmd - tau) / P[9]
    out[j] = v
    out[j + 1] = (spring - P[17] - friction) / mass


@njit(cache=True)
def _reference(P, t):
    v, ta, x0 = P[35], P[36], P[37]
    if ta > 0 and t < ta:
        return x0 + 0.5 * v * t * t / ta, v * t / ta
    return x0 + v * (t - 0.5 * ta), v


@njit(cache=True)
def update(P, t, s, xd):
    """One velocity-loop sample, ``xd = [v_cmd, integrator, theta_prev, force, tick]`` in place."""
    ratio, enc, period = P[0], P[8], P[31]
    theta = s[0]
    x = s[3] if P[9] > 0 else s[2]
    counted = enc * math.floor(theta / enc) if enc > 0 else theta
    speed = (counted - xd[2]) / period * ratio
    if xd[4] < 0.5:
        x_ref, v_ref = _reference(P, t)
        if P[33] > 0.5:
            res = P[34]
            measured = res * math.floor(x / res) if res > 0 else x
        else:
            measured = counted * ratio
        xd[0] = P[27] * (x_ref - measured) + P[28] * v_ref
    error = xd[0] - speed
    u = P[29] * error + xd[1]
    force = min(max(u, -P[6]), P[6])
    xd[1] += period * (P[30] * error + P[7] * (force - u))
    xd[2] = counted
    xd[3] = force
    xd[4] = 0.0 if xd[4] > P[32] - 1.5 else xd[4] + 1.0


@njit(cache=True)
def simulate_rk3(P, s0, xd0, duration, max_step, rtol, scales, v_index):
    """Adaptive Bogacki-Shampine RK3(2) between controller samples; table speed at every sample."""
    n = s0.shape[0]
    s = s0.copy()
    xd = xd0.copy()
    period = P[31]
    n_samples = int(math.ceil(duration / period - 1e-9))
    speeds = np.empty(n_samples + 1)
    speeds[0] = s[v_index]
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    y = np.empty(n)
    y3 = np.empty(n)
    h = max_step
    steps = 0
    for i in range(n_samples):
        t0 = i * period
        update(P, t0, s, xd)
        t1 = min((i + 1) * period, duration)
        t = t0
        rhs(P, s, xd[3], k1)
        while t < t1 - 1e-15:
            h = min(h, max_step, t1 - t)
            for q in range(n):
                y[q] = s[q] + 0.5 * h * k1[q]
            rhs(P, y, xd[3], k2)
            for q in range(n):
                y[q] = s[q] + 0.75 * h * k2[q]
            rhs(P, y, xd[3], k3)
            for q in range(n):
                y3[q] = s[q] + h * (2.0 * k1[q] + 3.0 * k2[q] + 4.0 * k3[q]) / 9.0
            rhs(P, y3, xd[3], k4)
            err = 0.0
            for q in range(n):
                e = h * (-5.0 * k1[q] / 72.0 + k2[q] / 12.0 + k3[q] / 9.0 - k4[q] / 8.0)
                e = abs(e) / (rtol * max(abs(y3[q]), scales[q]))
                if e > err:
                    err = e
            if err <= 1.0:
                t += h
                for q in range(n):
                    s[q] = y3[q]
                    k1[q] = k4[q]
                steps += 1
            h = h * min(4.0, max(0.1, 0.9 * (1.0 / max(err, 1e-12)) ** (1.0 / 3.0)))
        speeds[i + 1] = s[v_index]
    return speeds, steps


def run_numba(params, scenario):
    """Numba RK3 run of one case: ``(table speed at every controller sample, steps)``."""
    model = BaselineModel(params, scenario)
    s0, xd0 = model.initial_state()
    lag = model.lag > 0
    scales = np.array([1.0, 1.0] + ([1.0] if lag else []) + [1e-3, 1e-3] + [1.0] * model.nz)
    return simulate_rk3(pack(params, scenario), s0, np.array(xd0, dtype=float), scenario.duration,
                        params.simulation.max_step, target_accuracy(params), scales, 3 + lag)


# --------------------------------------------------------------------------- measurements

def check_port(params):
    print("numba port vs drakecreep (fluctuation rate over t >= steady_start):")
    for feed in (1e-3, 0.2e-3):
        scen = Scenario(feed=feed, load_case=3, duration=2.0)
        r = simulate(params, scen)
        v, _ = run_numba(params, scen)
        t = np.arange(len(v)) * params.controller.velocity_period
        w = v[t >= params.simulation.steady_start]
        rate = np.max(np.abs(w - w.mean())) / abs(w.mean())
        print(f"  feed {feed * 1e3:.1f} mm/s: drakecreep {r.metrics.fluctuation_rate * 100:8.3f} %  "
              f"mean {r.metrics.mean_speed * 1e3:.4f} mm/s | numba {rate * 100:8.3f} %  mean {w.mean() * 1e3:.4f} mm/s")


def throughput(params, n, duration, n_single=20):
    """Case-seconds per wall second on one core: numba RK3, the batched Drake path, single simulate()."""
    feeds = np.geomspace(0.2e-3, 2e-3, n)
    scens = [Scenario(feed=float(f), load_case=3, duration=duration) for f in feeds]
    run_numba(params, scens[0])  # JIT compile (cached on disk) outside the timing
    start = time.perf_counter()
    steps_numba = sum(run_numba(params, s)[1] for s in scens)
    t_numba = time.perf_counter() - start
    points = [dict(feed=float(f)) for f in feeds]
    batch_size = max(2, n // 2)
    start = time.perf_counter()
    swept = run_sweep(params, points, scenario=dict(load_case=3, duration=duration), executor="serial",
                      progress=False, batch_size=batch_size)
    t_batch = time.perf_counter() - start
    assert (swept.table["status"] == "ok").all()
    single = scens[:: max(1, n // n_single)]
    start = time.perf_counter()
    steps_drake = sum(simulate(params, s).stats["steps"] for s in single)
    t_single = (time.perf_counter() - start) * len(scens) / len(single)
    case_s = n * duration
    print(f"throughput, {n} cases x {duration:g} s (feeds 0.2-2 mm/s), one core:")
    print(f"  numba RK3, case by case:         {t_numba:7.3f} s = {case_s / t_numba:8.1f} case-s/s  ({steps_numba} steps)")
    print(f"  drakecreep run_sweep, batches of {batch_size}: {t_batch:7.3f} s = {case_s / t_batch:8.1f} case-s/s  "
          f"(whole sweep call: cases, batches, metrics)")
    print(f"  drakecreep simulate(), one by one: {t_single:5.3f} s = {case_s / t_single:8.1f} case-s/s  "
          f"(timed on {len(single)} of the cases, {steps_drake} steps)")
    ratio = t_batch / t_numba
    print(f"  RATIO drakecreep (batched) / numba time per case-second: {ratio:.1f}x  "
          f"(target <= 10x: {'met' if ratio <= 10 else 'NOT met'}); one by one: {t_single / t_numba:.1f}x")
    return ratio


def map_400(params, n_grid, duration, batch_size=None):
    points = grid({"nut.axial_stiffness": list(np.geomspace(5e6, 2e8, n_grid)),
                   "feed": list(np.geomspace(0.1e-3, 3e-3, n_grid))})
    start = time.perf_counter()
    result = run_sweep(params, points, scenario=dict(load_case=3, duration=duration), executor="processes",
                       progress=True, batch_size=batch_size)
    wall = time.perf_counter() - start
    ok = int((result.table["status"] == "ok").sum())
    how = f"in batches of {batch_size}" if batch_size else "case by case"
    print(f"map: {len(points)} cases x {duration:g} s on {os.cpu_count()} processes, {how}: {wall:.1f} s wall "
          f"({ok} ok, {int(result.table['creep'].sum())} creeping)")
    print(f"  RATIO map wall / 60 s target: {wall / 60.0:.2f}  (target <= 1: {'met' if wall <= 60 else 'NOT met'})")
    return wall


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=400, help="cases for the throughput comparison (default 400)")
    ap.add_argument("--grid", type=int, default=20, help="map is grid x grid cases (default 20: 400)")
    ap.add_argument("--duration", type=float, default=2.0, help="simulated seconds per case (default 2)")
    ap.add_argument("--skip-map", action="store_true")
    args = ap.parse_args()
    params = preset("paper")
    check_port(params)
    throughput(params, args.cases, args.duration)
    if not args.skip_map:
        map_400(params, args.grid, args.duration)
        map_400(params, args.grid, args.duration, batch_size=(args.grid * args.grid + 1) // 2)


if __name__ == "__main__":
    main()
